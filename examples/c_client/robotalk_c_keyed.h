/* Keyed mode for the C client, written from docs/security.md ("Keyed mode
 * byte by byte") and checked against its test vectors
 * (tests/data/keyed_vectors.txt, tests/examples/c_keyed_vectors_test.c).
 * Pure functions over byte arrays; libsodium does the cryptography.
 *
 * Thread safety: every function may be called from any thread once
 * rtc_keyed_init() returned 0. Errors: -1 with the reason in err. */
#ifndef ROBOTALK_C_KEYED_H
#define ROBOTALK_C_KEYED_H

#include <stddef.h>
#include <stdint.h>

#include "robotalk_msgs_hello_answer_t.h"
#include "robotalk_msgs_hello_t.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
  RTC_HELLO_SIGNED_BYTES = 105,
  RTC_ANSWER_SIGNED_BYTES = 243,
  RTC_SIGNATURE_SUFFIX_BYTES = 120, /* "rtsig-v1" || S || I || signature */
};

/* An identity: Ed25519 public key and libsodium's 64-byte secret key. */
typedef struct {
  uint8_t public_key[32];
  uint8_t secret_key[64];
} rtc_identity;

/* The keys of one session. */
typedef struct {
  int64_t session_id;
  uint8_t c2s[32], s2c[32];
} rtc_session_keys;

/* sodium_init(); 0, or -1 when libsodium cannot start. */
int rtc_keyed_init(void);

/* The identity of a 32-byte seed (crypto_sign_seed_keypair). */
void rtc_identity_from_seed(const uint8_t seed[32], rtc_identity* id);
/* Reads a secret key file ("robotalk-secret-key-v1 <64 hex>", '#' lines
 * before it); refuses one that group or others may read. */
int rtc_read_secret_key(const char* path, rtc_identity* id, char* err, size_t err_len);
/* Reads a .pub file ("ed25519:<64 hex> NAME"). */
int rtc_read_public_key(const char* path, uint8_t key[32], char* err, size_t err_len);
/* "rt:1a2b:3c4d:5e6f:7a8b" (22 characters and a NUL). */
void rtc_fingerprint(const uint8_t key[32], char out[23]);

/* A fresh X25519 pair for one session (crypto_kx_keypair). */
void rtc_kx_keypair(uint8_t public_key[32], uint8_t secret_key[32]);
/* Ed25519 detached signature of bytes[0..n). */
void rtc_sign(const rtc_identity* id, const uint8_t* bytes, size_t n, uint8_t signature[64]);
/* 1 when `signature` is `key`'s over bytes[0..n). */
int rtc_signature_verifies(const uint8_t key[32], const uint8_t* bytes, size_t n,
                           const uint8_t signature[64]);

/* A client id of `key`: its top half names the key; `low` 0 is made 1. */
int64_t rtc_keyed_client_id(const uint8_t key[32], uint32_t low);

/* The hello's signed bytes. */
void rtc_hello_signed(const uint8_t client_key[32], int64_t client_id, const uint8_t nonce[16],
                      const uint8_t client_kx[32], uint8_t out[RTC_HELLO_SIGNED_BYTES]);
/* The answer's signed bytes (the hello's inside). */
void rtc_answer_signed(const uint8_t hello_signed[RTC_HELLO_SIGNED_BYTES], int64_t client_id,
                       const uint8_t client_nonce[16], const uint8_t instance_nonce[16],
                       const uint8_t server_nonce[16], const uint8_t server_kx[32],
                       const uint8_t server_key[32], uint8_t out[RTC_ANSWER_SIGNED_BYTES]);
/* Session keys from the client's ephemeral pair, the server's kx key and the
 * answer's signed bytes. -1 for an unusable server kx key. */
int rtc_session_keys_derive(const uint8_t client_kx[32], const uint8_t client_kx_secret[32],
                            const uint8_t server_kx[32], const uint8_t answer_signed[RTC_ANSWER_SIGNED_BYTES],
                            rtc_session_keys* out);
/* BLAKE2b-128(key, LE64(session_id) || bytes[0..n)). */
void rtc_mac(const uint8_t key[32], int64_t session_id, const uint8_t* bytes, size_t n, uint8_t mac[16]);
/* 1 when the last 16 bytes of bytes[0..n) are their MAC (constant time), else 0. */
int rtc_mac_verifies(const uint8_t key[32], int64_t session_id, const uint8_t* bytes, size_t n);
/* 1 when bytes[0..n) end with a signature suffix by `server_key` for
 * `channel` (and, when instance is not NULL, that server instance). */
int rtc_broadcast_verifies(const char* channel, const uint8_t* bytes, size_t n, const uint8_t server_key[32],
                           const uint8_t* instance);

/* Makes `hello` (client_id and client_nonce set) keyed: a fresh ephemeral
 * pair (its secret to kx_secret), the key, the signature. */
void rtc_keyed_hello(robotalk_msgs_hello_t* hello, const rtc_identity* id, uint8_t kx_public[32],
                     uint8_t kx_secret[32]);
/* Checks an answer (session_id > 0) to the hello made with client_key and the
 * kx pair: keyed, signed by trusted_server_key, and its session id the derived
 * one; fills keys. 0, or -1 with the reason in why. */
int rtc_check_answer(const robotalk_msgs_hello_answer_t* m, const uint8_t client_key[32],
                     const uint8_t kx_public[32], const uint8_t kx_secret[32],
                     const uint8_t trusted_server_key[32], rtc_session_keys* keys, char* why, size_t why_len);

#ifdef __cplusplus
}
#endif
#endif
