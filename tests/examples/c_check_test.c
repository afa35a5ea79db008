#define _GNU_SOURCE /* memmem */
/* The C client's checked decoding (examples/c_client/robotalk_c_check.h):
 * each schema accepts what lcm-gen's encoder writes (with arrays and strings
 * in every place), refuses every truncation of it, and refuses a declared
 * count or length past the end. Exit 0 pass, 1 fail. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "robotalk_c_check.h"

static int failures = 0;
#define CHECK(cond, ...)                          \
  do {                                            \
    if (!(cond)) {                                \
      ++failures;                                 \
      printf("FAIL %s:%d: ", __FILE__, __LINE__); \
      printf(__VA_ARGS__);                        \
      printf("\n");                               \
    }                                             \
  } while (0)

/* Accepted whole (and with a trailing signature-like suffix); every strict prefix refused. */
static void check_encoding(const char* what, const uint8_t* buf, int len, const rtci_schema* schema) {
  CHECK(rtci_check_message(buf, (size_t)len, schema) == 0, "%s: the whole encoding (%d bytes) is refused",
        what, len);
  uint8_t longer[8192];
  memcpy(longer, buf, (size_t)len);
  memset(longer + len, 0xab, 120);
  CHECK(rtci_check_message(longer, (size_t)len + 120, schema) == 0, "%s: trailing bytes are refused", what);
  for (int n = 0; n < len; ++n)
    CHECK(rtci_check_message(buf, (size_t)n, schema) != 0, "%s: a truncation to %d of %d bytes passes", what,
          n, len);
}

int main(void) {
  uint8_t buf[8192];
  /* announce_t with two robots */
  robotalk_msgs_robot_info_t robots[2] = {{.name = "pioneer", .driver = "kinematic", .num_clients = 3},
                                          {.name = "arm", .driver = "ode"}};
  robotalk_msgs_announce_t a = {.protocol_version = 4, .url_hint = "hint", .num_robots = 2, .robots = robots};
  int len = robotalk_msgs_announce_t_encode(buf, 0, sizeof buf, &a);
  check_encoding("announce_t", buf, len, &rtci_announce_schema);
  /* a count past the end: num_robots sits 4 bytes before the robots */
  a.num_robots = 0;
  len = robotalk_msgs_announce_t_encode(buf, 0, sizeof buf, &a);
  buf[len - 4] = 0x10;
  CHECK(rtci_check_message(buf, (size_t)len, &rtci_announce_schema) != 0, "a huge num_robots passes");
  buf[len - 4] = 0xff; /* negative */
  CHECK(rtci_check_message(buf, (size_t)len, &rtci_announce_schema) != 0, "a negative num_robots passes");

  /* hello_answer_t */
  robotalk_msgs_hello_answer_t h;
  memset(&h, 0, sizeof h);
  h.refusal = "refused for a reason";
  len = robotalk_msgs_hello_answer_t_encode(buf, 0, sizeof buf, &h);
  check_encoding("hello_answer_t", buf, len, &rtci_hello_answer_schema);

  /* reply_package_t with replies carrying values */
  double values[3] = {1, 2, 3};
  robotalk_msgs_reply_t replies[2] = {{.id = 1, .message = "ok", .num_values = 3, .values = values},
                                      {.id = 2, .message = "", .num_values = 0, .values = NULL}};
  robotalk_msgs_reply_package_t r;
  memset(&r, 0, sizeof r);
  r.panic_refusal = "";
  r.num_replies = 2;
  r.replies = replies;
  len = robotalk_msgs_reply_package_t_encode(buf, 0, sizeof buf, &r);
  check_encoding("reply_package_t", buf, len, &rtci_reply_package_schema);
  /* a string without its NUL */
  uint8_t copy[8192];
  memcpy(copy, buf, (size_t)len);
  const uint8_t* ok = memmem(copy, (size_t)len, "ok", 3);
  CHECK(ok != NULL, "the reply's message is in the encoding");
  if (ok) {
    copy[ok - copy + 2] = 'x';
    CHECK(rtci_check_message(copy, (size_t)len, &rtci_reply_package_schema) != 0,
          "a string without NUL passes");
  }

  /* robot_config_t: a link, a joint with two dofs, a frame, a root */
  robotalk_msgs_link_t links[1] = {{.name = "base"}};
  robotalk_msgs_dof_t dofs[2];
  memset(dofs, 0, sizeof dofs);
  robotalk_msgs_joint_t joints[1];
  memset(joints, 0, sizeof joints);
  joints[0].name = "pan";
  joints[0].num_dofs = 2;
  joints[0].dofs = dofs;
  joints[0].mimic_leader = -1;
  robotalk_msgs_control_frame_t frames[1];
  memset(frames, 0, sizeof frames);
  frames[0].name = "camera";
  robotalk_msgs_root_link_t roots[1];
  memset(roots, 0, sizeof roots);
  robotalk_msgs_robot_config_t cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.robot_name = "pioneer";
  cfg.num_links = 1, cfg.links = links;
  cfg.num_joints = 1, cfg.joints = joints;
  cfg.num_frames = 1, cfg.frames = frames;
  cfg.num_roots = 1, cfg.roots = roots;
  len = robotalk_msgs_robot_config_t_encode(buf, 0, sizeof buf, &cfg);
  check_encoding("robot_config_t", buf, len, &rtci_robot_config_schema);

  printf("%s (%d failures)\n", failures ? "FAIL" : "PASS", failures);
  return failures ? 1 : 0;
}
