// The Java client example: connects to a robot, loads its configuration,
// sends a GOTO (direct mode), then a short timed sequence of pan/tilt
// set-points in delay mode, then one interpolated (cubic) sequence of pan
// waypoints, and prints every reply. Same steps and output as
// the C example (examples/c_client); tests/examples/client_example_test.sh runs it.
//   java -cp lcm.jar:robotalk_lcmtypes.jar:robotalk_java_client.jar robotalk.client.Example
//        [--url URL] [--robot NAME] [--delay S] [--pause S]
// --pause S: wait S seconds after the GOTO (keeping the session); the test
// restarts the server meanwhile, and the client must say hello again.
// Exit status 0 when every step succeeded.
package robotalk.client;

import robotalk_msgs.command_t;
import robotalk_msgs.package_header_t;
import robotalk_msgs.query_t;
import robotalk_msgs.reply_t;
import robotalk_msgs.robot_config_t;

public final class Example {
  static final double FRAME_SPACING_S = 0.25;
  static final double POINT_SPACING_S = 0.2;

  static void printReply(String what, reply_t r) {
    System.out.printf("reply %d %s: %s%s exec_us=%d late_ms=%.1f%n", r.id, what, RobotalkClient.signalName(r.signal),
        r.message.isEmpty() ? "" : " " + r.message, r.exec_time_us, r.lateness_us / 1000.0);
  }

  static command_t command(byte type, long startUs, String target, double... values) {
    command_t c = new command_t();
    c.type = type;
    c.start_time_us = startUs;
    c.target = target;
    c.num_values = (short) values.length;
    c.values = values;
    return c;
  }

  static boolean run(RobotalkClient client, double delayS, double pauseS) throws Exception {
    long[] clock = client.syncClock(5);
    System.out.printf("clock: offset_us=%d round_trip_us=%d%n", clock[0], clock[1]);

    robot_config_t config = client.loadConfig(5.0);
    int dofs = 0;
    for (robotalk_msgs.joint_t j : config.joints) dofs += j.num_dofs;
    System.out.printf("config: robot=%s links=%d joints=%d frames=%d dofs=%d hash=%016x (reply and message agree)%n",
        config.robot_name, config.num_links, config.num_joints, config.num_frames, dofs, config.header.hash);

    // Direct mode: a GOTO is answered when the base has reached its goal.
    command_t go = command(command_t.GOTO, 0, "", 0.5, 0.0, 0.0);
    client.sendCommands(package_header_t.MODE_DIRECT, go);
    reply_t r = client.await(30.0, go.id)[0];
    printReply("GOTO 0.5 0 0", r);
    boolean ok = r.signal == reply_t.SUCCESS;
    if (pauseS > 0) {
      System.out.printf("pausing %.1f s%n", pauseS);
      System.out.flush();
      client.pause(pauseS);
    }
    if (client.clockStale()) {  // a new server instance: its clock may be another's
      clock = client.syncClock(5);
      System.out.printf("new server instance %016x, session %016x: clock offset_us=%d%n", client.serverId(),
          client.sessionId(), clock[0]);
    }

    // Delay mode: each frame stamped server now + delay + its offset, all sent at once.
    String[] joints = {"pan", "pan", "pan", "tilt"};
    double[] targets = {0.1, 0.2, 0.3, -0.2};
    long[] ids = new long[joints.length];
    long startUs = client.serverNowUs() + (long) (delayS * 1e6);
    for (int k = 0; k < joints.length; k++) {
      command_t frame = command(command_t.JOINT_SETPOINT, startUs + (long) (k * FRAME_SPACING_S * 1e6), joints[k], targets[k]);
      client.sendCommands(package_header_t.MODE_DELAY, frame);
      ids[k] = frame.id;
    }
    System.out.printf("sequence sent: %d frames from server time %d us%n", joints.length, startUs);
    System.out.flush();
    reply_t[] replies = client.await(10.0 + delayS, ids);
    StringBuilder spacing = new StringBuilder("spacing_s:");
    for (int k = 0; k < joints.length; k++) {
      printReply(String.format("sequence +%.2f s %s %.2f", k * FRAME_SPACING_S, joints[k], targets[k]), replies[k]);
      ok &= replies[k].signal == reply_t.SUCCESS;
      if (k > 0) spacing.append(String.format(" %.3f", (replies[k].exec_time_us - replies[k - 1].exec_time_us) / 1e6));
    }
    System.out.println(spacing);

    // An interpolated sequence: pan's waypoints in one cubic package (delay mode), the middle one with its
    // velocity; each is answered when the trajectory passes it. It ends where the sequence left pan, at 0.3.
    // Sent only when everything so far succeeded: a client whose sequence failed moves nothing more.
    if (ok) {
      double[] way = {0.33, 0.36, 0.3};
      command_t[] points = new command_t[way.length];
      long trajStartUs = client.serverNowUs() + (long) (delayS * 1e6);
      for (int k = 0; k < way.length; k++) {
        points[k] = command(command_t.JOINT_SETPOINT, trajStartUs + (long) ((k + 1) * POINT_SPACING_S * 1e6), "pan", way[k]);
      }
      points[1].num_velocities = 1;
      points[1].velocities = new double[] {0.1};
      client.sendInterpolated(package_header_t.MODE_DELAY, package_header_t.INTERPOLATION_CUBIC, points);
      long[] pointIds = new long[points.length];
      for (int k = 0; k < points.length; k++) pointIds[k] = points[k].id;
      reply_t[] pointReplies = client.await(10.0 + delayS, pointIds);
      for (int k = 0; k < points.length; k++) {
        printReply(String.format("trajectory cubic +%.2f s pan %.2f", (k + 1) * POINT_SPACING_S, way[k]), pointReplies[k]);
        ok &= pointReplies[k].signal == reply_t.SUCCESS || pointReplies[k].signal == reply_t.MODIFIED;
      }
    }

    client.pause(0.5);  // the last set-point was taken when answered; let the joint get there
    reply_t pose = client.query(query_t.BASE_POSE, "", 5.0);
    System.out.printf("pose: x=%.3f y=%.3f theta=%.3f%n", pose.values[0], pose.values[1], pose.values[2]);
    reply_t pan = client.query(query_t.JOINT_STATE, "pan", 5.0);
    reply_t tilt = client.query(query_t.JOINT_STATE, "tilt", 5.0);
    System.out.printf("joints: pan=%.3f tilt=%.3f%n", pan.values[0], tilt.values[0]);
    return ok;
  }

  public static void main(String[] args) {
    String url = System.getenv().getOrDefault("LCM_DEFAULT_URL", "udpm://239.255.76.67:7667?ttl=0");
    String robot = "pioneer";
    double delayS = 0.5, pauseS = 0;
    for (int i = 0; i < args.length; i++) {
      if (args[i].equals("--url") && i + 1 < args.length) url = args[++i];
      else if (args[i].equals("--robot") && i + 1 < args.length) robot = args[++i];
      else if (args[i].equals("--delay") && i + 1 < args.length) delayS = Double.parseDouble(args[++i]);
      else if (args[i].equals("--pause") && i + 1 < args.length) pauseS = Double.parseDouble(args[++i]);
      else {
        System.err.println("usage: Example [--url URL] [--robot NAME] [--delay S] [--pause S]");
        System.exit(2);
      }
    }
    boolean ok = false;
    try (RobotalkClient client = new RobotalkClient(url, robot, 5.0)) {
      System.out.printf("connected: robot=%s server=%016x layout=%s session=%016x client=%016x%n", robot,
          client.serverId(), client.splitLayout() ? "split" : "single", client.sessionId(), client.clientId());
      ok = run(client, delayS, pauseS);
    } catch (Exception e) {
      System.err.println("error: " + e.getMessage());
    }
    System.out.println(ok ? "done" : "failed");
    System.exit(ok ? 0 : 1);
  }
}
