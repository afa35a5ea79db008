/* Connecting a client: the ANNOUNCE search, the traffic layout, keys (see
 * robotalk_c_client.h). */
#define _POSIX_C_SOURCE 200809L
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "robotalk_c_internal.h"
#include "robotalk_c_url.h"
#include "robotalk_msgs_announce_t.h"

static void on_announce(const lcm_recv_buf_t* rbuf, const char* channel, const robotalk_msgs_announce_t* m,
                        void* user) {
  (void)rbuf; /* keyed: its signature proves only who signed it; the answer is what we check */
  (void)channel;
  rtc_client* c = user;
  for (int i = 0; i < m->num_robots; ++i) {
    const char* name = m->robots[i].name;
    if (strcmp(name, c->robot) == 0) {
      c->found = 1;
      c->announce_version = m->protocol_version;
      c->announce_keyed = m->keyed;
      c->announce_layout = m->traffic_layout;
      c->announce_server_id = m->server_id;
    } else if (!strstr(c->heard, name) && strlen(c->heard) + strlen(name) + 3 < sizeof c->heard) {
      if (c->heard[0]) strcat(c->heard, ", ");
      strcat(c->heard, name);
    }
  }
}

/* ---- connecting --------------------------------------------------------- */

static int open_layout(rtc_client* c, const char* url) {
  c->split = c->announce_layout == ROBOTALK_MSGS_ANNOUNCE_T_TRAFFIC_SPLIT;
  if (c->announce_layout != ROBOTALK_MSGS_ANNOUNCE_T_TRAFFIC_SINGLE && !c->split)
    return rtci_set_error(c, "unknown traffic layout %d in ANNOUNCE", c->announce_layout), -1;
  c->request_lcm = c->reply_lcm = c->main_lcm;
  if (!c->split) return 0;
  char request_url[512], reply_url[512];
  int bucket = (int)((uint64_t)c->client_id % 64);
  if (rtc_shifted_url(url, 1, request_url, sizeof request_url) != 0 ||
      rtc_shifted_url(url, 2 + bucket, reply_url, sizeof reply_url) != 0)
    return rtci_set_error(c, "the split layout needs a udpm://GROUP:PORT URL, not '%s'", url), -1;
  c->request_lcm = lcm_create(request_url);
  c->reply_lcm = lcm_create(reply_url);
  if (!c->request_lcm || !c->reply_lcm)
    return rtci_set_error(c, "cannot open %s or %s", request_url, reply_url), -1;
  return 0;
}

static int find_robot(rtc_client* c, double timeout_s) {
  rtci_checked_sub* sub = rtci_subscribe_announce(c->main_lcm, "ROBOTALK/ANNOUNCE", on_announce, c);
  const int64_t deadline = rtc_now_us() + (int64_t)(timeout_s * 1e6);
  while (!c->found && rtc_now_us() < deadline) rtci_handle_for(c, 50000);
  rtci_unsubscribe_checked(c->main_lcm, sub);
  if (!c->found)
    return rtci_set_error(c, "no robot '%s' announced within %.1f s (heard: %s)", c->robot, timeout_s,
                          c->heard[0] ? c->heard : "nothing"),
           -1;
  if (c->announce_version != kProtocolVersion)
    return rtci_set_error(c, "'%s' speaks protocol %d; this client speaks %d", c->robot, c->announce_version,
                          kProtocolVersion),
           -1;
  if (c->announce_keyed && !c->keyed)
    return rtci_set_error(
               c,
               "the server of '%s' requires keys (keyed mode, docs/security.md); give this client one "
               "(--key FILE or ROBOTALK_KEY)",
               c->robot),
           -1;
  if (!c->announce_keyed && c->keyed)
    return rtci_set_error(
               c, "the server of '%s' is in open mode; this client was given a key and talks keyed only",
               c->robot),
           -1;
  return 0;
}

rtc_client* rtc_connect(const char* url, const char* robot, double timeout_s, char* err, size_t err_len) {
  return rtc_connect_keyed(url, robot, NULL, NULL, timeout_s, err, err_len);
}

/* Keyed: reads the keys; the client id is one of the key's. */
static int load_keys(rtc_client* c, const char* key_file, const char* server_key_file) {
  if (rtc_keyed_init() != 0) return rtci_set_error(c, "libsodium cannot start"), -1;
  if (rtc_read_secret_key(key_file, &c->identity, c->error, sizeof c->error) != 0) return -1;
  if (server_key_file) {
    if (rtc_read_public_key(server_key_file, c->server_key, c->error, sizeof c->error) != 0) return -1;
    c->have_server_key = 1;
  }
  c->keyed = 1;
  uint32_t low = 0;
  if (rtci_random_bytes(&low, sizeof low) != 0) return rtci_set_error(c, "no /dev/urandom"), -1;
  c->client_id = rtc_keyed_client_id(c->identity.public_key, low);
  return 0;
}

rtc_client* rtc_connect_keyed(const char* url, const char* robot, const char* key_file,
                              const char* server_key_file, double timeout_s, char* err, size_t err_len) {
  rtc_client* c = calloc(1, sizeof *c);
  if (!c) return NULL;
  snprintf(c->robot, sizeof c->robot, "%s", robot);
  c->next_sequence = 1;
  c->next_id = 1;
  if (key_file && load_keys(c, key_file, server_key_file) != 0) {
    snprintf(err, err_len, "%s", c->error);
    free(c);
    return NULL;
  }
  while (c->client_id == 0)
    if (rtci_random_bytes(&c->client_id, sizeof c->client_id) != 0) break;
  char lcm_url[512];
  rtc_lcm_url_of(url, lcm_url, sizeof lcm_url);
  url = lcm_url;
  c->main_lcm = lcm_create(url);
  int ok = c->client_id != 0 && c->main_lcm != NULL;
  if (!ok) rtci_set_error(c, "cannot open LCM on '%s'", url);
  ok = ok && find_robot(c, timeout_s) == 0 && open_layout(c, url) == 0;
  if (ok) {
    uint64_t hex = (uint64_t)c->client_id;
    snprintf(c->hello_channel, sizeof c->hello_channel, "ROBOTALK/%s/HELLO", robot);
    snprintf(c->hello_answer_channel, sizeof c->hello_answer_channel, "ROBOTALK/%s/HELLO/%016" PRIx64, robot,
             hex);
    snprintf(c->request_channel, sizeof c->request_channel, "ROBOTALK/%s/REQUEST", robot);
    snprintf(c->reply_channel, sizeof c->reply_channel, "ROBOTALK/%s/REPLY/%016" PRIx64, robot, hex);
    c->hello_sub =
        rtci_subscribe_hello_answer(c->reply_lcm, c->hello_answer_channel, rtci_on_hello_answer, c);
    c->reply_sub = rtci_subscribe_reply_package(c->reply_lcm, c->reply_channel, rtci_on_reply, c);
    rtci_checked_set_queue_capacity(c->reply_sub, 1000);
    ok = rtci_say_hello(c, timeout_s) == 0;
  }
  if (!ok) {
    snprintf(err, err_len, "%s", c->error);
    rtc_close(c);
    return NULL;
  }
  return c;
}

void rtc_close(rtc_client* c) {
  if (!c) return;
  for (int i = 0; i < kMaxPackages; ++i) free(c->packages[i].bytes);
  if (c->config) robotalk_msgs_robot_config_t_destroy(c->config);
  rtci_unsubscribe_checked(c->reply_lcm, c->hello_sub);
  rtci_unsubscribe_checked(c->reply_lcm, c->reply_sub);
  if (c->reply_lcm && c->reply_lcm != c->main_lcm) lcm_destroy(c->reply_lcm);
  if (c->request_lcm && c->request_lcm != c->main_lcm) lcm_destroy(c->request_lcm);
  if (c->main_lcm) lcm_destroy(c->main_lcm);
  free(c);
}
