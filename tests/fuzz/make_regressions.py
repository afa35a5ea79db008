#!/usr/bin/env python3
"""Writes tests/fuzz/regressions/<target>/ from valid seeds (issue 21).

usage: make_regressions.py SEEDS_DIR OUT_DIR

SEEDS_DIR is what robotalk-fuzz-seeds writes (scripts/fuzz.sh builds it; it
takes models/pioneer2dx_pantilt.urdf). Each input is a valid message with one
hostile edit at a field whose offset the script checks first: truncations,
counts and string lengths of 0, -1 and 2^31-1, NaN and infinity where the
decoders take numbers, a wrong fingerprint; the CONFIG edits recompute the
configuration hash (docs/configuration_message.md, Hash) so they reach the
model's validation. The URDF inputs are hand-written. The regular build
replays every file (FuzzRegressions.*); regenerate when a message layout
changes (a stale input stops at its fingerprint).
"""
import math
import os
import struct
import sys

seeds, out = sys.argv[1], sys.argv[2]


def read(target, name):
    with open(os.path.join(seeds, target, name), "rb") as f:
        return bytearray(f.read())


def put(b, offset, fmt, value, expect=None):
    b = bytearray(b)
    if expect is not None:
        got = struct.unpack_from(fmt, b, offset)[0]
        assert got == expect, f"offset {offset}: expected {expect}, found {got}"
    struct.pack_into(fmt, b, offset, value)
    return b


def write(target, name, data):
    os.makedirs(os.path.join(out, target), exist_ok=True)
    with open(os.path.join(out, target, name), "wb") as f:
        f.write(bytes(data))


NAN, INF = math.nan, math.inf
I32_MAX = 0x7FFFFFFF

# package_t, commands_mode0 (protocol 4: the header gained interpolation,
# max_late_us and round_trip_us, 17 bytes): header ends at 86; num_queries
# @86 (0), num_commands @90 (8), command 0 @94: id, type @102, start @103,
# target @111 ("pan": length 4), num_values @119 (int16, 1), values @121.
p = read("package", "commands_mode0")
write("package", "truncated_in_a_command", p[:107])
write("package", "header_only", p[:86])
write("package", "wrong_fingerprint", put(p, 0, ">B", p[0] ^ 0xFF))
for name, v in [("num_commands_max", I32_MAX), ("num_commands_negative", -1)]:
    write("package", name, put(p, 90, ">i", v, expect=8))
write("package", "payload_size_disagrees", put(p, 36, ">i", 1000, expect=8))
for name, v in [("target_length_zero", 0), ("target_length_max", I32_MAX), ("target_length_negative", -5)]:
    write("package", name, put(p, 111, ">i", v, expect=4))
for name, v in [("num_values_negative", -1), ("num_values_max", 0x7FFF)]:
    write("package", name, put(p, 119, ">h", v, expect=1))
write("package", "value_nan", put(p, 121, ">d", NAN, expect=0.5))
write("package", "value_infinite", put(p, 121, ">d", INF, expect=0.5))
write("package", "start_time_negative", put(p, 103, ">q", -(1 << 62), expect=0))
write("package", "type_unknown", put(p, 102, ">b", 99, expect=1))
write("package", "mode_unknown", put(p, 40, ">b", 77, expect=0))
write("package", "round_trip_negative", put(p, 78, ">q", -1, expect=0))
q = read("package", "query_7")  # STATE_STREAM with a period
write("package", "num_queries_max", put(q, 86, ">i", I32_MAX, expect=1))

# reply_package_t, replies: panic_refusal @36 (length 1), num_replies @65 (7),
# reply 0 @69: id, signal @77, message @78 (length 1), exec @83, lateness @91,
# num_values @99 (3), values @103.
r = read("reply_package", "replies")
write("reply_package", "truncated_in_a_reply", r[:100])
for name, v in [("num_replies_max", I32_MAX), ("num_replies_negative", -1)]:
    write("reply_package", name, put(r, 65, ">i", v, expect=7))
for name, v in [("panic_refusal_length_zero", 0), ("panic_refusal_length_max", I32_MAX)]:
    write("reply_package", name, put(r, 36, ">i", v, expect=1))
write("reply_package", "message_length_zero", put(r, 78, ">i", 0, expect=1))
for name, v in [("num_values_max", I32_MAX), ("num_values_negative", -7)]:
    write("reply_package", name, put(r, 99, ">i", v, expect=3))
write("reply_package", "value_nan", put(r, 103, ">d", NAN, expect=0.1))
write("reply_package", "signal_unknown", put(r, 77, ">b", 42, expect=0))

# robot_state_t: robot @32 ("pioneer": length 8), num_dofs @54 (2),
# position @58, velocity @74, effort @90, base @106, num_frames @146 (1),
# then the frame and (protocol 4) the link fields; link_level is the 9th byte
# from the end of the link block (client id 8 bytes before it).
s = read("robot_state", "state")
write("robot_state", "truncated_in_the_positions", s[:62])
for name, v in [("num_dofs_max", I32_MAX), ("num_dofs_negative", -2), ("num_dofs_more_than_sent", 3)]:
    write("robot_state", name, put(s, 54, ">i", v, expect=2))
write("robot_state", "robot_length_zero", put(s, 32, ">i", 0, expect=8))
write("robot_state", "position_nan", put(s, 58, ">d", NAN, expect=0.1))
write("robot_state", "base_infinite", put(s, 106, ">d", INF, expect=0.0))
for name, v in [("num_frames_max", I32_MAX), ("num_frames_negative", -1)]:
    write("robot_state", name, put(s, 146, ">i", v, expect=1))


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def rehash(c):
    c = bytearray(c)
    c[12:20] = bytes(8)
    c[12:20] = struct.pack(">Q", fnv1a64(c))
    return c


# robot_config_t: header @8 (format @8, hash @12, total_dofs @20, num_links @24,
# link offset @28, num_joints @32 ...), robot_name @56, num_links again after
# the name; link 0: name, then mass.
c = read("config", "pioneer2dx_pantilt")
assert rehash(c) == c, "the configuration hash is not what docs/configuration_message.md says"
name_len = struct.unpack_from(">i", c, 56)[0]
links_at = 60 + name_len
num_links = struct.unpack_from(">i", c, links_at)[0]
link0_name_len = struct.unpack_from(">i", c, links_at + 4)[0]
mass_at = links_at + 8 + link0_name_len
write("config", "truncated_in_the_links", c[:mass_at + 3])
write("config", "header_only", c[:56])
write("config", "edited_without_rehash", put(c, 20, ">i", 99))
write("config", "header_num_links_max", rehash(put(c, 24, ">i", I32_MAX, expect=num_links)))
write("config", "num_links_max", rehash(put(c, links_at, ">i", I32_MAX, expect=num_links)))
write("config", "num_links_negative", rehash(put(c, links_at, ">i", -1, expect=num_links)))
write("config", "link_offset_past_the_end", rehash(put(c, 28, ">i", len(c) + 100)))
write("config", "robot_name_length_zero", rehash(put(c, 56, ">i", 0, expect=name_len)))
write("config", "link_mass_nan", rehash(put(c, mass_at, ">d", NAN)))
write("config", "link_mass_negative", rehash(put(c, mass_at, ">d", -1.0)))
write("config", "com_infinite", rehash(put(c, mass_at + 8, ">d", INF)))
write("config", "total_dofs_disagrees", rehash(put(c, 20, ">i", 1000)))

# announce_t: url_hint @34 (length 32), traffic_layout, keyed, num_robots,
# robot 0 name ("pioneer": length 8).
a = read("announce", "announce")
url_len = struct.unpack_from(">i", a, 34)[0]
num_at = 38 + url_len + 2
write("announce", "truncated_in_a_robot", a[:num_at + 9])
for name, v in [("num_robots_max", I32_MAX), ("num_robots_negative", -1)]:
    write("announce", name, put(a, num_at, ">i", v, expect=2))
write("announce", "name_length_zero_current_fingerprint", put(a, num_at + 4, ">i", 0, expect=8))
write("announce", "url_hint_length_max", put(a, 34, ">i", I32_MAX, expect=url_len))

# hello_t, open: protocol @8, client @10, nonce @18, keyed @34, key @35 ...
h = read("hello", "open")
write("hello", "truncated_in_the_nonce", h[:25])
write("hello", "keyed_with_zero_key_and_signature", put(h, 34, ">b", 1, expect=0))
write("hello", "keyed_flag_not_a_boolean", put(h, 34, ">b", 7, expect=0))
write("hello", "client_id_zero", put(h, 10, ">q", 0))
write("hello", "protocol_version_future", put(h, 8, ">h", 999))
k = read("hello", "keyed")
write("hello", "keyed_signature_flipped", put(k, len(k) - 1, ">B", k[-1] ^ 1))

# hello_answer_t, refused: session @42, refusal @50.
ha = read("hello_answer", "refused")
ref_len = struct.unpack_from(">i", ha, 50)[0]
write("hello_answer", "truncated_in_the_refusal", ha[:60])
for name, v in [("refusal_length_zero", 0), ("refusal_length_max", I32_MAX), ("refusal_length_negative", -3)]:
    write("hello_answer", name, put(ha, 50, ">i", v, expect=ref_len))
write("hello_answer", "keyed_with_zero_keys", put(ha, 54 + ref_len, ">b", 1, expect=0))
write("hello_answer", "session_negative", put(read("hello_answer", "open"), 42, ">q", -1, expect=77))

INERTIAL = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
urdfs = {
    "truncated": f'<robot name="r"><link name="a">{INERTIAL}</link><joint name="j" type="revol',
    "origin_nan": f'<robot name="r"><link name="a">{INERTIAL}</link><link name="b">{INERTIAL}</link>'
                  '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
                  '<origin xyz="nan 0 0" rpy="0 inf 0"/><axis xyz="0 0 1"/>'
                  '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>',
    "mass_huge_and_inertia_nan": '<robot name="r"><link name="a"><inertial><mass value="1e308"/>'
                                 '<inertia ixx="nan" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>',
    "limits_nan_axis_zero": f'<robot name="r"><link name="a">{INERTIAL}</link><link name="b">{INERTIAL}</link>'
                            '<joint name="j" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="0 0 0"/>'
                            '<limit lower="nan" upper="-inf" effort="-1" velocity="0"/></joint></robot>',
    "joint_cycle": f'<robot name="r"><link name="a">{INERTIAL}</link><link name="b">{INERTIAL}</link>'
                   '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
                   '<joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint></robot>',
    "mimics_itself": f'<robot name="r"><link name="a">{INERTIAL}</link><link name="b">{INERTIAL}</link>'
                     '<joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
                     '<mimic joint="j" multiplier="nan" offset="1e308"/></joint></robot>',
    "duplicate_links": f'<robot name="r"><link name="a">{INERTIAL}</link><link name="a">{INERTIAL}</link></robot>',
    "not_xml": "\x00\xff\xfe<robot\x01",
    "empty_robot": '<robot name=""/>',
    "entity_expansion": '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;">]>'
                        '<robot name="&b;"><link name="&b;&b;"/></robot>',
    "robotalk_extension_hostile": f'<robot name="r"><link name="a">{INERTIAL}</link>'
                                  '<robotalk><control_frame name="f" link="missing" xyz="nan 0 0" servo="x"/>'
                                  '<base type="warp"/></robotalk></robot>',
}
for name, text in urdfs.items():
    write("urdf", name, text.encode("latin-1"))
