// A small RoboTalk client in Java (protocol 3, open mode), written from
// docs/protocol.md and docs/writing_a_client.md with LCM's Java API
// (liblcm-java) and the generated robotalk_lcmtypes.jar.
//
// What it does: finds the robot on ROBOTALK/ANNOUNCE (and from it the traffic
// layout, single or split), opens a session with a hello, numbers packages
// 1, 2, 3 ..., retransmits a package with the same sequence until it is
// acknowledged (fixed 300 ms timeout, 10 tries) and, once acknowledged, every
// second until each item has its final reply; files replies by id, only ids
// of a package still pending (a second copy is ignored); sends a heartbeat every 250 ms so the server's watchdog
// keeps the session; says hello again after SESSION_UNKNOWN (nothing in that
// package ran) and sends the package again in the new session.
// Not done here: keyed mode (a keyed server is refused with an error), RFC 6298
// adaptive timeouts (the C++ client does that).
//
// Threads: LCM delivers messages on its own threads; they are only queued
// there. Everything else runs in the thread that calls this client's methods,
// one thread at a time. Errors: IOException (LCM) or RobotalkException.
package robotalk.client;

import java.io.ByteArrayOutputStream;
import java.io.DataOutputStream;
import java.io.IOException;
import java.security.SecureRandom;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.LinkedBlockingQueue;
import java.util.concurrent.TimeUnit;
import lcm.lcm.LCM;
import robotalk_msgs.announce_t;
import robotalk_msgs.command_t;
import robotalk_msgs.hello_answer_t;
import robotalk_msgs.hello_t;
import robotalk_msgs.package_header_t;
import robotalk_msgs.package_t;
import robotalk_msgs.query_t;
import robotalk_msgs.reply_package_t;
import robotalk_msgs.reply_t;
import robotalk_msgs.robot_config_t;

public final class RobotalkClient implements AutoCloseable {
  public static final short PROTOCOL_VERSION = 4;
  static final long RETRANSMIT_US = 300_000, RECHECK_US = 1_000_000, HEARTBEAT_US = 250_000,
      HELLO_REPEAT_US = 200_000;
  static final int MAX_TRIES = 10;

  /** Thrown for protocol-level failures: no robot, refused hello, timeouts. */
  public static final class RobotalkException extends Exception {
    private static final long serialVersionUID = 1L;
    public RobotalkException(String message) { super(message); }
  }

  /**
   * A text from the wire (anyone's in open mode) as an error names it: each control character (C0,
   * DEL, C1) as \xNN, so it never reaches a terminal as an escape nor forges a line (review14).
   */
  static String printable(String text) {
    StringBuilder out = new StringBuilder(text.length());
    for (int i = 0; i < text.length(); i++) {
      char c = text.charAt(i);
      if (c < 0x20 || (c >= 0x7f && c <= 0x9f)) out.append(String.format("\\x%02x", (int) c));
      else out.append(c);
    }
    return out.toString();
  }

  /** A reply_t, or a synthetic UNKNOWN_OUTCOME when the server instance changed. */
  public static final int UNKNOWN_OUTCOME = -1;
  static final String[] SIGNALS = {"SUCCESS", "MODIFIED", "NA", "BUSY", "INTERRUPTED", "ERROR", "PANIC"};
  public static String signalName(int s) {
    return s >= 0 && s < SIGNALS.length ? SIGNALS[s] : s == UNKNOWN_OUTCOME ? "UNKNOWN_OUTCOME" : "?";
  }

  private static final class Pending {
    long sequence, sessionId, firstSendUs, lastSendUs;
    byte[] bytes;
    boolean acked, sessionUnknown;
    int tries = 1;
    long[] ids;
    // Clock sample of its acknowledgement, only when sent once (Karn's rule).
    boolean haveClock;
    long t1, t4, serverReceiveUs, serverSendUs;
  }

  private final String robot;
  private final LCM mainLcm, requestLcm, replyLcm;
  private final boolean split;
  private final long clientId;
  private final SecureRandom random = new SecureRandom();
  // Bounded: LCM's thread fills it, only a client call drains it, and anyone can send to our
  // channels. A message that finds it full is dropped and counted (droppedMessages()); a lost
  // reply comes again: the package is sent again until acknowledged, and every second until each
  // of its items has its final reply.
  static final int INBOX_CAPACITY = 256;
  private final LinkedBlockingQueue<Object[]> inbox = new LinkedBlockingQueue<>(INBOX_CAPACITY);
  private final java.util.concurrent.atomic.AtomicLong droppedMessages = new java.util.concurrent.atomic.AtomicLong();
  private final Map<Long, Pending> pending = new HashMap<>();
  private final Map<Long, reply_t> replies = new HashMap<>();
  private final String helloChannel, requestChannel, replyChannel, helloAnswerChannel;
  private long sessionId, serverId, nextSequence = 1, nextId = 1, lastNewPackageUs, clockOffsetUs;
  private byte[] nonce = new byte[16];
  private boolean helloAnswered, clockStale;
  private String refusal = "";
  private robot_config_t config;
  private long refusedMessages;

  /** The client's monotonic clock, microseconds. */
  public static long nowUs() { return System.nanoTime() / 1000; }

  /**
   * Listens to ROBOTALK/ANNOUNCE on url until robot is announced (at most timeoutS), opens the
   * LCM instances its traffic layout asks for, and says hello.
   */
  public RobotalkClient(String url, String robot, double timeoutS) throws IOException, RobotalkException {
    this.robot = robot;
    long id = 0;
    while (id == 0) id = random.nextLong();
    clientId = id;
    String hex = String.format("%016x", clientId);
    helloChannel = "ROBOTALK/" + robot + "/HELLO";
    helloAnswerChannel = helloChannel + "/" + hex;
    requestChannel = "ROBOTALK/" + robot + "/REQUEST";
    replyChannel = "ROBOTALK/" + robot + "/REPLY/" + hex;
    url = lcmUrl(url);
    mainLcm = new LCM(url);
    announce_t a = findRobot(timeoutS);
    split = a.traffic_layout == announce_t.TRAFFIC_SPLIT;
    if (!split && a.traffic_layout != announce_t.TRAFFIC_SINGLE) {
      mainLcm.close();
      throw new RobotalkException("unknown traffic layout " + a.traffic_layout + " in ANNOUNCE");
    }
    if (split) {
      requestLcm = new LCM(shiftedUrl(url, 1));
      replyLcm = new LCM(shiftedUrl(url, 2 + (int) Long.remainderUnsigned(clientId, 64)));
    } else {
      requestLcm = replyLcm = mainLcm;
    }
    replyLcm.subscribe(java.util.regex.Pattern.quote(helloAnswerChannel), this::enqueue);
    replyLcm.subscribe(java.util.regex.Pattern.quote(replyChannel), this::enqueue);
    sayHello(timeoutS);
  }

  public long clientId() { return clientId; }
  public long sessionId() { return sessionId; }
  public long serverId() { return serverId; }
  public boolean splitLayout() { return split; }

  @Override
  public void close() {
    if (replyLcm != mainLcm) replyLcm.close();
    if (requestLcm != mainLcm) requestLcm.close();
    mainLcm.close();
  }

  /** url without RoboTalk's own option traffic=single|split (LCM does not know it; ANNOUNCE says the layout). */
  static String lcmUrl(String url) {
    int q = url.indexOf('?');
    if (q < 0) return url;
    List<String> kept = new ArrayList<>();
    for (String opt : url.substring(q + 1).split("&"))
      if (!opt.isEmpty() && !opt.startsWith("traffic=")) kept.add(opt);
    return url.substring(0, q) + (kept.isEmpty() ? "" : "?" + String.join("&", kept));
  }

  /** "udpm://G:P?opts" -> "udpm://G:(P+delta)?opts" (the split layout's ports; no port: LCM's 7667). */
  static String shiftedUrl(String url, int delta) throws RobotalkException {
    java.util.regex.Matcher m = java.util.regex.Pattern.compile("^(udpm://[^:/?]+)(?::(\\d+))?(\\?.*)?$").matcher(url);
    if (!m.matches()) throw new RobotalkException("the split layout needs a udpm://GROUP:PORT URL, not '" + url + "'");
    int port = m.group(2) == null ? 7667 : Integer.parseInt(m.group(2));
    return m.group(1) + ":" + (port + delta) + (m.group(3) == null ? "" : m.group(3));
  }

  private void enqueue(LCM lcm, String channel, lcm.lcm.LCMDataInputStream ins) {
    try {
      byte[] b = new byte[ins.available()];
      ins.readFully(b);
      if (!inbox.offer(new Object[] {channel, b}) && droppedMessages.getAndIncrement() == 0)
        System.err.println("robotalk-java: the inbox is full (" + INBOX_CAPACITY + " messages not yet handled): "
            + "dropped a message on " + channel + " (counted, said once; a flood, or no client call for long)");
    } catch (IOException e) {
      // a truncated message: dropped, as LCM would
    }
  }

  private static final int MAX_HEARD = 32;

  private announce_t findRobot(double timeoutS) throws IOException, RobotalkException {
    lcm.lcm.LCMSubscriber sub = this::enqueue;
    mainLcm.subscribe("ROBOTALK/ANNOUNCE", sub);
    // The other robots heard, for the error: a set, and at most MAX_HEARD of
    // them (a flood of ANNOUNCEs naming made-up robots costs no memory).
    java.util.Set<String> heard = new java.util.TreeSet<>();
    long deadline = nowUs() + (long) (timeoutS * 1e6);
    String problem = null;
    announce_t found = null;
    while (found == null && problem == null && nowUs() < deadline) {
      Object[] m = take(deadline - nowUs());
      if (m == null || !m[0].equals("ROBOTALK/ANNOUNCE")) continue;
      announce_t a = checked((String) m[0], (byte[]) m[1], MessageCheck.ANNOUNCE, announce_t::new);
      if (a == null) continue;
      for (robotalk_msgs.robot_info_t r : a.robots) {
        if (!r.name.equals(robot)) {
          if (heard.size() < MAX_HEARD) heard.add(printable(r.name));
        } else if (a.protocol_version != PROTOCOL_VERSION) {
          problem = "'" + robot + "' speaks protocol " + a.protocol_version + "; this client speaks " + PROTOCOL_VERSION;
        } else if (a.keyed) {
          problem = "the server of '" + robot + "' requires keys (keyed mode, docs/security.md); "
              + "this example client supports open mode only";
        } else {
          found = a;
        }
      }
    }
    mainLcm.unsubscribe("ROBOTALK/ANNOUNCE", sub);
    if (found == null && problem == null)
      problem = String.format("no robot '%s' announced within %.1f s (heard: %s)", robot, timeoutS,
          heard.isEmpty() ? "nothing" : String.join(", ", heard));
    if (problem != null) {
      mainLcm.close();
      throw new RobotalkException(problem);
    }
    inbox.clear();
    return found;
  }

  private Object[] take(long waitUs) {
    try {
      return inbox.poll(Math.max(0, waitUs), TimeUnit.MICROSECONDS);
    } catch (InterruptedException e) {
      Thread.currentThread().interrupt();
      return null;
    }
  }

  // ---- receiving -----------------------------------------------------------

  /** Handles what arrives for at most waitUs. */
  private void handleFor(long waitUs) throws IOException {
    Object[] m = take(waitUs);
    while (m != null) {
      dispatch((String) m[0], (byte[]) m[1]);
      m = inbox.poll();
    }
  }

  private void dispatch(String channel, byte[] bytes) throws IOException {
    if (channel.equals(replyChannel)) {
      reply_package_t m = checked(channel, bytes, MessageCheck.REPLY_PACKAGE, reply_package_t::new);
      if (m != null) onReply(m);
    } else if (channel.equals(helloAnswerChannel)) {
      hello_answer_t m = checked(channel, bytes, MessageCheck.HELLO_ANSWER, hello_answer_t::new);
      if (m != null) onHelloAnswer(m);
    } else if (channel.equals("ROBOTALK/" + robot + "/CONFIG")) {
      robot_config_t m = checked(channel, bytes, MessageCheck.ROBOT_CONFIG, robot_config_t::new);
      if (m != null) config = m;
    }
  }

  private interface Decoder<T> {
    T decode(byte[] bytes) throws IOException;
  }

  /**
   * The decoded message, or null when it is refused: a declared count or length past its bytes
   * (MessageCheck, before lcm-gen's decoder allocates it) or a message that does not decode (another
   * type, corrupt). Anyone on the network can send one: it is dropped, counted and said once.
   */
  private <T> T checked(String channel, byte[] bytes, MessageCheck.Field[] schema, Decoder<T> decoder) {
    String why;
    if (!MessageCheck.fits(bytes, schema)) {
      why = "a declared count or length goes past its " + bytes.length + " bytes";
    } else {
      try {
        return decoder.decode(bytes);
      } catch (IOException e) {
        why = "it does not decode (" + e.getMessage() + ")";
      }
    }
    if (refusedMessages++ == 0)
      System.err.println("robotalk-java: dropped a message on " + channel + ": " + why
          + " (hostile or corrupt; counted, said once)");
    return null;
  }

  /** Messages dropped because they did not decode or declared more than they carried. */
  public long refusedMessages() { return refusedMessages; }

  /** Messages dropped because the inbox was full (INBOX_CAPACITY not yet handled). */
  public long droppedMessages() { return droppedMessages.get(); }

  private void onHelloAnswer(hello_answer_t m) {
    if (m.client_id != clientId || !Arrays.equals(m.client_nonce, nonce)) return;  // not our hello
    helloAnswered = true;
    sessionId = m.session_id;
    if (serverId != 0 && m.server_id != serverId) clockStale = true;
    serverId = m.server_id;
    refusal = m.keyed ? "the server answered in keyed mode" : m.session_id == 0 ? m.refusal : "";
  }

  // Filed only under the id of an item of a package still pending (sent, not all its replies in): a reply
  // under any other id (a forger's, naming ids this client never used) is dropped, so the map never holds
  // more than this client sent. A second copy: ignored.
  private void fileReply(reply_t r) {
    for (Pending p : pending.values()) {
      for (long id : p.ids) {
        if (id == r.id) {
          replies.putIfAbsent(r.id, r);
          return;
        }
      }
    }
  }

  /** The items of an acknowledged package whose session is gone: may or may not have run; never re-sent. */
  private void unknownOutcome(Pending p, String why) {
    for (long id : p.ids) {
      reply_t r = new reply_t();
      r.id = id;
      r.signal = (byte) UNKNOWN_OUTCOME;
      r.message = "may or may not have run (" + why + "); query or re-plan";
      r.values = new double[0];
      fileReply(r);
    }
  }

  private void onReply(reply_package_t m) {
    long t4 = nowUs();
    if (m.protocol_version != PROTOCOL_VERSION || m.client_id != clientId) return;
    if (serverId != 0 && m.server_id != serverId) {
      // A new server instance: what the old one acknowledged may or may not have run.
      String why = String.format("server instance %016x is gone", serverId);
      for (Pending p : pending.values()) if (p.acked) unknownOutcome(p, why);
      serverId = m.server_id;
      clockStale = true;
    }
    Pending p = pending.get(m.ack_sequence);
    if (m.session_status == reply_package_t.SESSION_UNKNOWN) {
      if (p != null && p.sessionId == m.session_id) {
        if (p.acked) unknownOutcome(p, "its session expired");  // its first copy was accepted before
        else p.sessionUnknown = true;  // nothing in it ran: send it again in a new session
      }
      if (m.session_id == sessionId) helloAnswered = false;  // say hello again
      return;
    }
    if (m.session_id != sessionId) return;  // an older session's late answer
    if (p != null && !p.acked) {
      p.acked = true;
      if (p.tries == 1) {
        p.haveClock = true;
        p.t1 = p.firstSendUs;
        p.t4 = t4;
        p.serverReceiveUs = m.server_receive_us;
        p.serverSendUs = m.server_send_us;
      }
    }
    for (reply_t r : m.replies) fileReply(r);
  }

  // ---- sending -------------------------------------------------------------

  private package_t newPackage(byte payloadType, int size, byte mode) {
    package_t pkg = new package_t();
    package_header_t h = pkg.header = new package_header_t();  // lcm-gen's Java leaves nested structs null
    h.protocol_version = PROTOCOL_VERSION;
    h.client_id = clientId;
    h.session_id = sessionId;
    h.sequence = nextSequence++;
    h.send_time_us = nowUs();
    h.payload_type = payloadType;
    h.payload_size = size;
    h.mode = mode;
    pkg.queries = new query_t[0];
    pkg.commands = new command_t[0];
    pkg.mac = new byte[16];  // open mode: zeros
    return pkg;
  }

  private byte[] publish(package_t pkg) throws IOException {
    ByteArrayOutputStream buffer = new ByteArrayOutputStream();
    pkg.encode(new DataOutputStream(buffer));
    byte[] bytes = buffer.toByteArray();
    lastNewPackageUs = nowUs();  // before sending: a clock sample's t1
    requestLcm.publish(requestChannel, bytes, 0, bytes.length);
    return bytes;
  }

  private long track(package_t pkg, long[] ids) throws IOException {
    Pending p = new Pending();
    p.bytes = publish(pkg);
    p.sequence = pkg.header.sequence;
    p.sessionId = sessionId;
    p.firstSendUs = p.lastSendUs = lastNewPackageUs;
    p.ids = ids;
    pending.put(p.sequence, p);
    return p.sequence;
  }

  /** Sends one package of queries, non-blocking; sets each query's id. Returns its sequence. */
  public long sendQueries(query_t... queries) throws IOException {
    long[] ids = new long[queries.length];
    for (int i = 0; i < queries.length; i++) ids[i] = queries[i].id = nextId++;
    package_t pkg = newPackage(package_header_t.PAYLOAD_QUERIES, queries.length, package_header_t.MODE_DIRECT);
    pkg.num_queries = queries.length;
    pkg.queries = queries;
    return track(pkg, ids);
  }

  /** Sends one package of commands, non-blocking; sets each command's id. mode: package_header_t.MODE_*. */
  public long sendCommands(byte mode, command_t... commands) throws IOException {
    return sendInterpolated(mode, package_header_t.INTERPOLATION_STEP, commands);
  }

  /**
   * The same with the package's interpolation (package_header_t.INTERPOLATION_*): its timed JOINT_SETPOINT /
   * FRAME_SETPOINT commands are the waypoints of a trajectory (docs/protocol.md, Trajectories), each command's
   * velocities and accelerations its rates (none: chosen by the server).
   */
  public long sendInterpolated(byte mode, byte interpolation, command_t... commands) throws IOException {
    long[] ids = new long[commands.length];
    for (int i = 0; i < commands.length; i++) ids[i] = commands[i].id = nextId++;
    package_t pkg = newPackage(package_header_t.PAYLOAD_COMMANDS, commands.length, mode);
    pkg.header.interpolation = interpolation;
    pkg.num_commands = commands.length;
    pkg.commands = commands;
    return track(pkg, ids);
  }

  // ---- sessions ------------------------------------------------------------

  private void sayHello(double timeoutS) throws IOException, RobotalkException {
    hello_t hello = new hello_t();  // keyed = false, key fields zero: open mode
    hello.protocol_version = PROTOCOL_VERSION;
    hello.client_id = clientId;
    random.nextBytes(nonce);
    hello.client_nonce = nonce.clone();
    hello.client_key = new byte[32];
    hello.client_kx = new byte[32];
    hello.signature = new byte[64];
    helloAnswered = false;
    long deadline = nowUs() + (long) (timeoutS * 1e6), nextHello = 0;
    while (!helloAnswered) {
      long now = nowUs();
      if (now >= deadline) throw new RobotalkException(String.format("no answer to hello from '%s' within %.1f s", robot, timeoutS));
      if (now >= nextHello) {
        requestLcm.publish(helloChannel, hello);
        nextHello = now + HELLO_REPEAT_US;
      }
      handleFor(Math.min(nextHello, deadline) - now);
    }
    if (sessionId == 0 || !refusal.isEmpty()) throw new RobotalkException("hello refused by '" + robot + "': " + printable(refusal));
    lastNewPackageUs = nowUs();
  }

  /** Timers: a new hello when the session is gone, resends, retransmissions, heartbeats. */
  private void runTimers() throws IOException, RobotalkException {
    if (!helloAnswered) {
      System.err.println("robotalk-java: session unknown to the server; saying hello again");
      sayHello(3.0);
    }
    for (Pending p : new ArrayList<>(pending.values())) {
      if (!p.sessionUnknown) continue;  // nothing in it ran: send it again, new sequence, new session
      package_t pkg = new package_t(p.bytes);
      pending.remove(p.sequence);
      pkg.header.sequence = nextSequence++;
      pkg.header.session_id = sessionId;
      pkg.header.send_time_us = nowUs();
      track(pkg, p.ids);
    }
    long now = nowUs();
    for (Pending p : new ArrayList<>(pending.values())) {
      boolean complete = true;
      for (long id : p.ids) complete &= replies.containsKey(id);
      if (p.acked && complete) {
        pending.remove(p.sequence);
        continue;
      }
      if (now - p.lastSendUs < (p.acked ? RECHECK_US : RETRANSMIT_US)) continue;
      if (!p.acked && p.tries >= MAX_TRIES)
        throw new RobotalkException("package " + p.sequence + " not acknowledged after " + p.tries + " tries");
      requestLcm.publish(requestChannel, p.bytes, 0, p.bytes.length);  // the same sequence
      p.lastSendUs = now;
      if (!p.acked) p.tries++;
    }
    if (now - lastNewPackageUs >= HEARTBEAT_US) {
      publish(newPackage(package_header_t.PAYLOAD_QUERIES, 0, package_header_t.MODE_DIRECT));
    }
  }

  /** Waits for the final reply of every id (at most timeoutS), keeping the session going. */
  public reply_t[] await(double timeoutS, long... ids) throws IOException, RobotalkException {
    long deadline = nowUs() + (long) (timeoutS * 1e6);
    for (;;) {
      int missing = 0;
      for (long id : ids) if (!replies.containsKey(id)) missing++;
      if (missing == 0) break;
      if (nowUs() >= deadline)
        throw new RobotalkException(String.format("%d of %d replies missing after %.1f s", missing, ids.length, timeoutS));
      runTimers();
      handleFor(20_000);
    }
    reply_t[] out = new reply_t[ids.length];
    for (int i = 0; i < ids.length; i++) out[i] = replies.get(ids[i]);
    return out;
  }

  /** Lets seconds pass while keeping the session (heartbeats, retransmissions, replies filed). */
  public void pause(double seconds) throws IOException, RobotalkException {
    long deadline = nowUs() + (long) (seconds * 1e6);
    for (long now = nowUs(); now < deadline; now = nowUs()) {
      runTimers();
      handleFor(Math.min(20_000, deadline - now));
    }
  }

  /** One query, blocking. */
  public reply_t query(byte type, String target, double timeoutS) throws IOException, RobotalkException {
    query_t q = new query_t();
    q.type = type;
    q.target = target;
    sendQueries(q);
    return await(timeoutS, q.id)[0];
  }

  /**
   * Estimates the server clock offset from `samples` CLOCK queries, keeping the sample with the
   * smallest round trip (docs/protocol.md, Clocks). Returns {offset_us, round_trip_us}.
   */
  public long[] syncClock(int samples) throws IOException, RobotalkException {
    long bestRtt = Long.MAX_VALUE, bestOffset = 0;
    int usable = 0;
    for (int s = 0; s < 3 * samples && usable < samples; s++) {  // retransmitted samples do not count
      query_t q = new query_t();
      q.type = query_t.CLOCK;
      q.target = "";
      long seq = sendQueries(q);
      Pending p = pending.get(seq);
      await(3.0, q.id);
      if (!p.haveClock) continue;  // retransmitted: an ambiguous sample
      usable++;
      long rtt = (p.t4 - p.t1) - (p.serverSendUs - p.serverReceiveUs);
      long offset = ((p.serverReceiveUs - p.t1) + (p.serverSendUs - p.t4)) / 2;
      if (rtt < bestRtt) {
        bestRtt = rtt;
        bestOffset = offset;
      }
    }
    if (bestRtt == Long.MAX_VALUE) throw new RobotalkException("no usable CLOCK sample");
    clockOffsetUs = bestOffset;
    clockStale = false;
    return new long[] {bestOffset, bestRtt};
  }

  /** True when a new server instance answered since the last syncClock: sync again before delay mode. */
  public boolean clockStale() { return clockStale; }

  /** The server clock now, from the client clock and the last syncClock. */
  public long serverNowUs() { return nowUs() + clockOffsetUs; }

  /**
   * Loads the configuration: subscribes to ROBOTALK/<robot>/CONFIG, sends a CONFIG query and waits
   * for both its reply and the robot_config_t whose hash the reply names (either order).
   */
  public robot_config_t loadConfig(double timeoutS) throws IOException, RobotalkException {
    String channel = "ROBOTALK/" + robot + "/CONFIG";
    lcm.lcm.LCMSubscriber sub = this::enqueue;
    mainLcm.subscribe(java.util.regex.Pattern.quote(channel), sub);  // before asking
    try {
      reply_t r = query(query_t.CONFIG, "", timeoutS);
      if (r.signal != reply_t.SUCCESS) throw new RobotalkException("CONFIG answered " + signalName(r.signal) + ": " + printable(r.message));
      long deadline = nowUs() + (long) (timeoutS * 1e6);
      while (config == null || !String.format("%016x", config.header.hash).equals(r.message)) {
        if (nowUs() >= deadline)
          throw new RobotalkException("no robot_config_t with hash " + printable(r.message) + " on " + channel);
        runTimers();
        handleFor(20_000);
      }
      return config;
    } finally {
      mainLcm.unsubscribe(java.util.regex.Pattern.quote(channel), sub);
    }
  }
}
