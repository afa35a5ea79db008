/* Keyed mode from docs/security.md: see robotalk_c_keyed.h. */
#define _POSIX_C_SOURCE 200809L
#include "robotalk_c_keyed.h"

#include <sodium.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static size_t put(uint8_t* out, const void* data, size_t n) {
  memcpy(out, data, n);
  return n;
}
static size_t put_tag(uint8_t* out, const char* tag) { return put(out, tag, strlen(tag)); }
static size_t put_le64(uint8_t* out, int64_t v) {
  for (int i = 0; i < 8; ++i) out[i] = (uint8_t)((uint64_t)v >> (8 * i));
  return 8;
}
/* BLAKE2b-256(key, tag || data) */
static void hash_tagged(uint8_t out[32], const uint8_t* key, size_t key_len, const char* tag,
                        const uint8_t* data, size_t n) {
  crypto_generichash_state st;
  crypto_generichash_init(&st, key, key_len, 32);
  crypto_generichash_update(&st, (const unsigned char*)tag, strlen(tag));
  crypto_generichash_update(&st, data, n);
  crypto_generichash_final(&st, out, 32);
}

int rtc_keyed_init(void) { return sodium_init() < 0 ? -1 : 0; }

void rtc_identity_from_seed(const uint8_t seed[32], rtc_identity* id) {
  crypto_sign_seed_keypair(id->public_key, id->secret_key, seed);
}

static int unhex(const char* text, uint8_t* out, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    unsigned v;
    if (sscanf(text + 2 * i, "%2x", &v) != 1) return -1;
    out[i] = (uint8_t)v;
  }
  return 0;
}

/* The first line of `path` that is not a comment. */
static int first_line(const char* path, char* line, size_t len, int secret, char* err, size_t err_len) {
  FILE* f = fopen(path, "r");
  if (!f) return snprintf(err, err_len, "%s: cannot open", path), -1;
  struct stat st;
  if (secret && (fstat(fileno(f), &st) != 0 || (st.st_mode & 077) != 0)) {
    fclose(f);
    return snprintf(err, err_len,
                    "%s: the secret key must not be readable by group or others; run chmod 600 %s", path,
                    path),
           -1;
  }
  int found = 0;
  while (!found && fgets(line, (int)len, f)) found = line[0] != '#' && line[0] != '\n';
  fclose(f);
  return found ? 0 : (snprintf(err, err_len, "%s: empty", path), -1);
}

int rtc_read_secret_key(const char* path, rtc_identity* id, char* err, size_t err_len) {
  char line[256];
  uint8_t seed[32];
  const char* tag = "robotalk-secret-key-v1 ";
  if (first_line(path, line, sizeof line, 1, err, err_len) != 0) return -1;
  if (strncmp(line, tag, strlen(tag)) != 0 || strlen(line) < strlen(tag) + 64 ||
      unhex(line + strlen(tag), seed, 32) != 0)
    return snprintf(err, err_len, "%s: expected '%s<64 hex digits>'", path, tag), -1;
  rtc_identity_from_seed(seed, id);
  sodium_memzero(seed, sizeof seed);
  return 0;
}

int rtc_read_public_key(const char* path, uint8_t key[32], char* err, size_t err_len) {
  char line[256];
  if (first_line(path, line, sizeof line, 0, err, err_len) != 0) return -1;
  if (strncmp(line, "ed25519:", 8) != 0 || strlen(line) < 8 + 64 || unhex(line + 8, key, 32) != 0)
    return snprintf(err, err_len, "%s: expected 'ed25519:<64 hex digits> NAME'", path), -1;
  return 0;
}

void rtc_fingerprint(const uint8_t key[32], char out[23]) {
  uint8_t h[32];
  crypto_generichash(h, sizeof h, key, 32, NULL, 0);
  snprintf(out, 23, "rt:%02x%02x:%02x%02x:%02x%02x:%02x%02x", h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7]);
}

void rtc_kx_keypair(uint8_t public_key[32], uint8_t secret_key[32]) {
  crypto_kx_keypair(public_key, secret_key);
}

void rtc_sign(const rtc_identity* id, const uint8_t* bytes, size_t n, uint8_t signature[64]) {
  crypto_sign_detached(signature, NULL, bytes, n, id->secret_key);
}

int rtc_signature_verifies(const uint8_t key[32], const uint8_t* bytes, size_t n,
                           const uint8_t signature[64]) {
  return crypto_sign_verify_detached(signature, bytes, n, key) == 0;
}

int64_t rtc_keyed_client_id(const uint8_t key[32], uint32_t low) {
  uint8_t h[32];
  hash_tagged(h, NULL, 0, "robotalk-client-id-v1", key, 32);
  const uint32_t prefix =
      ((uint32_t)h[0] << 24 | (uint32_t)h[1] << 16 | (uint32_t)h[2] << 8 | (uint32_t)h[3]) & 0x7fffffffU;
  return (int64_t)((uint64_t)prefix << 32 | (low == 0 ? 1U : low));
}

void rtc_hello_signed(const uint8_t client_key[32], int64_t client_id, const uint8_t nonce[16],
                      const uint8_t client_kx[32], uint8_t out[RTC_HELLO_SIGNED_BYTES]) {
  size_t at = put_tag(out, "robotalk-hello-v1");
  at += put(out + at, client_key, 32);
  at += put_le64(out + at, client_id);
  at += put(out + at, nonce, 16);
  put(out + at, client_kx, 32);
}

void rtc_answer_signed(const uint8_t hello_signed[RTC_HELLO_SIGNED_BYTES], int64_t client_id,
                       const uint8_t client_nonce[16], const uint8_t instance_nonce[16],
                       const uint8_t server_nonce[16], const uint8_t server_kx[32],
                       const uint8_t server_key[32], uint8_t out[RTC_ANSWER_SIGNED_BYTES]) {
  size_t at = put_tag(out, "robotalk-answer-v1");
  at += put(out + at, hello_signed, RTC_HELLO_SIGNED_BYTES);
  at += put_le64(out + at, client_id);
  at += put(out + at, client_nonce, 16);
  at += put(out + at, instance_nonce, 16);
  at += put(out + at, server_nonce, 16);
  at += put(out + at, server_kx, 32);
  put(out + at, server_key, 32);
}

int rtc_session_keys_derive(const uint8_t client_kx[32], const uint8_t client_kx_secret[32],
                            const uint8_t server_kx[32], const uint8_t answer_signed[RTC_ANSWER_SIGNED_BYTES],
                            rtc_session_keys* out) {
  uint8_t rx[32], tx[32], th[32], sid[32];
  if (crypto_kx_client_session_keys(rx, tx, client_kx, client_kx_secret, server_kx) != 0) return -1;
  hash_tagged(th, NULL, 0, "robotalk-transcript-v1", answer_signed, RTC_ANSWER_SIGNED_BYTES);
  hash_tagged(out->c2s, tx, sizeof tx, "robotalk-c2s-v1", th, sizeof th);
  hash_tagged(out->s2c, rx, sizeof rx, "robotalk-s2c-v1", th, sizeof th);
  hash_tagged(sid, NULL, 0, "robotalk-sid-v1", th, sizeof th);
  uint64_t id = 0;
  for (int i = 0; i < 8; ++i) id |= (uint64_t)sid[i] << (8 * i);
  id &= 0x7fffffffffffffffULL;
  out->session_id = id == 0 ? 1 : (int64_t)id;
  sodium_memzero(rx, sizeof rx);
  sodium_memzero(tx, sizeof tx);
  return 0;
}

void rtc_mac(const uint8_t key[32], int64_t session_id, const uint8_t* bytes, size_t n, uint8_t mac[16]) {
  uint8_t sid[8];
  put_le64(sid, session_id);
  crypto_generichash_state st;
  crypto_generichash_init(&st, key, 32, 16);
  crypto_generichash_update(&st, sid, sizeof sid);
  crypto_generichash_update(&st, bytes, n);
  crypto_generichash_final(&st, mac, 16);
}

int rtc_mac_verifies(const uint8_t key[32], int64_t session_id, const uint8_t* bytes, size_t n) {
  uint8_t mac[16];
  if (n < 16) return 0;
  rtc_mac(key, session_id, bytes, n - 16, mac);
  return sodium_memcmp(mac, bytes + n - 16, 16) == 0;
}

int rtc_broadcast_verifies(const char* channel, const uint8_t* bytes, size_t n, const uint8_t server_key[32],
                           const uint8_t* instance) {
  if (n < RTC_SIGNATURE_SUFFIX_BYTES + 8) return 0;
  const uint8_t* suffix = bytes + n - RTC_SIGNATURE_SUFFIX_BYTES;
  if (memcmp(suffix, "rtsig-v1", 8) != 0 || memcmp(suffix + 8, server_key, 32) != 0) return 0;
  if (instance && memcmp(suffix + 40, instance, 16) != 0) return 0;
  /* Signed: "robotalk-broadcast-v1" || channel || 0x00 || every byte before the signature. */
  const char* domain = "robotalk-broadcast-v1";
  const size_t covered_len = strlen(domain) + strlen(channel) + 1 + (n - 64);
  uint8_t* covered = sodium_malloc(covered_len);
  if (!covered) return 0;
  size_t at = put_tag(covered, domain);
  at += put_tag(covered + at, channel);
  covered[at++] = 0;
  put(covered + at, bytes, n - 64);
  const int ok = crypto_sign_verify_detached(bytes + n - 64, covered, covered_len, server_key) == 0;
  sodium_free(covered);
  return ok;
}

void rtc_keyed_hello(robotalk_msgs_hello_t* hello, const rtc_identity* id, uint8_t kx_public[32],
                     uint8_t kx_secret[32]) {
  uint8_t signed_bytes[RTC_HELLO_SIGNED_BYTES];
  rtc_kx_keypair(kx_public, kx_secret);
  hello->keyed = 1;
  memcpy(hello->client_key, id->public_key, 32);
  memcpy(hello->client_kx, kx_public, 32);
  rtc_hello_signed(id->public_key, hello->client_id, hello->client_nonce, kx_public, signed_bytes);
  rtc_sign(id, signed_bytes, sizeof signed_bytes, hello->signature);
}

int rtc_check_answer(const robotalk_msgs_hello_answer_t* m, const uint8_t client_key[32],
                     const uint8_t kx_public[32], const uint8_t kx_secret[32],
                     const uint8_t trusted_server_key[32], rtc_session_keys* keys, char* why,
                     size_t why_len) {
  uint8_t hello[RTC_HELLO_SIGNED_BYTES], answer[RTC_ANSWER_SIGNED_BYTES];
  char want[23], got[23];
  if (!m->keyed) return snprintf(why, why_len, "the server answered in open mode"), -1;
  if (memcmp(m->server_key, trusted_server_key, 32) != 0) {
    rtc_fingerprint(trusted_server_key, want);
    rtc_fingerprint(m->server_key, got);
    return snprintf(why, why_len, "answer signed by %s, expected server key %s", got, want), -1;
  }
  rtc_hello_signed(client_key, m->client_id, m->client_nonce, kx_public, hello);
  rtc_answer_signed(hello, m->client_id, m->client_nonce, m->instance_nonce, m->server_nonce, m->server_kx,
                    m->server_key, answer);
  if (!rtc_signature_verifies(m->server_key, answer, sizeof answer, m->signature))
    return snprintf(why, why_len, "bad signature on the answer"), -1;
  if (rtc_session_keys_derive(kx_public, kx_secret, m->server_kx, answer, keys) != 0)
    return snprintf(why, why_len, "unusable key-exchange key"), -1;
  if (keys->session_id != m->session_id)
    return snprintf(why, why_len, "the answer's session id is not the one its transcript gives"), -1;
  return 0;
}
