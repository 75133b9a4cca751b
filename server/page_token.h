#ifndef CABLESIM_SERVER_PAGE_TOKEN_H_
#define CABLESIM_SERVER_PAGE_TOKEN_H_

// Opaque, authenticated page tokens for ListJobs (keyset pagination).
//
// A token names the place after which the next page starts: the order key
// of the last job listed (the store's internal row number, which only
// grows), never a job id. So deleting that job between two calls does not
// lose the place: the next page lists the jobs with a smaller key, as if
// the job were still there.
//
// The key is hidden, since row numbers would reveal how many jobs the
// server has made, and the token is authenticated, so that a client can
// neither forge a key nor reuse a token for another tenant or another
// query. The cipher is AES-256-GCM (an authenticated cipher, through
// OpenSSL's EVP interface). With S the store's secret
// (JobStore::page_token_secret, 32 random bytes kept in the store) and
// K = HMAC-SHA256(S, "cablesim page token aes-256-gcm"):
//
//   n      = 12 random bytes (a fresh nonce per token)
//   aad    = v || |tenant| (8 bytes, big-endian) || tenant || query, v = 2
//   c, tag = AES-256-GCM(K, n, key as 8 bytes big-endian, aad), 16-byte tag
//   token  = base64url(n || c || tag): 48 characters
//
// Tokens of version 1 (an HMAC-based encrypt-then-MAC, before 0.16) are
// refused like forged ones; a client starts again from the first page.
// The query is what must stay the same from page to page (the state and
// sweep filters); the page size may change.

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"

namespace cablesim {

class PageTokenCodec {
 public:
  // `secret`: the store's page-token secret (any length; 32 random bytes).
  explicit PageTokenCodec(const std::string& secret);

  // The token that continues after order key `key` (> 0) for `tenant`
  // ("" without tokens) and `query`. Unavailable only when the system has
  // no randomness.
  absl::StatusOr<std::string> Encode(int64_t key, const std::string& tenant,
                                     const std::string& query) const;
  // The order key of a token Encode made for the same tenant and query;
  // InvalidArgument naming `page_token` for anything else (garbage, a
  // changed byte, another tenant's or another query's token, a token of
  // another store).
  absl::StatusOr<int64_t> Decode(const std::string& token, const std::string& tenant,
                                 const std::string& query) const;

 private:
  std::string key_;  // 32 bytes
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_PAGE_TOKEN_H_
