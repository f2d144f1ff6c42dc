#include "gbdcs/server/auth.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sodium.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace gbdcs::server {

namespace {

void ensure_sodium() {
  static const int ok = sodium_init();
  if (ok < 0) throw std::runtime_error("libsodium could not initialise");
}

constexpr char kCrockford[] = "0123456789ABCDEFGHJKMNPQRSTVWXYZ";
constexpr char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::int64_t ms_of(contracts::UtcTime t) { return t.time_since_epoch().count(); }

}  // namespace

std::string UlidGenerator::next() {
  ensure_sodium();
  std::lock_guard lock(mutex_);
  const std::int64_t ms = ms_of(clock_.utc_now());
  if (ms == last_ms_) {
    // Monotonic within a millisecond: increment the random part.
    for (int i = 9; i >= 0; --i) {
      if (++last_random_[i] != 0) break;
    }
  } else {
    randombytes_buf(last_random_, sizeof last_random_);
    last_ms_ = ms;
  }
  std::string out(26, '0');
  auto t = static_cast<std::uint64_t>(ms);
  for (int i = 9; i >= 0; --i) {
    out[static_cast<std::size_t>(i)] = kCrockford[t & 31];
    t >>= 5;
  }
  // 80 bits of randomness -> 16 characters.
  std::uint64_t hi = 0, lo = 0;
  for (int i = 0; i < 2; ++i) hi = (hi << 8) | last_random_[i];
  for (int i = 2; i < 10; ++i) lo = (lo << 8) | last_random_[i];
  for (int i = 25; i >= 10; --i) {
    out[static_cast<std::size_t>(i)] = kCrockford[lo & 31];
    lo = (lo >> 5) | ((hi & 31) << 59);
    hi >>= 5;
  }
  return out;
}

std::string check_password_strength(std::string_view email, std::string_view password) {
  if (password.size() < 10) return "the password has fewer than 10 characters";
  const auto p = lower(password);
  const auto e = lower(email);
  if (p == e) return "the password is the e-mail address";
  const auto local = e.substr(0, e.find('@'));
  if (local.size() >= 3 && p.find(local) != std::string::npos)
    return "the password contains the e-mail address's name part";
  if (std::all_of(p.begin(), p.end(), [&](char c) { return c == p.front(); }))
    return "the password repeats one character";
  return {};
}

std::string hash_password(std::string_view password) {
  ensure_sodium();
  char out[crypto_pwhash_STRBYTES];
  if (crypto_pwhash_str(out, password.data(), password.size(), crypto_pwhash_OPSLIMIT_INTERACTIVE,
                        crypto_pwhash_MEMLIMIT_INTERACTIVE) != 0) {
    throw std::runtime_error("Argon2id hashing ran out of memory");
  }
  return out;
}

bool verify_password(std::string_view hash, std::string_view password) {
  ensure_sodium();
  const std::string h(hash);
  return crypto_pwhash_str_verify(h.c_str(), password.data(), password.size()) == 0;
}

std::string base64_encode(std::string_view bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const auto n = (static_cast<unsigned char>(bytes[i]) << 16) |
                   (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                   static_cast<unsigned char>(bytes[i + 2]);
    out += kB64[(n >> 18) & 63];
    out += kB64[(n >> 12) & 63];
    out += kB64[(n >> 6) & 63];
    out += kB64[n & 63];
  }
  if (i < bytes.size()) {
    auto n = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kB64[(n >> 18) & 63];
    out += kB64[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kB64[(n >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string base64url_encode(std::string_view bytes) {
  auto s = base64_encode(bytes);
  for (auto& c : s) {
    if (c == '+') c = '-';
    if (c == '/') c = '_';
  }
  while (!s.empty() && s.back() == '=') s.pop_back();
  return s;
}

std::optional<std::string> base64url_decode(std::string_view text) {
  std::string out;
  unsigned buffer = 0;
  int bits = 0;
  for (char c : text) {
    int v = -1;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    else if (c >= '0' && c <= '9') v = c - '0' + 52;
    else if (c == '-') v = 62;
    else if (c == '_') v = 63;
    else return std::nullopt;
    buffer = (buffer << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((buffer >> bits) & 0xFF);
    }
  }
  return out;
}

TokenService::TokenService(const contracts::Clock& clock, std::string secret, int ttl_s)
    : clock_(clock), secret_(std::move(secret)), ttl_s_(ttl_s), ids_(clock) {
  if (secret_.size() < 32)
    throw std::invalid_argument(
        "GBDCS_JWT_SECRET has " + std::to_string(secret_.size()) +
        " bytes; use at least 32 (e.g. `openssl rand -hex 32`)");
  if (ttl_s_ < 60 || ttl_s_ > 1800)
    throw std::invalid_argument("GBDCS_TOKEN_TTL_S must be between 60 and 1800 seconds");
}

std::string TokenService::random_secret() {
  ensure_sodium();
  unsigned char bytes[32];
  randombytes_buf(bytes, sizeof bytes);
  std::string hex(64, '0');
  constexpr char kHex[] = "0123456789abcdef";
  for (std::size_t i = 0; i < 32; ++i) {
    hex[2 * i] = kHex[bytes[i] >> 4];
    hex[2 * i + 1] = kHex[bytes[i] & 15];
  }
  return hex;
}

std::string TokenService::sign(std::string_view input) const {
  unsigned char mac[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  HMAC(EVP_sha256(), secret_.data(), static_cast<int>(secret_.size()),
       reinterpret_cast<const unsigned char*>(input.data()), input.size(), mac, &len);
  return std::string(reinterpret_cast<const char*>(mac), len);
}

IssuedToken TokenService::issue(std::int64_t user_id, const std::string& email) {
  IssuedToken t;
  t.claims.user_id = user_id;
  t.claims.email = email;
  t.claims.jti = ids_.next();
  t.claims.issued_at = clock_.utc_now();
  t.claims.expires_at = t.claims.issued_at + std::chrono::seconds(ttl_s_);
  const nlohmann::json header = {{"alg", "HS256"}, {"typ", "JWT"}};
  const nlohmann::json payload = {{"sub", std::to_string(user_id)},
                                  {"email", email},
                                  {"iat", ms_of(t.claims.issued_at) / 1000},
                                  {"exp", ms_of(t.claims.expires_at) / 1000},
                                  {"exp_ms", ms_of(t.claims.expires_at)},
                                  {"jti", t.claims.jti}};
  const auto input = base64url_encode(header.dump()) + "." + base64url_encode(payload.dump());
  t.token = input + "." + base64url_encode(sign(input));
  return t;
}

TokenError TokenService::verify(std::string_view token, TokenClaims& out) const {
  if (token.empty()) return TokenError::kMissing;
  const auto d1 = token.find('.');
  const auto d2 = token.find('.', d1 == std::string_view::npos ? 0 : d1 + 1);
  if (d1 == std::string_view::npos || d2 == std::string_view::npos ||
      token.find('.', d2 + 1) != std::string_view::npos || token.size() > 4096)
    return TokenError::kMalformed;
  const auto header_text = base64url_decode(token.substr(0, d1));
  const auto payload_text = base64url_decode(token.substr(d1 + 1, d2 - d1 - 1));
  const auto signature = base64url_decode(token.substr(d2 + 1));
  if (!header_text || !payload_text || !signature) return TokenError::kMalformed;
  nlohmann::json header, payload;
  try {
    header = nlohmann::json::parse(*header_text);
    payload = nlohmann::json::parse(*payload_text);
  } catch (const std::exception&) {
    return TokenError::kMalformed;
  }
  // Only HS256: never let the token choose "none" or another algorithm.
  if (!header.is_object() || header.value("alg", "") != "HS256") return TokenError::kMalformed;
  const auto expected = sign(token.substr(0, d2));
  if (signature->size() != expected.size() ||
      CRYPTO_memcmp(signature->data(), expected.data(), expected.size()) != 0)
    return TokenError::kBadSignature;
  try {
    out.user_id = std::stoll(payload.at("sub").get<std::string>());
    out.email = payload.at("email").get<std::string>();
    out.jti = payload.at("jti").get<std::string>();
    out.issued_at = contracts::UtcTime{std::chrono::seconds(payload.at("iat").get<std::int64_t>())};
    out.expires_at =
        contracts::UtcTime{std::chrono::milliseconds(payload.at("exp_ms").get<std::int64_t>())};
  } catch (const std::exception&) {
    return TokenError::kMalformed;
  }
  if (clock_.utc_now() >= out.expires_at) return TokenError::kExpired;
  return TokenError::kNone;
}

double LoginLimiter::retry_after_s(const std::string& key) {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(key);
  if (it == entries_.end()) return 0;
  const auto now = clock_.now();
  if (contracts::to_seconds(now - it->second.first_failure) > options_.window_s &&
      now >= it->second.blocked_until) {
    entries_.erase(it);
    return 0;
  }
  if (now >= it->second.blocked_until) return 0;
  return std::max(0.001, contracts::to_seconds(it->second.blocked_until - now));
}

void LoginLimiter::record_failure(const std::string& key) {
  std::lock_guard lock(mutex_);
  const auto now = clock_.now();
  auto& e = entries_[key];
  if (e.failures == 0 || contracts::to_seconds(now - e.first_failure) > options_.window_s) {
    e = Entry{0, now, now};
  }
  ++e.failures;
  if (e.failures >= options_.free_failures) {
    const int over = e.failures - options_.free_failures + 1;
    const double wait = std::min(options_.max_wait_s, std::pow(2.0, std::min(over, 30)));
    e.blocked_until = now + contracts::from_seconds(wait);
  }
  if (entries_.size() > 100000) entries_.clear();  // bounded memory under a flood
}

void LoginLimiter::record_success(const std::string& key) {
  std::lock_guard lock(mutex_);
  entries_.erase(key);
}

}  // namespace gbdcs::server
