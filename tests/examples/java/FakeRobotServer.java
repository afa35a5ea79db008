// A fake server for robot 'fake', for the Java client example's flood tests
// (InboxFloodTest, ReplyFloodTest): it announces the robot (server id 7)
// for 3 s and answers every hello with session 99.
import java.io.ByteArrayOutputStream;
import java.io.DataOutputStream;
import java.io.IOException;
import lcm.lcm.LCM;
import lcm.lcm.LCMEncodable;
import robotalk.client.RobotalkClient;
import robotalk_msgs.announce_t;
import robotalk_msgs.hello_answer_t;
import robotalk_msgs.hello_t;
import robotalk_msgs.reply_package_t;
import robotalk_msgs.reply_t;
import robotalk_msgs.robot_info_t;

final class FakeRobotServer {
  private FakeRobotServer() {}

  static byte[] encode(LCMEncodable m) throws IOException {
    ByteArrayOutputStream bytes = new ByteArrayOutputStream();
    m.encode(new DataOutputStream(bytes));
    return bytes.toByteArray();
  }

  /**
   * A flood's reply package to `client`: one reply `r` of 2,000 characters
   * (its id the caller's), under the given server instance and session.
   */
  static reply_package_t floodPackage(long client, long server, long session, reply_t r) {
    r.message = new String(new char[2000]).replace('\0', 'x');
    r.values = new double[0];
    reply_package_t p = new reply_package_t();
    p.protocol_version = RobotalkClient.PROTOCOL_VERSION;
    p.client_id = client;
    p.server_id = server;
    p.session_id = session;
    p.panic_refusal = "";
    p.replies = new reply_t[] {r};
    p.num_replies = 1;
    return p;
  }

  /** The heap in use after a few collections, bytes. */
  static long usedHeap() throws InterruptedException {
    Runtime rt = Runtime.getRuntime();
    for (int i = 0; i < 3; ++i) {
      System.gc();
      Thread.sleep(50);
    }
    return rt.totalMemory() - rt.freeMemory();
  }

  /** Starts serving on `url`; the LCM instance it publishes with. */
  static LCM start(String url) throws IOException {
    LCM server = new LCM(url);
    server.subscribe("ROBOTALK/fake/HELLO", (lcm, channel, ins) -> {
      try {
        hello_t h = new hello_t(ins);
        hello_answer_t a = new hello_answer_t();
        a.protocol_version = RobotalkClient.PROTOCOL_VERSION;
        a.client_id = h.client_id;
        a.client_nonce = h.client_nonce;
        a.server_id = 7;
        a.session_id = 99;
        a.refusal = "";
        byte[] b = encode(a);
        lcm.publish(String.format("ROBOTALK/fake/HELLO/%016x", h.client_id), b, 0, b.length);
      } catch (IOException e) {
        throw new RuntimeException(e);
      }
    });
    announce_t an = new announce_t();
    an.protocol_version = RobotalkClient.PROTOCOL_VERSION;
    an.server_id = 7;
    an.url_hint = "";
    robot_info_t fake = new robot_info_t();
    fake.name = "fake";
    fake.driver = "none";
    an.robots = new robot_info_t[] {fake};
    an.num_robots = 1;
    byte[] announce = encode(an);
    Thread announcer = new Thread(() -> {
      try {
        for (int i = 0; i < 60; ++i) {
          server.publish("ROBOTALK/ANNOUNCE", announce, 0, announce.length);
          Thread.sleep(50);
        }
      } catch (Exception e) {
        throw new RuntimeException(e);
      }
    });
    announcer.setDaemon(true);
    announcer.start();
    return server;
  }
}
