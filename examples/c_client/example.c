/* The C client example: connects to a robot, loads its configuration, sends
 * a GOTO (direct mode), then a short timed sequence of pan/tilt set-points in
 * delay mode, then one interpolated (cubic) sequence of pan waypoints, and
 * prints every reply. Same steps and output as the Java
 * example (examples/java_client); tests/examples/client_example_test.sh runs it.
 *   robotalk_c_example [--url URL] [--robot NAME] [--delay S] [--pause S]
 *                      [--key FILE] [--server-key FILE.pub]
 * --key FILE: keyed mode with this secret key (or $ROBOTALK_KEY);
 * --server-key FILE.pub: the server key to trust (default: the first answer's, not pinned).
 * --pause S: wait S seconds after the GOTO (keeping the session); the test
 * restarts the server meanwhile, and the client must say hello again.
 * Exit status 0 when every step succeeded. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "robotalk_c_client.h"

#define SEQUENCE_FRAMES 4
static const double kFrameSpacing = 0.25; /* s between the sequence's frames */
#define TRAJECTORY_POINTS 3
static const double kPointSpacing = 0.2; /* s between the trajectory's waypoints */

/* A server's text (a reply's message, an error naming what it sent) is
   anyone's bytes in open mode: written with its control characters (C0,
   DEL, C1 in UTF-8) as \xNN, it never forges a line nor reaches the
   terminal as an escape, as the robotalk CLI writes it. */
static void put_text(FILE* f, const char* s) {
  for (; *s; ++s) {
    const unsigned char u = (unsigned char)*s, next = (unsigned char)s[1];
    if (u == 0xc2 && next >= 0x80 && next <= 0x9f) {
      fprintf(f, "\\x%02x\\x%02x", u, next);
      ++s;
    } else if (u < 0x20 || u == 0x7f) {
      fprintf(f, "\\x%02x", u);
    } else {
      fputc(u, f);
    }
  }
}

static void print_reply(const char* what, const rtc_reply* r) {
  printf("reply %" PRId64 " %s: %s%s", r->id, what, rtc_signal_name(r->signal), r->message[0] ? " " : "");
  put_text(stdout, r->message);
  printf(" exec_us=%" PRId64 " late_ms=%.1f\n", r->exec_time_us, r->lateness_us / 1000.0);
}

static void print_error(const char* text) {
  fputs("error: ", stderr);
  put_text(stderr, text);
  fputc('\n', stderr);
}

static int query(rtc_client* c, int8_t type, const char* target, rtc_reply* out) {
  robotalk_msgs_query_t q;
  memset(&q, 0, sizeof q);
  q.type = type;
  q.target = (char*)target;
  return rtc_send_queries(c, &q, 1) > 0 && rtc_wait(c, &q.id, 1, 5.0, out) == 0 ? 0 : -1;
}

static int run(rtc_client* c, double delay_s, double pause_s) {
  int64_t offset_us = 0, rtt_us = 0;
  if (rtc_sync_clock(c, 5, &offset_us, &rtt_us) != 0) return -1;
  printf("clock: offset_us=%" PRId64 " round_trip_us=%" PRId64 "\n", offset_us, rtt_us);

  robotalk_msgs_robot_config_t* config = rtc_load_config(c, 5.0);
  if (!config) return -1;
  int dofs = 0;
  for (int j = 0; j < config->num_joints; ++j) dofs += config->joints[j].num_dofs;
  printf("config: robot=%s links=%d joints=%d frames=%d dofs=%d hash=%016" PRIx64
         " (reply and message agree)\n",
         config->robot_name, config->num_links, config->num_joints, config->num_frames, dofs,
         (uint64_t)config->header.hash);
  robotalk_msgs_robot_config_t_destroy(config);

  /* Direct mode: a GOTO is answered when the base has reached its goal. */
  double goal[3] = {0.5, 0.0, 0.0};
  robotalk_msgs_command_t go = {
      .type = ROBOTALK_MSGS_COMMAND_T_GOTO, .target = "", .num_values = 3, .values = goal};
  rtc_reply r;
  if (rtc_send_commands(c, ROBOTALK_MSGS_PACKAGE_HEADER_T_MODE_DIRECT, &go, 1) < 0 ||
      rtc_wait(c, &go.id, 1, 30.0, &r) != 0)
    return -1;
  print_reply("GOTO 0.5 0 0", &r);
  int failures = r.signal != ROBOTALK_MSGS_REPLY_T_SUCCESS;
  if (pause_s > 0) {
    printf("pausing %.1f s\n", pause_s);
    fflush(stdout);
    if (rtc_pause(c, pause_s) != 0) return -1;
  }
  if (rtc_clock_stale(c)) { /* a new server instance: its clock may be another's */
    if (rtc_sync_clock(c, 5, &offset_us, &rtt_us) != 0) return -1;
    printf("new server instance %016" PRIx64 ", session %016" PRIx64 ": clock offset_us=%" PRId64 "\n",
           (uint64_t)rtc_server_id(c), (uint64_t)rtc_session_id(c), offset_us);
  }

  /* Delay mode: each frame stamped server now + delay + its offset, all sent at once. */
  const char* joints[SEQUENCE_FRAMES] = {"pan", "pan", "pan", "tilt"};
  double targets[SEQUENCE_FRAMES] = {0.1, 0.2, 0.3, -0.2};
  robotalk_msgs_command_t frames[SEQUENCE_FRAMES];
  int64_t ids[SEQUENCE_FRAMES];
  const int64_t start_us = rtc_server_now_us(c) + (int64_t)(delay_s * 1e6);
  for (int k = 0; k < SEQUENCE_FRAMES; ++k) {
    frames[k] = (robotalk_msgs_command_t){.type = ROBOTALK_MSGS_COMMAND_T_JOINT_SETPOINT,
                                          .start_time_us = start_us + (int64_t)(k * kFrameSpacing * 1e6),
                                          .target = (char*)joints[k],
                                          .num_values = 1,
                                          .values = &targets[k]};
    if (rtc_send_commands(c, ROBOTALK_MSGS_PACKAGE_HEADER_T_MODE_DELAY, &frames[k], 1) < 0) return -1;
    ids[k] = frames[k].id;
  }
  printf("sequence sent: %d frames from server time %" PRId64 " us\n", SEQUENCE_FRAMES, start_us);
  fflush(stdout);
  rtc_reply replies[SEQUENCE_FRAMES];
  if (rtc_wait(c, ids, SEQUENCE_FRAMES, 10.0 + delay_s, replies) != 0) return -1;
  for (int k = 0; k < SEQUENCE_FRAMES; ++k) {
    char what[64];
    snprintf(what, sizeof what, "sequence +%.2f s %s %.2f", k * kFrameSpacing, joints[k], targets[k]);
    print_reply(what, &replies[k]);
    failures += replies[k].signal != ROBOTALK_MSGS_REPLY_T_SUCCESS;
  }
  printf("spacing_s:");
  for (int k = 1; k < SEQUENCE_FRAMES; ++k)
    printf(" %.3f", (replies[k].exec_time_us - replies[k - 1].exec_time_us) / 1e6);
  printf("\n");

  /* An interpolated sequence: pan's waypoints in one cubic package (delay mode),
   * the middle one with its velocity; each is answered when the trajectory
   * passes it. It ends where the sequence above left pan, at 0.3. Sent only when
   * everything so far succeeded: a client whose sequence failed moves nothing more. */
  if (!failures) {
    double way[TRAJECTORY_POINTS] = {0.33, 0.36, 0.3};
    double way_velocity[TRAJECTORY_POINTS] = {0.0, 0.1, 0.0};
    robotalk_msgs_command_t points[TRAJECTORY_POINTS];
    int64_t point_ids[TRAJECTORY_POINTS];
    const int64_t traj_start_us = rtc_server_now_us(c) + (int64_t)(delay_s * 1e6);
    for (int k = 0; k < TRAJECTORY_POINTS; ++k) {
      points[k] =
          (robotalk_msgs_command_t){.type = ROBOTALK_MSGS_COMMAND_T_JOINT_SETPOINT,
                                    .start_time_us = traj_start_us + (int64_t)((k + 1) * kPointSpacing * 1e6),
                                    .target = "pan",
                                    .num_values = 1,
                                    .values = &way[k],
                                    .num_velocities = k == 1,
                                    .velocities = &way_velocity[k]};
    }
    if (rtc_send_interpolated(c, ROBOTALK_MSGS_PACKAGE_HEADER_T_MODE_DELAY,
                              ROBOTALK_MSGS_PACKAGE_HEADER_T_INTERPOLATION_CUBIC, points,
                              TRAJECTORY_POINTS) < 0)
      return -1;
    for (int k = 0; k < TRAJECTORY_POINTS; ++k) point_ids[k] = points[k].id;
    rtc_reply point_replies[TRAJECTORY_POINTS];
    if (rtc_wait(c, point_ids, TRAJECTORY_POINTS, 10.0 + delay_s, point_replies) != 0) return -1;
    for (int k = 0; k < TRAJECTORY_POINTS; ++k) {
      char what[64];
      snprintf(what, sizeof what, "trajectory cubic +%.2f s pan %.2f", (k + 1) * kPointSpacing, way[k]);
      print_reply(what, &point_replies[k]);
      failures += point_replies[k].signal != ROBOTALK_MSGS_REPLY_T_SUCCESS &&
                  point_replies[k].signal != ROBOTALK_MSGS_REPLY_T_MODIFIED;
    }
  }

  /* The last set-point was taken when answered; give the joint time to get there. */
  if (rtc_pause(c, 0.5) != 0) return -1;
  if (query(c, ROBOTALK_MSGS_QUERY_T_BASE_POSE, "", &r) != 0) return -1;
  printf("pose: x=%.3f y=%.3f theta=%.3f\n", r.values[0], r.values[1], r.values[2]);
  rtc_reply pan, tilt;
  if (query(c, ROBOTALK_MSGS_QUERY_T_JOINT_STATE, "pan", &pan) != 0 ||
      query(c, ROBOTALK_MSGS_QUERY_T_JOINT_STATE, "tilt", &tilt) != 0)
    return -1;
  printf("joints: pan=%.3f tilt=%.3f\n", pan.values[0], tilt.values[0]);
  return failures ? -1 : 0;
}

int main(int argc, char** argv) {
  const char* url = getenv("LCM_DEFAULT_URL");
  const char* robot = "pioneer";
  const char* key_file = getenv("ROBOTALK_KEY");
  const char* server_key_file = NULL;
  double delay_s = 0.5, pause_s = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--url") == 0 && i + 1 < argc) {
      url = argv[++i];
    } else if (strcmp(argv[i], "--robot") == 0 && i + 1 < argc) {
      robot = argv[++i];
    } else if (strcmp(argv[i], "--delay") == 0 && i + 1 < argc) {
      delay_s = atof(argv[++i]);
    } else if (strcmp(argv[i], "--pause") == 0 && i + 1 < argc) {
      pause_s = atof(argv[++i]);
    } else if (strcmp(argv[i], "--key") == 0 && i + 1 < argc) {
      key_file = argv[++i];
    } else if (strcmp(argv[i], "--server-key") == 0 && i + 1 < argc) {
      server_key_file = argv[++i];
    } else {
      fprintf(stderr,
              "usage: %s [--url URL] [--robot NAME] [--delay S] [--pause S] [--key FILE] "
              "[--server-key FILE.pub]\n",
              argv[0]);
      return 2;
    }
  }
  if (!url) url = "udpm://239.255.76.67:7667?ttl=0";
  char err[512];
  if (key_file && !key_file[0]) key_file = NULL;
  rtc_client* c = rtc_connect_keyed(url, robot, key_file, server_key_file, 5.0, err, sizeof err);
  if (!c) {
    print_error(err);
    return 1;
  }
  printf("connected: robot=%s server=%016" PRIx64 " layout=%s session=%016" PRIx64 " client=%016" PRIx64
         "%s\n",
         robot, (uint64_t)rtc_server_id(c), rtc_split_layout(c) ? "split" : "single",
         (uint64_t)rtc_session_id(c), (uint64_t)rtc_client_id(c), key_file ? " keyed" : "");
  int rc = run(c, delay_s, pause_s);
  if (rc != 0 && rtc_error(c)[0]) print_error(rtc_error(c));
  printf("%s\n", rc == 0 ? "done" : "failed");
  rtc_close(c);
  return rc == 0 ? 0 : 1;
}
