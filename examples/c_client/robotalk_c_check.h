/* Checked decoding for the C client (docs/writing_a_client.md, "Hostile
 * input"). lcm-gen's C decoders allocate `count * sizeof(element)` as soon
 * as they read an array's declared count or a string's declared length,
 * before checking it against the bytes that follow, and free nothing when
 * the decode then fails: one datagram declaring a huge count makes the
 * reader allocate (and leak) that much. So every message the client
 * receives is first walked here: each declared count and length must fit in
 * the bytes that remain, each string must end in its NUL. Only a message
 * that passes reaches the generated decoder, whose allocations are then
 * what the datagram carries.
 *
 * Thread safety: as LCM's handlers (the thread that calls lcm_handle). */
#ifndef ROBOTALK_C_CHECK_H
#define ROBOTALK_C_CHECK_H

#include <lcm/lcm.h>
#include <stddef.h>
#include <stdint.h>

#include "robotalk_msgs_announce_t.h"
#include "robotalk_msgs_hello_answer_t.h"
#include "robotalk_msgs_reply_package_t.h"
#include "robotalk_msgs_robot_config_t.h"

/* One message type's layout on the wire (after the 8-byte type hash). */
typedef struct rtci_schema rtci_schema;
extern const rtci_schema rtci_announce_schema, rtci_hello_answer_schema, rtci_reply_package_schema,
    rtci_robot_config_schema;

/* 0 when `len` bytes hold a whole message of `schema` (trailing bytes, such
 * as a keyed broadcast's signature, allowed); -1 when a declared count or
 * length goes past the end, is negative, or a string lacks its NUL. */
int rtci_check_message(const void* buf, size_t len, const rtci_schema* schema);

/* A subscription whose messages are checked before they are decoded; a
 * message that fails is dropped, counted and (the first time) said on stderr. */
typedef struct rtci_checked_sub rtci_checked_sub;
rtci_checked_sub* rtci_subscribe_announce(lcm_t* lcm, const char* channel,
                                          void (*handler)(const lcm_recv_buf_t*, const char*,
                                                          const robotalk_msgs_announce_t*, void*),
                                          void* user);
rtci_checked_sub* rtci_subscribe_hello_answer(lcm_t* lcm, const char* channel,
                                              void (*handler)(const lcm_recv_buf_t*, const char*,
                                                              const robotalk_msgs_hello_answer_t*, void*),
                                              void* user);
rtci_checked_sub* rtci_subscribe_reply_package(lcm_t* lcm, const char* channel,
                                               void (*handler)(const lcm_recv_buf_t*, const char*,
                                                               const robotalk_msgs_reply_package_t*, void*),
                                               void* user);
rtci_checked_sub* rtci_subscribe_robot_config(lcm_t* lcm, const char* channel,
                                              void (*handler)(const lcm_recv_buf_t*, const char*,
                                                              const robotalk_msgs_robot_config_t*, void*),
                                              void* user);
/* Sets the LCM queue capacity of the subscription (as lcm-gen's). */
void rtci_checked_set_queue_capacity(rtci_checked_sub* sub, int num_messages);
/* Messages dropped because they failed the check. */
uint64_t rtci_checked_refused(const rtci_checked_sub* sub);
void rtci_unsubscribe_checked(lcm_t* lcm, rtci_checked_sub* sub);

#endif
