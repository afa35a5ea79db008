/* A small RoboTalk client in C: see robotalk_c_client.h. Sessions, packages,
 * replies; connecting is in robotalk_c_connect.c. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <inttypes.h>
#include <lcm/lcm.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <time.h>

#include "robotalk_c_internal.h"
#include "robotalk_msgs_hello_t.h"
#include "robotalk_msgs_package_t.h"

void rtci_set_error(rtc_client* c, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(c->error, sizeof c->error, fmt, ap);
  va_end(ap);
}

const char* rtc_error(const rtc_client* c) { return c->error; }
int64_t rtc_client_id(const rtc_client* c) { return c->client_id; }
int64_t rtc_session_id(const rtc_client* c) { return c->session_id; }
int64_t rtc_server_id(const rtc_client* c) { return c->server_id; }
int rtc_split_layout(const rtc_client* c) { return c->split; }

const char* rtc_signal_name(int signal) {
  static const char* names[] = {"SUCCESS", "MODIFIED", "NA", "BUSY", "INTERRUPTED", "ERROR", "PANIC"};
  if (signal >= 0 && signal <= 6) return names[signal];
  return signal == RTC_UNKNOWN_OUTCOME ? "UNKNOWN_OUTCOME" : "?";
}

int64_t rtc_now_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

int64_t rtc_server_now_us(const rtc_client* c) { return rtc_now_us() + c->clock_offset_us; }
int rtc_clock_stale(const rtc_client* c) { return c->clock_stale; }

int rtci_random_bytes(void* out, size_t n) {
  FILE* f = fopen("/dev/urandom", "rb");
  if (!f) return -1;
  size_t got = fread(out, 1, n, f);
  fclose(f);
  return got == n ? 0 : -1;
}

/* ---- receiving ---------------------------------------------------------- */

static pending_package* find_package(rtc_client* c, int64_t sequence) {
  for (int i = 0; i < kMaxPackages; ++i)
    if (c->packages[i].used && c->packages[i].sequence == sequence) return &c->packages[i];
  return NULL;
}

static const rtc_reply* find_reply(const rtc_client* c, int64_t id) {
  for (int i = 0; i < c->reply_count; ++i)
    if (c->replies[i].id == id) return &c->replies[i];
  return NULL;
}

static void file_reply(rtc_client* c, const rtc_reply* r) {
  if (find_reply(c, r->id)) return; /* a second copy: ignored */
  c->replies[c->reply_next] = *r;
  c->reply_next = (c->reply_next + 1) % kMaxReplies;
  if (c->reply_count < kMaxReplies) ++c->reply_count;
}

/* A new server instance answered: what was acknowledged by the old one may or may not have run. */
/* The items of an acknowledged package whose session is gone: they may or may
 * not have run; never re-sent (the C++ client's UnknownOutcomeError). */
static void unknown_outcome(rtc_client* c, const pending_package* p, const char* why) {
  for (int k = 0; k < p->n_ids; ++k) {
    rtc_reply r = {.id = p->ids[k], .signal = RTC_UNKNOWN_OUTCOME};
    snprintf(r.message, sizeof r.message, "may or may not have run (%s); query or re-plan", why);
    file_reply(c, &r); /* ignored for an item that has its final reply */
  }
}

/* A new server instance answered: what the old one acknowledged may or may not have run. */
static void server_changed(rtc_client* c, int64_t new_server_id) {
  char why[96];
  snprintf(why, sizeof why, "server instance %016" PRIx64 " is gone", (uint64_t)c->server_id);
  for (int i = 0; i < kMaxPackages; ++i)
    if (c->packages[i].used && c->packages[i].acked) unknown_outcome(c, &c->packages[i], why);
  c->server_id = new_server_id;
  c->clock_stale = 1;
}

void rtci_on_reply(const lcm_recv_buf_t* rbuf, const char* channel, const robotalk_msgs_reply_package_t* m,
                   void* user) {
  rtc_client* c = user;
  int64_t t4 = rtc_now_us();
  if (m->protocol_version != kProtocolVersion || m->client_id != c->client_id) return;
  /* Keyed: a reply of our session must carry its MAC; SESSION_UNKNOWN has none but the
   * server key's signature, of any instance (a fake server's would end our sessions). */
  if (c->keyed && m->session_status != ROBOTALK_MSGS_REPLY_PACKAGE_T_SESSION_UNKNOWN &&
      (m->session_id != c->keys.session_id ||
       !rtc_mac_verifies(c->keys.s2c, c->keys.session_id, rbuf->data, rbuf->data_size)))
    return;
  if (c->keyed && m->session_status == ROBOTALK_MSGS_REPLY_PACKAGE_T_SESSION_UNKNOWN &&
      !rtc_broadcast_verifies(channel, rbuf->data, rbuf->data_size, c->server_key, NULL))
    return;
  if (m->server_id != c->server_id && c->server_id != 0) server_changed(c, m->server_id);
  pending_package* p = m->ack_sequence > 0 ? find_package(c, m->ack_sequence) : NULL;
  if (m->session_status == ROBOTALK_MSGS_REPLY_PACKAGE_T_SESSION_UNKNOWN) {
    if (p && p->session_id == m->session_id) {
      if (p->acked) /* its first copy was accepted in the session that has expired since */
        unknown_outcome(c, p, "its session expired");
      else
        p->session_unknown = 1; /* nothing in it ran: send it again in a new session */
    }
    if (m->session_id == c->session_id) c->hello_answered = 0; /* say hello again */
    return;
  }
  if (m->session_id != c->session_id) return; /* an older session's late answer */
  if (p && !p->acked) {
    p->acked = 1;
    if (p->tries == 1) {
      p->have_clock = 1;
      p->t1 = p->first_send_us;
      p->t4 = t4;
      p->server_receive_us = m->server_receive_us;
      p->server_send_us = m->server_send_us;
    }
  }
  for (int i = 0; i < m->num_replies; ++i) {
    const robotalk_msgs_reply_t* in = &m->replies[i];
    rtc_reply r = {
        .id = in->id, .signal = in->signal, .exec_time_us = in->exec_time_us, .lateness_us = in->lateness_us};
    snprintf(r.message, sizeof r.message, "%s", in->message);
    r.num_values = in->num_values < RTC_MAX_VALUES ? in->num_values : RTC_MAX_VALUES;
    for (int k = 0; k < r.num_values; ++k) r.values[k] = in->values[k];
    file_reply(c, &r);
  }
}

void rtci_on_hello_answer(const lcm_recv_buf_t* rbuf, const char* channel,
                          const robotalk_msgs_hello_answer_t* m, void* user) {
  (void)rbuf;
  (void)channel;
  rtc_client* c = user;
  if (m->client_id != c->client_id || memcmp(m->client_nonce, c->nonce, 16) != 0) return; /* not our hello */
  /* Keyed: an answer that does not verify (forged, another server's key) is
   * ignored: the real one may follow. With no --server-key, the first answer
   * that verifies names the server (trusted on first use, not pinned). */
  if (c->keyed && m->session_id != 0) {
    const uint8_t* trusted = c->have_server_key ? c->server_key : m->server_key;
    if (rtc_check_answer(m, c->identity.public_key, c->kx_public, c->kx_secret, trusted, &c->keys, c->ignored,
                         sizeof c->ignored) != 0) {
      fprintf(stderr, "robotalk-c: answer ignored: %s\n", c->ignored);
      return;
    }
    if (!c->have_server_key) {
      char fingerprint[23];
      rtc_fingerprint(m->server_key, fingerprint);
      fprintf(stderr, "robotalk-c: trusting server key %s (not pinned; --server-key FILE.pub checks it)\n",
              fingerprint);
      memcpy(c->server_key, m->server_key, 32);
      c->have_server_key = 1;
    }
  }
  c->hello_answered = 1;
  c->session_id = m->session_id;
  memcpy(c->instance_nonce, m->instance_nonce, 16);
  if (c->server_id != 0 && m->server_id != c->server_id) c->clock_stale = 1;
  c->server_id = m->server_id;
  snprintf(c->refusal, sizeof c->refusal, "%s", m->session_id == 0 ? m->refusal : "");
  if (m->keyed && !c->keyed) snprintf(c->refusal, sizeof c->refusal, "the server answered in keyed mode");
}

static void on_config(const lcm_recv_buf_t* rbuf, const char* channel, const robotalk_msgs_robot_config_t* m,
                      void* user) {
  rtc_client* c = user;
  if (c->keyed &&
      !rtc_broadcast_verifies(channel, rbuf->data, rbuf->data_size, c->server_key, c->instance_nonce))
    return; /* not signed by our server's instance */
  if (c->config) robotalk_msgs_robot_config_t_destroy(c->config);
  c->config = robotalk_msgs_robot_config_t_copy(m);
}

/* Handles what arrives on any of the client's LCM instances for at most wait_us. */
void rtci_handle_for(rtc_client* c, int64_t wait_us) {
  lcm_t* all[2] = {c->main_lcm, c->reply_lcm}; /* request_lcm only publishes */
  int n = c->split ? 2 : 1;
  fd_set fds;
  FD_ZERO(&fds);
  int max_fd = -1;
  for (int i = 0; i < n; ++i) {
    int fd = lcm_get_fileno(all[i]);
    FD_SET(fd, &fds);
    if (fd > max_fd) max_fd = fd;
  }
  struct timeval tv = {.tv_sec = wait_us / 1000000, .tv_usec = wait_us % 1000000};
  if (select(max_fd + 1, &fds, NULL, NULL, &tv) <= 0) return;
  for (int i = 0; i < n; ++i)
    if (FD_ISSET(lcm_get_fileno(all[i]), &fds)) lcm_handle(all[i]);
}

/* ---- sending ------------------------------------------------------------ */

static int publish_package(rtc_client* c, robotalk_msgs_package_t* pkg, uint8_t** bytes_out, int* size_out) {
  int size = robotalk_msgs_package_t_encoded_size(pkg);
  uint8_t* bytes = malloc((size_t)size);
  if (!bytes || robotalk_msgs_package_t_encode(bytes, 0, size, pkg) != size) {
    free(bytes);
    rtci_set_error(c, "cannot encode a package");
    return -1;
  }
  if (c->keyed) /* the MAC is the encoding's last 16 bytes and covers every byte before */
    rtc_mac(c->keys.c2s, pkg->header.session_id, bytes, (size_t)size - 16, bytes + size - 16);
  c->last_new_package_us = rtc_now_us(); /* before sending: a clock sample's t1 */
  lcm_publish(c->request_lcm, c->request_channel, bytes, (unsigned)size);
  if (bytes_out) {
    *bytes_out = bytes;
    *size_out = size;
  } else {
    free(bytes);
  }
  return 0;
}

static void fill_header(rtc_client* c, robotalk_msgs_package_header_t* h, int8_t payload_type, int32_t size,
                        int8_t mode) {
  memset(h, 0, sizeof *h);
  h->protocol_version = kProtocolVersion;
  h->client_id = c->client_id;
  h->session_id = c->session_id;
  h->sequence = c->next_sequence++;
  h->send_time_us = rtc_now_us();
  h->payload_type = payload_type;
  h->payload_size = size;
  h->mode = mode;
}

static void send_heartbeat(rtc_client* c) {
  robotalk_msgs_package_t pkg;
  memset(&pkg, 0, sizeof pkg); /* no payload; mac = 16 zero bytes (open mode) */
  fill_header(c, &pkg.header, ROBOTALK_MSGS_PACKAGE_HEADER_T_PAYLOAD_QUERIES, 0,
              ROBOTALK_MSGS_PACKAGE_HEADER_T_MODE_DIRECT);
  publish_package(c, &pkg, NULL, NULL);
}

static int64_t track_and_send(rtc_client* c, robotalk_msgs_package_t* pkg, const int64_t* ids, int n_ids) {
  pending_package* slot = NULL;
  for (int i = 0; i < kMaxPackages && !slot; ++i)
    if (!c->packages[i].used) slot = &c->packages[i];
  if (!slot || n_ids > kMaxIdsPerPackage) {
    rtci_set_error(c, "too many outstanding packages or items");
    return -1;
  }
  memset(slot, 0, sizeof *slot);
  if (publish_package(c, pkg, &slot->bytes, &slot->size) != 0) return -1;
  slot->used = 1;
  slot->sequence = pkg->header.sequence;
  slot->session_id = c->session_id;
  slot->tries = 1;
  slot->first_send_us = slot->last_send_us = c->last_new_package_us;
  slot->n_ids = n_ids;
  memcpy(slot->ids, ids, sizeof(int64_t) * (size_t)n_ids);
  return slot->sequence;
}

int64_t rtc_send_queries(rtc_client* c, robotalk_msgs_query_t* queries, int n) {
  int64_t ids[kMaxIdsPerPackage];
  if (n > kMaxIdsPerPackage) return rtci_set_error(c, "at most %d items per package", kMaxIdsPerPackage), -1;
  for (int i = 0; i < n; ++i) ids[i] = queries[i].id = c->next_id++;
  robotalk_msgs_package_t pkg;
  memset(&pkg, 0, sizeof pkg);
  fill_header(c, &pkg.header, ROBOTALK_MSGS_PACKAGE_HEADER_T_PAYLOAD_QUERIES, n,
              ROBOTALK_MSGS_PACKAGE_HEADER_T_MODE_DIRECT);
  pkg.num_queries = n;
  pkg.queries = queries;
  return track_and_send(c, &pkg, ids, n);
}

int64_t rtc_send_commands(rtc_client* c, int8_t mode, robotalk_msgs_command_t* commands, int n) {
  return rtc_send_interpolated(c, mode, ROBOTALK_MSGS_PACKAGE_HEADER_T_INTERPOLATION_STEP, commands, n);
}

int64_t rtc_send_interpolated(rtc_client* c, int8_t mode, int8_t interpolation,
                              robotalk_msgs_command_t* commands, int n) {
  int64_t ids[kMaxIdsPerPackage];
  if (n > kMaxIdsPerPackage) return rtci_set_error(c, "at most %d items per package", kMaxIdsPerPackage), -1;
  for (int i = 0; i < n; ++i) ids[i] = commands[i].id = c->next_id++;
  robotalk_msgs_package_t pkg;
  memset(&pkg, 0, sizeof pkg);
  fill_header(c, &pkg.header, ROBOTALK_MSGS_PACKAGE_HEADER_T_PAYLOAD_COMMANDS, n, mode);
  pkg.header.interpolation = interpolation;
  pkg.num_commands = n;
  pkg.commands = commands;
  return track_and_send(c, &pkg, ids, n);
}

/* ---- sessions ----------------------------------------------------------- */

int rtci_say_hello(rtc_client* c, double timeout_s) {
  robotalk_msgs_hello_t hello;
  memset(&hello, 0, sizeof hello); /* keyed = false, key fields zero: open mode */
  hello.protocol_version = kProtocolVersion;
  hello.client_id = c->client_id;
  if (rtci_random_bytes(c->nonce, sizeof c->nonce) != 0) return rtci_set_error(c, "no /dev/urandom"), -1;
  memcpy(hello.client_nonce, c->nonce, sizeof c->nonce);
  if (c->keyed) rtc_keyed_hello(&hello, &c->identity, c->kx_public, c->kx_secret);
  c->hello_answered = 0;
  const int64_t deadline = rtc_now_us() + (int64_t)(timeout_s * 1e6);
  int64_t next_hello = 0;
  while (!c->hello_answered) {
    int64_t now = rtc_now_us();
    if (now >= deadline)
      return rtci_set_error(c, "no answer to hello from '%s' within %.1f s%s%s%s", c->robot, timeout_s,
                            c->ignored[0] ? " (an answer was ignored: " : "", c->ignored,
                            c->ignored[0] ? ")" : ""),
             -1;
    if (now >= next_hello) {
      robotalk_msgs_hello_t_publish(c->request_lcm, c->hello_channel, &hello);
      next_hello = now + kHelloRepeatUs;
    }
    rtci_handle_for(c, (next_hello < deadline ? next_hello : deadline) - now);
  }
  if (c->session_id == 0 || c->refusal[0])
    return rtci_set_error(c, "hello refused by '%s': %s", c->robot, c->refusal), -1;
  c->last_new_package_us = rtc_now_us();
  return 0;
}

/* A package answered SESSION_UNKNOWN ran nothing: send it again, new sequence, new session. */
static int resend_in_new_session(rtc_client* c, pending_package* p) {
  robotalk_msgs_package_t pkg;
  if (robotalk_msgs_package_t_decode(p->bytes, 0, p->size, &pkg) < 0)
    return rtci_set_error(c, "cannot decode"), -1;
  pkg.header.sequence = c->next_sequence++;
  pkg.header.session_id = c->session_id;
  pkg.header.send_time_us = rtc_now_us();
  free(p->bytes);
  p->bytes = NULL;
  int rc = publish_package(c, &pkg, &p->bytes, &p->size);
  robotalk_msgs_package_t_decode_cleanup(&pkg);
  p->sequence = pkg.header.sequence;
  p->session_id = c->session_id;
  p->session_unknown = 0;
  p->acked = 0;
  p->tries = 1;
  p->first_send_us = p->last_send_us = c->last_new_package_us;
  return rc;
}

/* Timers: a new hello when the session is gone, retransmissions, heartbeats. */
static int run_timers(rtc_client* c) {
  if (!c->hello_answered) { /* SESSION_UNKNOWN for our session: the server forgot it */
    fprintf(stderr, "robotalk-c: session unknown to the server; saying hello again\n");
    if (rtci_say_hello(c, 3.0) != 0) return -1;
  }
  for (int i = 0; i < kMaxPackages; ++i)
    if (c->packages[i].used && c->packages[i].session_unknown &&
        resend_in_new_session(c, &c->packages[i]) != 0)
      return -1;
  const int64_t now = rtc_now_us();
  for (int i = 0; i < kMaxPackages; ++i) {
    pending_package* p = &c->packages[i];
    if (!p->used) continue;
    int complete = 1;
    for (int k = 0; k < p->n_ids && complete; ++k) complete = find_reply(c, p->ids[k]) != NULL;
    if (p->acked && complete) {
      free(p->bytes);
      p->bytes = NULL;
      p->used = 0;
      continue;
    }
    const int64_t timeout = p->acked ? kRecheckUs : kRetransmitUs;
    if (now - p->last_send_us < timeout) continue;
    if (!p->acked && p->tries >= kMaxTries) {
      rtci_set_error(c, "package %" PRId64 " not acknowledged after %d tries", p->sequence, p->tries);
      return -1;
    }
    lcm_publish(c->request_lcm, c->request_channel, p->bytes, (unsigned)p->size); /* same sequence */
    p->last_send_us = now;
    if (!p->acked) ++p->tries;
  }
  if (now - c->last_new_package_us >= kHeartbeatUs) send_heartbeat(c);
  return 0;
}

int rtc_wait(rtc_client* c, const int64_t* ids, int n, double timeout_s, rtc_reply* out) {
  const int64_t deadline = rtc_now_us() + (int64_t)(timeout_s * 1e6);
  for (;;) {
    int missing = 0;
    for (int i = 0; i < n; ++i) missing += find_reply(c, ids[i]) == NULL;
    if (!missing) break;
    if (rtc_now_us() >= deadline)
      return rtci_set_error(c, "%d of %d replies missing after %.1f s", missing, n, timeout_s), -1;
    if (run_timers(c) != 0) return -1;
    rtci_handle_for(c, 20000);
  }
  for (int i = 0; out && i < n; ++i) out[i] = *find_reply(c, ids[i]);
  return 0;
}

int rtc_pause(rtc_client* c, double seconds) {
  const int64_t deadline = rtc_now_us() + (int64_t)(seconds * 1e6);
  for (int64_t now = rtc_now_us(); now < deadline; now = rtc_now_us()) {
    if (run_timers(c) != 0) return -1;
    rtci_handle_for(c, deadline - now < 20000 ? deadline - now : 20000);
  }
  return 0;
}

int rtc_sync_clock(rtc_client* c, int samples, int64_t* offset_us, int64_t* round_trip_us) {
  int64_t best_rtt = INT64_MAX, best_offset = 0;
  int usable = 0;
  for (int s = 0; s < 3 * samples && usable < samples; ++s) { /* retransmitted samples do not count */
    robotalk_msgs_query_t q;
    memset(&q, 0, sizeof q);
    q.type = ROBOTALK_MSGS_QUERY_T_CLOCK;
    q.target = "";
    int64_t seq = rtc_send_queries(c, &q, 1);
    if (seq < 0 || rtc_wait(c, &q.id, 1, 3.0, NULL) != 0) return -1;
    const pending_package* p = find_package(c, seq);
    if (!p || !p->have_clock) continue; /* retransmitted: ambiguous sample */
    ++usable;
    int64_t rtt = (p->t4 - p->t1) - (p->server_send_us - p->server_receive_us);
    int64_t offset = ((p->server_receive_us - p->t1) + (p->server_send_us - p->t4)) / 2;
    if (rtt < best_rtt) best_rtt = rtt, best_offset = offset;
  }
  if (best_rtt == INT64_MAX) return rtci_set_error(c, "no usable CLOCK sample"), -1;
  c->clock_offset_us = best_offset;
  c->clock_stale = 0;
  if (offset_us) *offset_us = best_offset;
  if (round_trip_us) *round_trip_us = best_rtt;
  return 0;
}

robotalk_msgs_robot_config_t* rtc_load_config(rtc_client* c, double timeout_s) {
  char channel[192];
  snprintf(channel, sizeof channel, "ROBOTALK/%s/CONFIG", c->robot);
  rtci_checked_sub* sub = rtci_subscribe_robot_config(c->main_lcm, channel, on_config, c); /* before asking */
  robotalk_msgs_query_t q;
  memset(&q, 0, sizeof q);
  q.type = ROBOTALK_MSGS_QUERY_T_CONFIG;
  q.target = "";
  robotalk_msgs_robot_config_t* result = NULL;
  rtc_reply r;
  if (rtc_send_queries(c, &q, 1) > 0 && rtc_wait(c, &q.id, 1, timeout_s, &r) == 0) {
    if (r.signal != ROBOTALK_MSGS_REPLY_T_SUCCESS) {
      rtci_set_error(c, "CONFIG answered %s: %s", rtc_signal_name(r.signal), r.message);
    } else {
      const int64_t deadline = rtc_now_us() + (int64_t)(timeout_s * 1e6);
      char hash[17] = "";
      while (rtc_now_us() < deadline) {
        if (c->config) snprintf(hash, sizeof hash, "%016" PRIx64, (uint64_t)c->config->header.hash);
        if (c->config && strcmp(hash, r.message) == 0) break;
        if (run_timers(c) != 0) break;
        rtci_handle_for(c, 20000);
      }
      if (c->config && strcmp(hash, r.message) == 0) {
        result = c->config;
        c->config = NULL;
      } else {
        rtci_set_error(c, "no robot_config_t with hash %s on %s within %.1f s", r.message, channel,
                       timeout_s);
      }
    }
  }
  rtci_unsubscribe_checked(c->main_lcm, sub);
  return result;
}
