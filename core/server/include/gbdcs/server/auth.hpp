// Auth for the server: request ids, passwords, tokens, login back-off. Plain logic on an
// injected Clock; the HTTP layer only calls it.
//
//   UlidGenerator     26-character ULIDs (48-bit ms time + 80 random bits from libsodium),
//                     monotonic within a millisecond; request ids and token ids.
//   check_password_strength / hash_password / verify_password
//                     policy: >= 10 characters, not the e-mail nor containing its local part;
//                     Argon2id via libsodium crypto_pwhash_str (interactive limits).
//   TokenService      HS256 JWT (header.payload.signature, base64url) signed with a secret of
//                     >= 32 bytes; claims sub (user id), email, iat, exp, jti. ttl <= 1800 s.
//                     verify() checks alg, signature (constant time), expiry by the Clock.
//   LoginLimiter      failures per key (client address, e-mail): after `free_failures` within
//                     `window_s`, every further attempt waits 2^(n - free) s, capped at max_s.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "gbdcs/contracts/clock.hpp"

namespace gbdcs::server {

class UlidGenerator {
 public:
  explicit UlidGenerator(const contracts::Clock& clock) : clock_(clock) {}
  std::string next();

 private:
  const contracts::Clock& clock_;
  std::mutex mutex_;
  std::int64_t last_ms_ = -1;
  unsigned char last_random_[10] = {};
};

// Empty when acceptable; otherwise what is wrong with it, for the operator.
std::string check_password_strength(std::string_view email, std::string_view password);
std::string hash_password(std::string_view password);  // throws std::runtime_error (memory)
bool verify_password(std::string_view hash, std::string_view password);

std::string base64url_encode(std::string_view bytes);
std::optional<std::string> base64url_decode(std::string_view text);
std::string base64_encode(std::string_view bytes);

struct TokenClaims {
  std::int64_t user_id = 0;
  std::string email;
  std::string jti;
  contracts::UtcTime issued_at{};
  contracts::UtcTime expires_at{};
};

enum class TokenError { kNone, kMissing, kMalformed, kBadSignature, kExpired };

struct IssuedToken {
  std::string token;
  TokenClaims claims;
};

class TokenService {
 public:
  // secret: >= 32 bytes (throws std::invalid_argument otherwise); ttl_s in [60, 1800].
  TokenService(const contracts::Clock& clock, std::string secret, int ttl_s = 1800);
  IssuedToken issue(std::int64_t user_id, const std::string& email);
  // The claims, or why not.
  TokenError verify(std::string_view token, TokenClaims& out) const;
  int ttl_s() const { return ttl_s_; }
  // A random secret (hex of 32 random bytes) for development runs.
  static std::string random_secret();

 private:
  std::string sign(std::string_view signing_input) const;
  const contracts::Clock& clock_;
  std::string secret_;
  int ttl_s_;
  UlidGenerator ids_;
};

struct LoginLimiterOptions {
  int free_failures = 5;
  double window_s = 900;
  double max_wait_s = 900;
};

class LoginLimiter {
 public:
  explicit LoginLimiter(const contracts::Clock& clock, LoginLimiterOptions options = {})
      : clock_(clock), options_(options) {}
  // Seconds to wait before `key` may try again; 0 = may try now.
  double retry_after_s(const std::string& key);
  void record_failure(const std::string& key);
  void record_success(const std::string& key);

 private:
  struct Entry {
    int failures = 0;
    contracts::Duration first_failure{};
    contracts::Duration blocked_until{};
  };
  const contracts::Clock& clock_;
  LoginLimiterOptions options_;
  std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

}  // namespace gbdcs::server
