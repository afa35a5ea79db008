/* The C example's keyed mode (examples/c_client/robotalk_c_keyed.c) against
 * the test vectors of docs/security.md (tests/data/keyed_vectors.txt): every
 * byte string the C code builds from the file's inputs is the file's.
 *   c_keyed_vectors_test VECTORS_FILE */
#include <sodium.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "robotalk_c_keyed.h"

#define MAX_VALUE 2048
static char names[64][48];
static char values[64][MAX_VALUE];
static int count;
static int failures, passes;

static const char* value(const char* name) {
  for (int i = 0; i < count; ++i)
    if (strcmp(names[i], name) == 0) return values[i];
  fprintf(stderr, "vectors: no '%s'\n", name);
  exit(1);
}

static size_t bytes(const char* name, uint8_t* out, size_t max) {
  const char* hex = value(name);
  size_t n = strlen(hex) / 2;
  if (n > max) n = max;
  for (size_t i = 0; i < n; ++i) {
    unsigned v;
    sscanf(hex + 2 * i, "%2x", &v);
    out[i] = (uint8_t)v;
  }
  return n;
}

static void expect_hex(const char* name, const uint8_t* got, size_t n) {
  char hex[MAX_VALUE];
  for (size_t i = 0; i < n && 2 * i + 2 < sizeof hex; ++i) sprintf(hex + 2 * i, "%02x", got[i]);
  hex[2 * n < sizeof hex ? 2 * n : sizeof hex - 1] = 0;
  if (strcmp(hex, value(name)) == 0) {
    ++passes;
  } else {
    printf("FAIL: %s\n  got      %s\n  expected %s\n", name, hex, value(name));
    ++failures;
  }
}

static void expect_text(const char* name, const char* got) {
  if (strcmp(got, value(name)) == 0) {
    ++passes;
  } else {
    printf("FAIL: %s: got '%s', expected '%s'\n", name, got, value(name));
    ++failures;
  }
}

static void expect_true(const char* what, int ok) {
  if (ok) {
    ++passes;
  } else {
    printf("FAIL: %s\n", what);
    ++failures;
  }
}

int main(int argc, char** argv) {
  if (argc != 2 || rtc_keyed_init() != 0) return 2;
  FILE* f = fopen(argv[1], "r");
  if (!f) return perror(argv[1]), 2;
  static char line[MAX_VALUE + 64];
  while (count < 64 && fgets(line, sizeof line, f)) {
    char* eq = strstr(line, " = ");
    if (line[0] == '#' || !eq) continue;
    *eq = 0;
    char* v = eq + 3;
    v[strcspn(v, "\n")] = 0;
    if (v[0] == '"') v[strlen(v) - 1] = 0, ++v;
    snprintf(names[count], sizeof names[count], "%s", line);
    snprintf(values[count], sizeof values[count], "%s", v);
    ++count;
  }
  fclose(f);

  uint8_t seed[32], nonce[16], kx_secret[32], kx_public[32], instance[16], server_nonce[16];
  rtc_identity client, server;
  bytes("client_seed", seed, 32);
  rtc_identity_from_seed(seed, &client);
  bytes("server_seed", seed, 32);
  rtc_identity_from_seed(seed, &server);
  expect_hex("client_key", client.public_key, 32);
  expect_hex("server_key", server.public_key, 32);
  char fingerprint[23];
  rtc_fingerprint(client.public_key, fingerprint);
  expect_text("client_fingerprint", fingerprint);

  const int64_t client_id =
      rtc_keyed_client_id(client.public_key, (uint32_t)strtoul(value("client_id_low"), 0, 10));
  char id_text[32];
  snprintf(id_text, sizeof id_text, "%lld", (long long)client_id);
  expect_text("client_id", id_text);

  bytes("client_nonce", nonce, 16);
  bytes("client_kx_secret", kx_secret, 32);
  crypto_scalarmult_base(kx_public, kx_secret);
  expect_hex("client_kx", kx_public, 32);
  uint8_t hello[RTC_HELLO_SIGNED_BYTES], signature[64];
  rtc_hello_signed(client.public_key, client_id, nonce, kx_public, hello);
  expect_hex("hello_signed", hello, sizeof hello);
  rtc_sign(&client, hello, sizeof hello, signature);
  expect_hex("hello_signature", signature, 64);

  uint8_t server_kx[32], answer[RTC_ANSWER_SIGNED_BYTES], answer_signature[64];
  bytes("instance_nonce", instance, 16);
  bytes("server_nonce", server_nonce, 16);
  bytes("server_kx", server_kx, 32);
  rtc_answer_signed(hello, client_id, nonce, instance, server_nonce, server_kx, server.public_key, answer);
  expect_hex("answer_signed", answer, sizeof answer);
  bytes("answer_signature", answer_signature, 64);
  expect_true("the answer's signature verifies",
              rtc_signature_verifies(server.public_key, answer, sizeof answer, answer_signature));

  rtc_session_keys keys;
  expect_true("session keys derive",
              rtc_session_keys_derive(kx_public, kx_secret, server_kx, answer, &keys) == 0);
  expect_hex("key_c2s", keys.c2s, 32);
  expect_hex("key_s2c", keys.s2c, 32);
  snprintf(id_text, sizeof id_text, "%lld", (long long)keys.session_id);
  expect_text("session_id", id_text);

  uint8_t package[MAX_VALUE / 2 + 16], mac[16];
  size_t n = bytes("package_before_mac", package, MAX_VALUE / 2);
  rtc_mac(keys.c2s, keys.session_id, package, n, mac);
  expect_hex("package_mac", mac, 16);
  n = bytes("reply_before_mac", package, MAX_VALUE / 2);
  bytes("reply_mac", package + n, 16);
  expect_true("the reply's MAC verifies", rtc_mac_verifies(keys.s2c, keys.session_id, package, n + 16));
  package[0] ^= 1;
  expect_true("a changed reply does not", !rtc_mac_verifies(keys.s2c, keys.session_id, package, n + 16));

  uint8_t broadcast[MAX_VALUE / 2];
  n = bytes("broadcast_signed", broadcast, sizeof broadcast);
  const char* channel = value("broadcast_channel");
  expect_true("the broadcast verifies",
              rtc_broadcast_verifies(channel, broadcast, n, server.public_key, instance));
  expect_true("not on another channel",
              !rtc_broadcast_verifies("ROBOTALK/other/STATE", broadcast, n, server.public_key, instance));
  expect_true("not by another key",
              !rtc_broadcast_verifies(channel, broadcast, n, client.public_key, instance));
  printf("%d checks passed, %d failed\n", passes, failures);
  return failures ? 1 : 0;
}
