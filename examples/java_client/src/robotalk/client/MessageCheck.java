// Checked decoding for the Java client (docs/writing_a_client.md, "Hostile
// input"): lcm-gen's Java decoders create a declared array (new T[count])
// before reading its elements, so one 45-byte ANNOUNCE declaring 2^31 - 1
// robots threw OutOfMemoryError out of the client, and any message that did
// not decode threw IOException out of whatever call was waiting. Every
// message is walked here first: a declared count or string length past the
// bytes that remain, a negative one, or a string without its NUL refuses it
// before the generated decoder sees it. The schemas mirror
// lcmtypes/robotalk_msgs field by field, as examples/c_client/robotalk_c_check.c
// does; MessageCheckTest proves each accepts what lcm-gen's Java encoder
// writes and refuses every truncation of it.
package robotalk.client;

final class MessageCheck {
  private MessageCheck() {}

  private static final int I8 = 0, I16 = 1, I32 = 2, I64 = 3, F64 = 4, STR = 5, NESTED = 6;
  private static final int[] SIZE = {1, 2, 4, 8, 8};

  /** One field: a scalar, a fixed array, or a variable array whose count is field countOf. */
  static final class Field {
    final int kind, fixed, countOf;
    final Field[] nested;
    Field(int kind, int fixed, int countOf, Field[] nested) {
      this.kind = kind;
      this.fixed = fixed;
      this.countOf = countOf;
      this.nested = nested;
    }
  }
  private static Field s(int k) { return new Field(k, 1, -1, null); }
  private static Field fixed(int k, int n) { return new Field(k, n, -1, null); }
  private static Field var(int k, int countOf) { return new Field(k, 0, countOf, null); }
  private static Field sub(Field[] schema) { return new Field(NESTED, 1, -1, schema); }
  private static Field subVar(Field[] schema, int countOf) { return new Field(NESTED, 0, countOf, schema); }

  // dof_t: type, axis[3], lower, upper, velocity, effort
  private static final Field[] DOF = {s(I8), fixed(F64, 3), s(F64), s(F64), s(F64), s(F64)};
  // link_t: name, mass, com[3], inertia[6]
  private static final Field[] LINK = {s(STR), s(F64), fixed(F64, 3), fixed(F64, 6)};
  // joint_t: name, parent_link, child_link, inboard[3], outboard[3], rest[4], servo_types,
  // num_dofs (int8), dofs[num_dofs], mimic_leader, mimic_multiplier, mimic_offset
  private static final Field[] JOINT = {s(STR), s(I32), s(I32), fixed(F64, 3), fixed(F64, 3), fixed(F64, 4),
      s(I8), s(I8), subVar(DOF, 7), s(I32), s(F64), s(F64)};
  // control_frame_t: name, parent_link, position[3], orientation[4], servo_types
  private static final Field[] FRAME = {s(STR), s(I32), fixed(F64, 3), fixed(F64, 4), s(I8)};
  // root_link_t: link, position[3], orientation[4], base_type
  private static final Field[] ROOT = {s(I32), fixed(F64, 3), fixed(F64, 4), s(I8)};
  // config_header_t: format_version, hash, then 9 int32 (total_dofs, counts and offsets)
  private static final Field[] HEADER = {s(I32), s(I64), fixed(I32, 9)};
  // robot_config_t: header, robot_name, num_links, links, num_joints, joints, num_frames, frames,
  // num_roots, roots
  static final Field[] ROBOT_CONFIG = {sub(HEADER), s(STR), s(I32), subVar(LINK, 2), s(I32), subVar(JOINT, 4),
      s(I32), subVar(FRAME, 6), s(I32), subVar(ROOT, 8)};
  // robot_info_t: name, driver, config_hash, total_dofs, base_type, panic, num_clients
  private static final Field[] ROBOT_INFO = {s(STR), s(STR), s(I64), s(I32), s(I8), s(I8), s(I32)};
  // announce_t: protocol_version, server_id, server_time_us, uptime_us, url_hint, traffic_layout,
  // keyed, num_robots, robots
  static final Field[] ANNOUNCE = {s(I16), s(I64), s(I64), s(I64), s(STR), s(I8), s(I8), s(I32),
      subVar(ROBOT_INFO, 7)};
  // hello_answer_t: protocol_version, client_id, client_nonce[16], server_id, session_id, refusal,
  // keyed, instance_nonce[16], server_nonce[16], server_kx[32], server_key[32], signature[64]
  static final Field[] HELLO_ANSWER = {s(I16), s(I64), fixed(I8, 16), s(I64), s(I64), s(STR), s(I8),
      fixed(I8, 16), fixed(I8, 16), fixed(I8, 32), fixed(I8, 32), fixed(I8, 64)};
  // reply_t: id, signal, message, exec_time_us, lateness_us, num_values, values
  private static final Field[] REPLY = {s(I64), s(I8), s(STR), s(I64), s(I64), s(I32), var(F64, 5)};
  // reply_package_t: protocol_version, client_id, server_id, session_id, session_status,
  // panic_status, panic_refusal, ack_sequence, server_receive_us, server_send_us, num_replies,
  // replies, mac[16]
  static final Field[] REPLY_PACKAGE = {s(I16), s(I64), s(I64), s(I64), s(I8), s(I8), s(STR), s(I64), s(I64),
      s(I64), s(I32), subVar(REPLY, 10), fixed(I8, 16)};

  private static final int MAX_DEPTH = 4;

  /** True when every declared count and length of `bytes` fits in them (the type hash is the decoder's to check). */
  static boolean fits(byte[] bytes, Field[] schema) {
    if (bytes.length < 8) return false;
    int[] pos = {8};
    return walk(bytes, pos, schema, 0);
  }

  private static long readInt(byte[] b, int at, int size) {
    long v = b[at];  // sign-extended
    for (int i = 1; i < size; ++i) v = v << 8 | (b[at + i] & 0xff);
    return v;
  }

  private static boolean walk(byte[] b, int[] pos, Field[] schema, int depth) {
    if (depth > MAX_DEPTH) return false;
    long[] value = new long[schema.length];  // this struct's integer scalars: the counts of its arrays
    for (int i = 0; i < schema.length; ++i) {
      Field f = schema[i];
      long n = f.countOf >= 0 ? value[f.countOf] : f.fixed;
      long left = b.length - pos[0];
      if (n < 0) return false;
      if (f.kind == STR) {
        for (long k = 0; k < n; ++k) {
          if (b.length - pos[0] < 4) return false;
          long size = readInt(b, pos[0], 4);  // with its NUL
          pos[0] += 4;
          if (size < 1 || size > b.length - pos[0] || b[pos[0] + (int) size - 1] != 0) return false;
          pos[0] += (int) size;
        }
      } else if (f.kind == NESTED) {
        if (n > left) return false;  // every element takes at least one byte
        for (long k = 0; k < n; ++k)
          if (!walk(b, pos, f.nested, depth + 1)) return false;
      } else {
        int size = SIZE[f.kind];
        if (n > left / size) return false;
        if (n == 1 && f.countOf < 0 && f.kind != F64) value[i] = readInt(b, pos[0], size);
        pos[0] += (int) (n * size);
      }
    }
    return true;
  }
}
