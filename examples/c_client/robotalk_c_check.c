/* Checked decoding (robotalk_c_check.h). The schemas mirror lcmtypes/robotalk_msgs/
 * field by field; tests/examples/c_check_test.c proves each one accepts what
 * lcm-gen's encoder writes and refuses every truncation of it. */
#include "robotalk_c_check.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum kind { I8, I16, I32, I64, F64, STR, NESTED };
typedef struct rtci_field {
  enum kind kind;
  int fixed;    /* elements of a fixed-size array (1: a scalar) */
  int count_of; /* >= 0: a variable array whose count is that field (of this struct) */
  const rtci_schema* nested;
} rtci_field;
struct rtci_schema {
  int n;
  const rtci_field* fields;
};

#define S(k) \
  { k, 1, -1, NULL }
#define FIXED(k, n) \
  { k, n, -1, NULL }
#define VAR(k, i) \
  { k, 0, i, NULL }
#define SUB(s) \
  { NESTED, 1, -1, &s }
#define SUBVAR(s, i) \
  { NESTED, 0, i, &s }
#define SCHEMA(linkage, name, ...)                         \
  static const rtci_field name##_fields[] = {__VA_ARGS__}; \
  linkage const rtci_schema name = {(int)(sizeof name##_fields / sizeof name##_fields[0]), name##_fields}
/* dof_t: type, axis[3], lower, upper, velocity, effort */
SCHEMA(static, dof_schema, S(I8), FIXED(F64, 3), S(F64), S(F64), S(F64), S(F64));
/* link_t: name, mass, com[3], inertia[6] */
SCHEMA(static, link_schema, S(STR), S(F64), FIXED(F64, 3), FIXED(F64, 6));
/* joint_t: name, parent_link, child_link, inboard[3], outboard[3], rest[4], servo_types,
 * num_dofs (int8), dofs[num_dofs], mimic_leader, mimic_multiplier, mimic_offset */
SCHEMA(static, joint_schema, S(STR), S(I32), S(I32), FIXED(F64, 3), FIXED(F64, 3), FIXED(F64, 4), S(I8),
       S(I8), SUBVAR(dof_schema, 7), S(I32), S(F64), S(F64));
/* control_frame_t: name, parent_link, position[3], orientation[4], servo_types */
SCHEMA(static, frame_schema, S(STR), S(I32), FIXED(F64, 3), FIXED(F64, 4), S(I8));
/* root_link_t: link, position[3], orientation[4], base_type */
SCHEMA(static, root_schema, S(I32), FIXED(F64, 3), FIXED(F64, 4), S(I8));
/* config_header_t: format_version, hash, then 9 int32 (total_dofs, counts and offsets) */
SCHEMA(static, header_schema, S(I32), S(I64), FIXED(I32, 9));
/* robot_config_t: header, robot_name, num_links, links, num_joints, joints, num_frames, frames,
 * num_roots, roots */
SCHEMA(, rtci_robot_config_schema, SUB(header_schema), S(STR), S(I32), SUBVAR(link_schema, 2), S(I32),
       SUBVAR(joint_schema, 4), S(I32), SUBVAR(frame_schema, 6), S(I32), SUBVAR(root_schema, 8));
/* robot_info_t: name, driver, config_hash, total_dofs, base_type, panic, num_clients */
SCHEMA(static, robot_info_schema, S(STR), S(STR), S(I64), S(I32), S(I8), S(I8), S(I32));
/* announce_t: protocol_version, server_id, server_time_us, uptime_us, url_hint, traffic_layout,
 * keyed, num_robots, robots */
SCHEMA(, rtci_announce_schema, S(I16), S(I64), S(I64), S(I64), S(STR), S(I8), S(I8), S(I32),
       SUBVAR(robot_info_schema, 7));
/* hello_answer_t: protocol_version, client_id, client_nonce[16], server_id, session_id, refusal,
 * keyed, instance_nonce[16], server_nonce[16], server_kx[32], server_key[32], signature[64] */
SCHEMA(, rtci_hello_answer_schema, S(I16), S(I64), FIXED(I8, 16), S(I64), S(I64), S(STR), S(I8),
       FIXED(I8, 16), FIXED(I8, 16), FIXED(I8, 32), FIXED(I8, 32), FIXED(I8, 64));
/* reply_t: id, signal, message, exec_time_us, lateness_us, num_values, values */
SCHEMA(static, reply_schema, S(I64), S(I8), S(STR), S(I64), S(I64), S(I32), VAR(F64, 5));
/* reply_package_t: protocol_version, client_id, server_id, session_id, session_status,
 * panic_status, panic_refusal, ack_sequence, server_receive_us, server_send_us, num_replies,
 * replies, mac[16] */
SCHEMA(, rtci_reply_package_schema, S(I16), S(I64), S(I64), S(I64), S(I8), S(I8), S(STR), S(I64), S(I64),
       S(I64), S(I32), SUBVAR(reply_schema, 10), FIXED(I8, 16));

enum { kMaxFields = 16, kMaxDepth = 4 };

static int64_t read_int(const uint8_t* p, int bytes) { /* big-endian, sign-extended */
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  const int shift = 64 - 8 * bytes;
  return shift ? (int64_t)(v << shift) >> shift : (int64_t)v;
}

static int walk(const uint8_t* buf, size_t len, size_t* pos, const rtci_schema* s, int depth) {
  static const int size_of[] = {[I8] = 1, [I16] = 2, [I32] = 4, [I64] = 8, [F64] = 8};
  int64_t value[kMaxFields] = {0}; /* this struct's integer scalars: the counts of its arrays */
  if (depth > kMaxDepth || s->n > kMaxFields) return -1;
  for (int i = 0; i < s->n; ++i) {
    const rtci_field* f = &s->fields[i];
    const int64_t n = f->count_of >= 0 ? value[f->count_of] : f->fixed;
    const size_t left = len - *pos;
    if (n < 0) return -1;
    if (f->kind == STR) {
      for (int64_t k = 0; k < n; ++k) {
        if (len - *pos < 4) return -1;
        const int64_t size = read_int(buf + *pos, 4); /* with its NUL */
        *pos += 4;
        if (size < 1 || (uint64_t)size > len - *pos || buf[*pos + (size_t)size - 1] != 0) return -1;
        *pos += (size_t)size;
      }
    } else if (f->kind == NESTED) {
      if ((uint64_t)n > left) return -1; /* every element takes at least one byte */
      for (int64_t k = 0; k < n; ++k)
        if (walk(buf, len, pos, f->nested, depth + 1) != 0) return -1;
    } else {
      const size_t size = (size_t)size_of[f->kind];
      if ((uint64_t)n > left / size) return -1;
      if (n == 1 && f->count_of < 0 && f->kind != F64) value[i] = read_int(buf + *pos, (int)size);
      *pos += (size_t)n * size;
    }
  }
  return 0;
}

int rtci_check_message(const void* buf, size_t len, const rtci_schema* schema) {
  size_t pos = 8; /* the type hash: lcm-gen's decoder compares it before allocating anything */
  if (len < pos) return -1;
  return walk(buf, len, &pos, schema, 0);
}

typedef void (*any_handler)(void);
struct rtci_checked_sub {
  lcm_subscription_t* lcm_sub;
  const rtci_schema* schema;
  any_handler handler; /* the typed handler, called through its own type */
  void* user;
  uint64_t refused;
};

/* Refuses (counts, says once) a message that fails the check: 1 refused. */
static int refuse(rtci_checked_sub* s, const lcm_recv_buf_t* rbuf, const char* channel) {
  if (rtci_check_message(rbuf->data, rbuf->data_size, s->schema) == 0) return 0;
  if (s->refused++ == 0)
    fprintf(stderr,
            "robotalk-c: dropped a message on %s: a declared length goes past its %u bytes "
            "(hostile or corrupt; counted, said once)\n",
            channel, rbuf->data_size);
  return 1;
}

/* The LCM handler of one message type: check, decode, call, free. A decode
 * that fails after the check is another type (its hash): nothing allocated. */
#define CHECKED_TYPE(T, name)                                                                       \
  typedef void (*T##_handler)(const lcm_recv_buf_t*, const char*, const robotalk_msgs_##T*, void*); \
  static void T##_stub(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {               \
    rtci_checked_sub* s = user;                                                                     \
    if (refuse(s, rbuf, channel)) return;                                                           \
    robotalk_msgs_##T m;                                                                            \
    memset(&m, 0, sizeof m);                                                                        \
    if (robotalk_msgs_##T##_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) return;            \
    ((T##_handler)s->handler)(rbuf, channel, &m, s->user);                                          \
    robotalk_msgs_##T##_decode_cleanup(&m);                                                         \
  }                                                                                                 \
  rtci_checked_sub* rtci_subscribe_##name(lcm_t* lcm, const char* channel, T##_handler handler,     \
                                          void* user) {                                             \
    rtci_checked_sub* s = calloc(1, sizeof *s);                                                     \
    if (!s) return NULL;                                                                            \
    s->schema = &rtci_##name##_schema;                                                              \
    s->handler = (any_handler)handler;                                                              \
    s->user = user;                                                                                 \
    s->lcm_sub = lcm_subscribe(lcm, channel, T##_stub, s);                                          \
    if (!s->lcm_sub) {                                                                              \
      free(s);                                                                                      \
      return NULL;                                                                                  \
    }                                                                                               \
    return s;                                                                                       \
  }

CHECKED_TYPE(announce_t, announce)
CHECKED_TYPE(hello_answer_t, hello_answer)
CHECKED_TYPE(reply_package_t, reply_package)
CHECKED_TYPE(robot_config_t, robot_config)

void rtci_checked_set_queue_capacity(rtci_checked_sub* sub, int num_messages) {
  if (sub) lcm_subscription_set_queue_capacity(sub->lcm_sub, num_messages);
}

uint64_t rtci_checked_refused(const rtci_checked_sub* sub) { return sub ? sub->refused : 0; }

void rtci_unsubscribe_checked(lcm_t* lcm, rtci_checked_sub* sub) {
  if (!sub) return;
  lcm_unsubscribe(lcm, sub->lcm_sub);
  free(sub);
}
