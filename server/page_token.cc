#include "server/page_token.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

constexpr unsigned char kVersion = 1;
constexpr size_t kNonceBytes = 8;
constexpr size_t kKeyBytes = 8;
constexpr size_t kTagBytes = 16;
constexpr size_t kTokenBytes = 1 + kNonceBytes + kKeyBytes + kTagBytes;

// HMAC-SHA256(key, data), 32 bytes. Should OpenSSL fail (out of memory),
// 32 random bytes instead: tokens made or checked with them are refused as
// altered (fail closed), and nothing reads past a short result.
std::string HmacSha256(const std::string& key, const std::string& data) {
  unsigned char out[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()),
           reinterpret_cast<const unsigned char*>(data.data()), data.size(), out,
           &length) == nullptr ||
      length != 32) {
    length = 32;
    if (RAND_bytes(out, 32) != 1) {
      std::fputs("cablesim-server: OpenSSL's HMAC and RAND_bytes both failed\n", stderr);
      std::abort();  // no token can be made or checked safely
    }
  }
  return std::string(reinterpret_cast<const char*>(out), length);
}

// 8 bytes big-endian.
std::string BigEndian(uint64_t v) {
  std::string bytes(8, '\0');
  for (int i = 7; i >= 0; --i, v >>= 8) bytes[i] = static_cast<char>(v & 0xff);
  return bytes;
}

absl::Status NotAToken(const std::string& why) {
  return absl::InvalidArgumentError(absl::StrCat(
      "page_token: ", why,
      "; pass the next_page_token of a previous ListJobs response to the same query, "
      "or none to start from the newest job"));
}

}  // namespace

PageTokenCodec::PageTokenCodec(const std::string& secret)
    : encryption_key_(HmacSha256(secret, "cablesim page token encryption")),
      mac_key_(HmacSha256(secret, "cablesim page token mac")) {}

std::string PageTokenCodec::Tag(const std::string& body, const std::string& tenant,
                                const std::string& query) const {
  return HmacSha256(mac_key_, absl::StrCat(body, BigEndian(tenant.size()), tenant, query))
      .substr(0, kTagBytes);
}

absl::StatusOr<std::string> PageTokenCodec::Encode(int64_t key, const std::string& tenant,
                                                   const std::string& query) const {
  std::string nonce(kNonceBytes, '\0');
  if (RAND_bytes(reinterpret_cast<unsigned char*>(nonce.data()), kNonceBytes) != 1) {
    return absl::UnavailableError("page_token: no randomness for the nonce");
  }
  const std::string pad = HmacSha256(encryption_key_, nonce);
  std::string sealed = BigEndian(static_cast<uint64_t>(key));
  for (size_t i = 0; i < kKeyBytes; ++i) sealed[i] ^= pad[i];
  std::string body = absl::StrCat(std::string(1, static_cast<char>(kVersion)), nonce, sealed);
  return absl::WebSafeBase64Escape(absl::StrCat(body, Tag(body, tenant, query)));
}

absl::StatusOr<int64_t> PageTokenCodec::Decode(const std::string& token,
                                               const std::string& tenant,
                                               const std::string& query) const {
  std::string bytes;
  if (token.size() > 64 || !absl::WebSafeBase64Unescape(token, &bytes) ||
      bytes.size() != kTokenBytes || static_cast<unsigned char>(bytes[0]) != kVersion) {
    return NotAToken("not a page token");
  }
  const std::string body = bytes.substr(0, kTokenBytes - kTagBytes);
  const std::string tag = Tag(body, tenant, query);
  if (CRYPTO_memcmp(tag.data(), bytes.data() + body.size(), kTagBytes) != 0) {
    return NotAToken("altered, or made for another query, tenant or server's store");
  }
  const std::string pad = HmacSha256(encryption_key_, body.substr(1, kNonceBytes));
  uint64_t key = 0;
  for (size_t i = 0; i < kKeyBytes; ++i) {
    key = (key << 8) | static_cast<unsigned char>(body[1 + kNonceBytes + i] ^ pad[i]);
  }
  if (key == 0 || key > static_cast<uint64_t>(INT64_MAX)) return NotAToken("not a page token");
  return static_cast<int64_t>(key);
}

}  // namespace cablesim
