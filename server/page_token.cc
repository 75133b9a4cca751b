#include "server/page_token.h"

#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <cstdio>
#include <cstdlib>
#include <memory>

#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

constexpr unsigned char kVersion = 2;
constexpr size_t kNonceBytes = 12;
constexpr size_t kKeyBytes = 8;
constexpr size_t kTagBytes = 16;
// No version byte in the token (36 bytes: 48 base64 characters without
// padding bits, so every character counts); the version is bound in the
// associated data, and version 1's tokens (33 bytes) have another length.
constexpr size_t kTokenBytes = kNonceBytes + kKeyBytes + kTagBytes;

// HMAC-SHA256(key, data), 32 bytes: the cipher key derived from the
// store's secret. Should OpenSSL fail here (out of memory at start-up),
// there is no safe key: stop.
std::string DeriveKey(const std::string& secret) {
  unsigned char out[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  static constexpr char kLabel[] = "cablesim page token aes-256-gcm";
  if (HMAC(EVP_sha256(), secret.data(), static_cast<int>(secret.size()),
           reinterpret_cast<const unsigned char*>(kLabel), sizeof(kLabel) - 1, out,
           &length) == nullptr ||
      length != 32) {
    std::fputs("cablesim-server: OpenSSL's HMAC failed deriving the page-token key\n", stderr);
    std::abort();
  }
  return std::string(reinterpret_cast<const char*>(out), length);
}

// 8 bytes big-endian.
std::string BigEndian(uint64_t v) {
  std::string bytes(8, '\0');
  for (int i = 7; i >= 0; --i, v >>= 8) bytes[i] = static_cast<char>(v & 0xff);
  return bytes;
}

std::string AssociatedData(const std::string& tenant, const std::string& query) {
  return absl::StrCat(std::string(1, static_cast<char>(kVersion)), BigEndian(tenant.size()),
                      tenant, query);
}

absl::Status NotAToken(const std::string& why) {
  return absl::InvalidArgumentError(absl::StrCat(
      "page_token: ", why,
      "; pass the next_page_token of a previous ListJobs response to the same query, "
      "or none to start from the newest job"));
}

using CipherContext = std::unique_ptr<EVP_CIPHER_CTX, decltype(&EVP_CIPHER_CTX_free)>;

const unsigned char* Bytes(const std::string& s) {
  return reinterpret_cast<const unsigned char*>(s.data());
}

}  // namespace

PageTokenCodec::PageTokenCodec(const std::string& secret) : key_(DeriveKey(secret)) {}

absl::StatusOr<std::string> PageTokenCodec::Encode(int64_t key, const std::string& tenant,
                                                   const std::string& query) const {
  std::string nonce(kNonceBytes, '\0');
  if (RAND_bytes(reinterpret_cast<unsigned char*>(nonce.data()), kNonceBytes) != 1) {
    return absl::UnavailableError("page_token: no randomness for the nonce");
  }
  const std::string plain = BigEndian(static_cast<uint64_t>(key));
  const std::string aad = AssociatedData(tenant, query);
  std::string sealed(kKeyBytes, '\0'), tag(kTagBytes, '\0');
  CipherContext ctx(EVP_CIPHER_CTX_new(), EVP_CIPHER_CTX_free);
  int n = 0;
  if (ctx == nullptr ||
      EVP_EncryptInit_ex(ctx.get(), EVP_aes_256_gcm(), nullptr, nullptr, nullptr) != 1 ||
      EVP_CIPHER_CTX_ctrl(ctx.get(), EVP_CTRL_GCM_SET_IVLEN, kNonceBytes, nullptr) != 1 ||
      EVP_EncryptInit_ex(ctx.get(), nullptr, nullptr, Bytes(key_), Bytes(nonce)) != 1 ||
      EVP_EncryptUpdate(ctx.get(), nullptr, &n, Bytes(aad), static_cast<int>(aad.size())) != 1 ||
      EVP_EncryptUpdate(ctx.get(), reinterpret_cast<unsigned char*>(sealed.data()), &n,
                        Bytes(plain), kKeyBytes) != 1 ||
      n != static_cast<int>(kKeyBytes) ||
      EVP_EncryptFinal_ex(ctx.get(), reinterpret_cast<unsigned char*>(sealed.data()) + n, &n) !=
          1 ||
      EVP_CIPHER_CTX_ctrl(ctx.get(), EVP_CTRL_GCM_GET_TAG, kTagBytes, tag.data()) != 1) {
    return absl::UnavailableError("page_token: OpenSSL could not seal the token");
  }
  return absl::WebSafeBase64Escape(absl::StrCat(nonce, sealed, tag));
}

absl::StatusOr<int64_t> PageTokenCodec::Decode(const std::string& token,
                                               const std::string& tenant,
                                               const std::string& query) const {
  std::string bytes;
  if (token.size() > 64 || !absl::WebSafeBase64Unescape(token, &bytes) ||
      bytes.size() != kTokenBytes) {
    return NotAToken("not a page token");
  }
  const std::string nonce = bytes.substr(0, kNonceBytes);
  const std::string sealed = bytes.substr(kNonceBytes, kKeyBytes);
  std::string tag = bytes.substr(kNonceBytes + kKeyBytes, kTagBytes);
  const std::string aad = AssociatedData(tenant, query);
  std::string plain(kKeyBytes, '\0');
  CipherContext ctx(EVP_CIPHER_CTX_new(), EVP_CIPHER_CTX_free);
  int n = 0;
  // Any failure, the tag's check (EVP_DecryptFinal_ex) included, refuses
  // the token: fail closed.
  if (ctx == nullptr ||
      EVP_DecryptInit_ex(ctx.get(), EVP_aes_256_gcm(), nullptr, nullptr, nullptr) != 1 ||
      EVP_CIPHER_CTX_ctrl(ctx.get(), EVP_CTRL_GCM_SET_IVLEN, kNonceBytes, nullptr) != 1 ||
      EVP_DecryptInit_ex(ctx.get(), nullptr, nullptr, Bytes(key_), Bytes(nonce)) != 1 ||
      EVP_DecryptUpdate(ctx.get(), nullptr, &n, Bytes(aad), static_cast<int>(aad.size())) != 1 ||
      EVP_DecryptUpdate(ctx.get(), reinterpret_cast<unsigned char*>(plain.data()), &n,
                        Bytes(sealed), kKeyBytes) != 1 ||
      EVP_CIPHER_CTX_ctrl(ctx.get(), EVP_CTRL_GCM_SET_TAG, kTagBytes, tag.data()) != 1 ||
      EVP_DecryptFinal_ex(ctx.get(), reinterpret_cast<unsigned char*>(plain.data()) + n, &n) !=
          1) {
    return NotAToken("altered, or made for another query, tenant or server's store");
  }
  uint64_t key = 0;
  for (size_t i = 0; i < kKeyBytes; ++i) key = (key << 8) | static_cast<unsigned char>(plain[i]);
  if (key == 0 || key > static_cast<uint64_t>(INT64_MAX)) return NotAToken("not a page token");
  return static_cast<int64_t>(key);
}

}  // namespace cablesim
