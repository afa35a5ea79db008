/* A small RoboTalk client in C (protocol 4, open and keyed mode), written from
 * docs/protocol.md, docs/writing_a_client.md and docs/security.md with LCM's C
 * API, the C bindings lcm-gen makes of lcmtypes/robotalk_msgs
 * (robotalk::lcmtypes_c) and libsodium (keyed mode: robotalk_c_keyed.h).
 *
 * What it does: finds the robot on ROBOTALK/ANNOUNCE (and from it the traffic
 * layout, single or split), opens a session with a hello, numbers packages
 * 1, 2, 3 ..., retransmits a package with the same sequence until it is
 * acknowledged (fixed 300 ms timeout, 10 tries) and, once acknowledged, every
 * second until every item has its final reply; files replies by id (a second
 * copy is ignored); sends a heartbeat every 250 ms so the server's watchdog
 * keeps the session; says hello again after SESSION_UNKNOWN (nothing in that
 * package ran) and sends the package again in the new session.
 *
 * Not done here: pinning the server key in a file (give it, or the ANNOUNCE's
 * signer is trusted), checking STATE signatures (no STATE is read), RFC 6298
 * adaptive timeouts (the C++ client does those).
 *
 * Threads: one rtc_client is used by one thread; nothing runs in the
 * background. Every blocking call takes a timeout in seconds. Errors: calls
 * return NULL or -1 and rtc_error() says why. */
#ifndef ROBOTALK_C_CLIENT_H
#define ROBOTALK_C_CLIENT_H

#include <stddef.h>
#include <stdint.h>

#include "robotalk_msgs_command_t.h"
#include "robotalk_msgs_package_header_t.h"
#include "robotalk_msgs_query_t.h"
#include "robotalk_msgs_reply_t.h"
#include "robotalk_msgs_robot_config_t.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rtc_client rtc_client;

/* One final reply (reply_t), copied out of the reply package. signal is one
 * of robotalk_msgs_reply_t's signals, or RTC_UNKNOWN_OUTCOME when the server
 * instance changed while the item was outstanding (it may or may not have run). */
enum { RTC_UNKNOWN_OUTCOME = -1, RTC_MAX_VALUES = 32 };
typedef struct {
  int64_t id;
  int8_t signal;
  char message[256];
  int64_t exec_time_us; /* server clock */
  int64_t lateness_us;
  int num_values; /* values kept: the first RTC_MAX_VALUES */
  double values[RTC_MAX_VALUES];
} rtc_reply;

/* "SUCCESS", "MODIFIED", ... for a reply signal. */
const char* rtc_signal_name(int signal);

/* The client's monotonic clock, microseconds. */
int64_t rtc_now_us(void);

/* Listens to ROBOTALK/ANNOUNCE on url until `robot` is announced (at most
 * timeout_s), opens the LCM instances its traffic layout asks for, and says
 * hello. NULL on failure, with the reason in err (a robot not heard, a keyed
 * server, a refused hello, a layout this client cannot derive ports for). */
rtc_client* rtc_connect(const char* url, const char* robot, double timeout_s, char* err, size_t err_len);
/* The same in keyed mode (docs/security.md) when key_file is not NULL: the
 * client's secret key file, and the server's .pub file to trust (NULL: the key
 * of the first hello answer whose signature verifies, trusted on first use and
 * not pinned; its fingerprint is printed on stderr).
 * The client id is one of the key's; every package is sealed with the
 * session's MAC; replies, answers and CONFIG messages that do not verify are
 * dropped. */
rtc_client* rtc_connect_keyed(const char* url, const char* robot, const char* key_file,
                              const char* server_key_file, double timeout_s, char* err, size_t err_len);
void rtc_close(rtc_client* c);
const char* rtc_error(const rtc_client* c);

int64_t rtc_client_id(const rtc_client* c);
int64_t rtc_session_id(const rtc_client* c);
int64_t rtc_server_id(const rtc_client* c);
int rtc_split_layout(const rtc_client* c); /* 1: TRAFFIC_SPLIT, 0: TRAFFIC_SINGLE */

/* Estimates the server clock offset from `samples` CLOCK queries answered
 * without a retransmission (at most 3 x samples sent), keeping the
 * sample with the smallest round trip (docs/protocol.md, Clocks). 0 or -1. */
int rtc_sync_clock(rtc_client* c, int samples, int64_t* offset_us, int64_t* round_trip_us);
/* The server clock now, from the client clock and the last rtc_sync_clock. */
int64_t rtc_server_now_us(const rtc_client* c);
/* 1 when a new server instance answered since the last rtc_sync_clock (its
 * clock may be another's): sync again before stamping delay-mode commands. */
int rtc_clock_stale(const rtc_client* c);

/* Send one package, non-blocking. Each item's id is set by the library (read
 * it back from queries[i].id / commands[i].id). Returns the package's
 * sequence (> 0), or -1. mode: robotalk_msgs_package_header_t MODE_*. */
int64_t rtc_send_queries(rtc_client* c, robotalk_msgs_query_t* queries, int n);
int64_t rtc_send_commands(rtc_client* c, int8_t mode, robotalk_msgs_command_t* commands, int n);
/* The same with the package's interpolation (package_header_t INTERPOLATION_*):
 * its timed JOINT_SETPOINT / FRAME_SETPOINT commands are the waypoints of a
 * trajectory (docs/protocol.md, Trajectories); a command's velocities and
 * accelerations (num_velocities = 0: chosen by the server) are its rates.
 * rtc_send_commands sends INTERPOLATION_STEP. */
int64_t rtc_send_interpolated(rtc_client* c, int8_t mode, int8_t interpolation,
                              robotalk_msgs_command_t* commands, int n);

/* Waits until every id in ids[0..n) has its final reply, for at most
 * timeout_s, keeping heartbeats and retransmissions going; copies the replies
 * to out[0..n) (in the order of ids) when out is not NULL. 0, or -1 on timeout
 * or a package never acknowledged. */
int rtc_wait(rtc_client* c, const int64_t* ids, int n, double timeout_s, rtc_reply* out);

/* Lets seconds pass while keeping the session (heartbeats, retransmissions,
 * replies filed). 0, or -1 when a package was never acknowledged. */
int rtc_pause(rtc_client* c, double seconds);

/* Loads the configuration: subscribes to ROBOTALK/<robot>/CONFIG, sends a
 * CONFIG query and waits for both its reply and the robot_config_t whose hash
 * the reply names (they travel separately, in either order). Returns a copy
 * to free with robotalk_msgs_robot_config_t_destroy, or NULL. */
robotalk_msgs_robot_config_t* rtc_load_config(rtc_client* c, double timeout_s);

#ifdef __cplusplus
}
#endif
#endif
