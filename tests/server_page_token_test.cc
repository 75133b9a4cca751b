// ListJobs page tokens against a real cablesim-server, on either store
// (SQLite in the data directory; PostgreSQL the test starts on loopback,
// tests/postgres_test_util.h): keyset paging that survives deleting the
// page's last job, opaque tokens (neither a job id nor a count), tampered,
// foreign-tenant and garbage tokens refused naming `page_token`, and tokens
// that survive a restart (the secret is kept in the store; with
// PostgreSQL, every server of the store accepts every other's tokens).

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "server/page_token.h"
#include "both_stores_test_util.h"
#include "postgres_test_util.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::Pendulum;
using testing::ServerProcess;

struct Page {
  grpc::Status status;
  std::vector<std::string> ids;
  std::string next;
};

Page List(v1::CablesimService::Stub* stub, int page_size, const std::string& token,
          const std::string& bearer = "", v1::JobState state = v1::JOB_STATE_UNSPECIFIED) {
  grpc::ClientContext context;
  if (!bearer.empty()) context.AddMetadata("authorization", "Bearer " + bearer);
  v1::ListJobsRequest request;
  request.set_page_size(page_size);
  request.set_page_token(token);
  request.set_state(state);
  v1::ListJobsResponse response;
  Page page;
  page.status = stub->ListJobs(&context, request, &response);
  for (const v1::Job& job : response.jobs()) page.ids.push_back(job.id());
  page.next = response.next_page_token();
  return page;
}

grpc::StatusCode Delete(v1::CablesimService::Stub* stub, const std::string& id) {
  return testing::DeleteJob(stub, id).error_code();
}

// `n` short jobs, run to the end; their ids oldest first.
std::vector<std::string> FinishedJobs(v1::CablesimService::Stub* stub, int n) {
  std::vector<std::string> ids;
  for (int i = 0; i < n; ++i) {
    ids.push_back(testing::Submit(stub, Pendulum(0.01, 1e-3, 1e-2)).id());
  }
  for (const std::string& id : ids) EXPECT_EQ(testing::WaitForJob(stub, id), v1::SUCCEEDED);
  return ids;
}

// HMAC-SHA256(key, data), computed here independently of page_token.cc.
std::string Hmac(const std::string& key, const std::string& data) {
  unsigned char out[32];
  unsigned int length = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()),
       reinterpret_cast<const unsigned char*>(data.data()), data.size(), out, &length);
  return std::string(reinterpret_cast<const char*>(out), length);
}

// The token is standard AES-256-GCM (page_token.h spells it out): opened
// here with OpenSSL's EVP interface directly, from the documented key
// derivation, nonce, associated data and tag, it gives the key back; a
// token of the old home-made encrypt-then-MAC (version 1) is refused like
// a forged one.
TEST(PageTokenCodecTest, TokensAreAes256GcmAndOldTokensAreRefused) {
  const std::string secret(32, '\x5a');
  PageTokenCodec codec(secret);
  absl::StatusOr<std::string> token = codec.Encode(123456789, "alice", "state=3");
  ASSERT_TRUE(token.ok()) << token.status();
  std::string bytes;
  ASSERT_TRUE(absl::WebSafeBase64Unescape(*token, &bytes));
  ASSERT_EQ(bytes.size(), 36u);
  const std::string key = Hmac(secret, "cablesim page token aes-256-gcm");
  std::string tenant_size(8, '\0');
  tenant_size[7] = 5;
  const std::string aad = absl::StrCat(std::string(1, '\x02'), tenant_size, "alice", "state=3");
  auto u = [](const std::string& s) { return reinterpret_cast<const unsigned char*>(s.data()); };
  EVP_CIPHER_CTX* ctx = EVP_CIPHER_CTX_new();
  unsigned char plain[16];
  int n = 0, m = 0;
  std::string tag = bytes.substr(20, 16);
  ASSERT_EQ(EVP_DecryptInit_ex(ctx, EVP_aes_256_gcm(), nullptr, nullptr, nullptr), 1);
  ASSERT_EQ(EVP_CIPHER_CTX_ctrl(ctx, EVP_CTRL_GCM_SET_IVLEN, 12, nullptr), 1);
  ASSERT_EQ(EVP_DecryptInit_ex(ctx, nullptr, nullptr, u(key), u(bytes)), 1);
  ASSERT_EQ(EVP_DecryptUpdate(ctx, nullptr, &n, u(aad), static_cast<int>(aad.size())), 1);
  ASSERT_EQ(EVP_DecryptUpdate(ctx, plain, &n, u(bytes) + 12, 8), 1);
  ASSERT_EQ(EVP_CIPHER_CTX_ctrl(ctx, EVP_CTRL_GCM_SET_TAG, 16, tag.data()), 1);
  EXPECT_EQ(EVP_DecryptFinal_ex(ctx, plain + n, &m), 1);  // the tag checks out
  EVP_CIPHER_CTX_free(ctx);
  uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value = (value << 8) | plain[i];
  EXPECT_EQ(value, 123456789u);
  EXPECT_EQ(*codec.Decode(*token, "alice", "state=3"), 123456789);
  EXPECT_FALSE(codec.Decode(*token, "bob", "state=3").ok());
  EXPECT_FALSE(codec.Decode(*token, "alice", "state=4").ok());

  // Version 1: v || n || key XOR HMAC(K_e, n) || HMAC(K_m, ...)[0..16).
  const std::string k_e = Hmac(secret, "cablesim page token encryption");
  const std::string k_m = Hmac(secret, "cablesim page token mac");
  const std::string nonce(8, '\x11');
  std::string sealed(8, '\0');
  sealed[7] = 7;
  const std::string pad = Hmac(k_e, nonce);
  for (int i = 0; i < 8; ++i) sealed[i] ^= pad[i];
  const std::string body = absl::StrCat(std::string(1, '\x01'), nonce, sealed);
  const std::string old_token = absl::WebSafeBase64Escape(absl::StrCat(
      body, Hmac(k_m, absl::StrCat(body, tenant_size, "alice", "state=3")).substr(0, 16)));
  absl::StatusOr<int64_t> old = codec.Decode(old_token, "alice", "state=3");
  EXPECT_EQ(old.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(old.status().message(), HasSubstr("page_token"));
}

using ServerPageTokenTest = testing::BothStoresTest;

TEST_P(ServerPageTokenTest, ThreePagesWithDeletionsListEveryRemainingJobOnceInOrder) {
  std::vector<std::string> flags = StoreFlags("page_delete");
  if (skipped_) GTEST_SKIP() << "PostgreSQL is not installed";
  flags.push_back("--workers=2");
  ServerProcess server(testing::FreshDir("page_delete_" + GetParam()), flags);
  auto stub = server.Stub();
  const std::vector<std::string> ids = FinishedJobs(stub.get(), 9);
  // Newest first: 8 7 6 | 5 4 3 | 2 1 0 with pages of 3.
  const Page first = List(stub.get(), 3, "");
  ASSERT_TRUE(first.status.ok()) << first.status.error_message();
  EXPECT_THAT(first.ids, ::testing::ElementsAre(ids[8], ids[7], ids[6]));
  ASSERT_FALSE(first.next.empty());
  // The token is opaque: no job id in it, 48 URL-safe characters.
  EXPECT_THAT(first.next, ::testing::MatchesRegex("[A-Za-z0-9_-]{48}"));
  for (const std::string& id : ids) EXPECT_EQ(first.next.find(id.substr(2)), std::string::npos);
  // The page's last job and the next page's first are deleted in between.
  ASSERT_EQ(Delete(stub.get(), ids[6]), grpc::StatusCode::OK);
  ASSERT_EQ(Delete(stub.get(), ids[5]), grpc::StatusCode::OK);
  const Page second = List(stub.get(), 3, first.next);
  ASSERT_TRUE(second.status.ok()) << second.status.error_message();
  EXPECT_THAT(second.ids, ::testing::ElementsAre(ids[4], ids[3], ids[2]));
  ASSERT_FALSE(second.next.empty());
  // Again, and a job already listed: nothing listed twice, nothing lost.
  ASSERT_EQ(Delete(stub.get(), ids[2]), grpc::StatusCode::OK);
  ASSERT_EQ(Delete(stub.get(), ids[7]), grpc::StatusCode::OK);
  const Page third = List(stub.get(), 3, second.next);
  ASSERT_TRUE(third.status.ok()) << third.status.error_message();
  EXPECT_THAT(third.ids, ::testing::ElementsAre(ids[1], ids[0]));
  EXPECT_TRUE(third.next.empty());
  // The same place twice gives two different tokens (a fresh nonce), that
  // both continue there: the token says nothing about how many jobs exist.
  const Page again = List(stub.get(), 3, "");
  ASSERT_TRUE(again.status.ok());
  const Page once_more = List(stub.get(), 3, "");
  EXPECT_NE(again.next, once_more.next);
  EXPECT_EQ(List(stub.get(), 3, again.next).ids, List(stub.get(), 3, once_more.next).ids);
}

TEST_P(ServerPageTokenTest, AlteredOrGarbageOrOtherQueryTokensAreRefusedNamingTheField) {
  std::vector<std::string> flags = StoreFlags("page_tamper");
  if (skipped_) GTEST_SKIP() << "PostgreSQL is not installed";
  ServerProcess server(testing::FreshDir("page_tamper_" + GetParam()), flags);
  auto stub = server.Stub();
  FinishedJobs(stub.get(), 3);
  const Page first = List(stub.get(), 1, "");
  ASSERT_TRUE(first.status.ok());
  ASSERT_FALSE(first.next.empty());
  EXPECT_TRUE(List(stub.get(), 1, first.next).status.ok());
  std::vector<std::string> bad = {"not a token", "j-000001", "", first.next + "A",
                                  first.next.substr(0, 47)};
  bad[2] = absl::WebSafeBase64Escape(std::string(36, '\x01'));  // well formed, not sealed
  // Each byte of the token changed in turn (the base64 character for the
  // byte's 6 bits flipped): every one detected.
  for (size_t i = 0; i < first.next.size(); ++i) {
    std::string altered = first.next;
    altered[i] = altered[i] == 'A' ? 'B' : 'A';
    bad.push_back(altered);
  }
  for (const std::string& token : bad) {
    const Page page = List(stub.get(), 1, token);
    EXPECT_EQ(page.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << token;
    EXPECT_THAT(page.status.error_message(), HasSubstr("page_token")) << token;
  }
  // A token is for the query that made it: the state filter may not change.
  const Page other_query = List(stub.get(), 1, first.next, "", v1::SUCCEEDED);
  EXPECT_EQ(other_query.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(other_query.status.error_message(), HasSubstr("page_token"));
}

TEST_P(ServerPageTokenTest, AnotherTenantsTokenIsRefused) {
  std::vector<std::string> flags = StoreFlags("page_tenant");
  if (skipped_) GTEST_SKIP() << "PostgreSQL is not installed";
  const std::string dir = testing::FreshDir("page_tenant_" + GetParam());
  const std::string alice = "tok-alice-0123456789", bob = "tok-bob-0123456789ab";
  testing::WritePrivateFile(dir + "/tokens", absl::StrCat(alice, " alice\n", bob, " bob\n"));
  flags.push_back("--token-file=" + dir + "/tokens");
  ServerProcess server(dir, flags);
  auto stub = server.Stub();
  for (const std::string& who : {alice, bob}) {
    for (int i = 0; i < 2; ++i) {
      grpc::ClientContext context;
      context.AddMetadata("authorization", "Bearer " + who);
      v1::SubmitJobRequest request;
      *request.mutable_scene() = Pendulum(0.01, 1e-3, 1e-2);
      v1::Job job;
      ASSERT_TRUE(stub->SubmitJob(&context, request, &job).ok());
    }
  }
  const Page alices = List(stub.get(), 1, "", alice);
  ASSERT_TRUE(alices.status.ok()) << alices.status.error_message();
  ASSERT_FALSE(alices.next.empty());
  EXPECT_TRUE(List(stub.get(), 1, alices.next, alice).status.ok());
  const Page stolen = List(stub.get(), 1, alices.next, bob);
  EXPECT_EQ(stolen.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(stolen.status.error_message(), HasSubstr("page_token"));
}

TEST_P(ServerPageTokenTest, ATokenSurvivesARestart) {
  std::vector<std::string> flags = StoreFlags("page_restart");
  if (skipped_) GTEST_SKIP() << "PostgreSQL is not installed";
  ServerProcess server(testing::FreshDir("page_restart_" + GetParam()), flags);
  auto stub = server.Stub();
  const std::vector<std::string> ids = FinishedJobs(stub.get(), 4);
  const Page first = List(stub.get(), 2, "");
  ASSERT_TRUE(first.status.ok());
  ASSERT_FALSE(first.next.empty());
  server.Kill(SIGKILL);
  server.Restart();
  stub = server.Stub();
  const Page second = List(stub.get(), 2, first.next);
  ASSERT_TRUE(second.status.ok()) << second.status.error_message();
  EXPECT_THAT(second.ids, ::testing::ElementsAre(ids[1], ids[0]));
  if (GetParam() != "postgresql") return;
  // Another server of the same database continues the same listing.
  ServerProcess other(testing::FreshDir("page_restart_other"), flags);
  auto other_stub = other.Stub();
  const Page elsewhere = List(other_stub.get(), 2, first.next);
  ASSERT_TRUE(elsewhere.status.ok()) << elsewhere.status.error_message();
  EXPECT_THAT(elsewhere.ids, ::testing::ElementsAre(ids[1], ids[0]));
}

INSTANTIATE_TEST_SUITE_P(BothStores, ServerPageTokenTest, ::testing::Values("sqlite", "postgresql"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace cablesim
