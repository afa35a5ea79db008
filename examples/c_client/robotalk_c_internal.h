/* What robotalk_c_client.c and robotalk_c_connect.c share: the client's
 * state and the functions both use. Private to the library. */
#ifndef ROBOTALK_C_INTERNAL_H
#define ROBOTALK_C_INTERNAL_H

#include <lcm/lcm.h>

#include "robotalk_c_check.h"
#include "robotalk_c_client.h"
#include "robotalk_c_keyed.h"
#include "robotalk_msgs_hello_answer_t.h"
#include "robotalk_msgs_reply_package_t.h"

enum {
  kProtocolVersion = 4,
  kMaxPackages = 64,  /* outstanding packages */
  kMaxReplies = 1024, /* the reply cache (oldest dropped first) */
  kMaxIdsPerPackage = 64,
  kRetransmitUs = 300000, /* unacknowledged: fixed timeout */
  kRecheckUs = 1000000,   /* acknowledged, final replies missing: ask again */
  kMaxTries = 10,
  kHeartbeatUs = 250000,
  kHelloRepeatUs = 200000,
};

typedef struct {
  int used;
  int64_t sequence;
  uint8_t* bytes; /* the encoded package_t, re-sent as is */
  int size;
  int acked;
  int tries;
  int64_t first_send_us, last_send_us;
  int n_ids;
  int64_t ids[kMaxIdsPerPackage];
  int64_t session_id;  /* the session it was sent in */
  int session_unknown; /* SESSION_UNKNOWN: nothing ran; send again after a new hello */
  /* Clock sample from its acknowledgement (only when sent once: Karn's rule). */
  int have_clock;
  int64_t t1, t4, server_receive_us, server_send_us;
} pending_package;

struct rtc_client {
  char robot[128];
  lcm_t* main_lcm;    /* ANNOUNCE, CONFIG, STATE */
  lcm_t* request_lcm; /* HELLO, REQUEST (== main_lcm in the single layout) */
  lcm_t* reply_lcm;   /* REPLY/<client>, HELLO/<client> (== main_lcm in the single layout) */
  int split;
  char hello_channel[192], request_channel[192], reply_channel[192], hello_answer_channel[192];
  int64_t client_id, session_id, server_id;
  uint8_t nonce[16];
  int hello_answered;
  char refusal[256];
  int64_t next_sequence, next_id;
  int64_t last_new_package_us;
  int64_t clock_offset_us;
  int clock_stale;
  pending_package packages[kMaxPackages];
  rtc_reply replies[kMaxReplies];
  int reply_count, reply_next;
  robotalk_msgs_robot_config_t* config; /* the last CONFIG message heard */
  rtci_checked_sub* hello_sub;          /* checked before decoding (robotalk_c_check.h) */
  rtci_checked_sub* reply_sub;
  char error[512];
  /* rtc_connect: the ANNOUNCE search */
  int found;
  int announce_version, announce_keyed, announce_layout;
  int64_t announce_server_id;
  char heard[512];
  /* Keyed mode (docs/security.md, "Keyed mode byte by byte"). */
  int keyed, have_server_key;
  rtc_identity identity;
  uint8_t server_key[32];               /* --server-key, else the first answer's that verified */
  char ignored[256];                    /* why the last answer was ignored */
  uint8_t kx_public[32], kx_secret[32]; /* this hello's ephemeral pair */
  uint8_t instance_nonce[16];           /* of the server instance of the session */
  rtc_session_keys keys;
};

void rtci_set_error(rtc_client* c, const char* fmt, ...);
int rtci_random_bytes(void* out, size_t n);
/* Handles what arrives on any of the client's LCM instances for at most wait_us. */
void rtci_handle_for(rtc_client* c, int64_t wait_us);
/* Says hello until answered (at most timeout_s): 0 with a session, or -1. */
int rtci_say_hello(rtc_client* c, double timeout_s);
void rtci_on_reply(const lcm_recv_buf_t* rbuf, const char* channel, const robotalk_msgs_reply_package_t* m,
                   void* user);
void rtci_on_hello_answer(const lcm_recv_buf_t* rbuf, const char* channel,
                          const robotalk_msgs_hello_answer_t* m, void* user);

#endif
