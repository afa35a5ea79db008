// The Java client example under a flood of well-formed messages (review9):
// LCM's receive thread queued every message on the client's channels into an
// unbounded inbox, drained only while the program is inside a client call, so
// a sender flooding its REPLY channel while the program did something else
// grew the heap without bound.
// Runs under scripts/netns_run.sh:
//   java -cp ... InboxFloodTest URL
// Plays a server for robot 'fake' (announces it, answers the hello), connects,
// then floods the client's REPLY channel with 40,000 well-formed reply
// packages of 2 KiB (other sessions' replies) while the program is idle; the
// heap may grow by at most 32 MiB. Exit 0 pass, 1 fail.
import lcm.lcm.LCM;
import robotalk.client.RobotalkClient;
import robotalk_msgs.reply_package_t;
import robotalk_msgs.reply_t;

public final class InboxFloodTest {
  public static void main(String[] args) throws Exception {
    String url = args[0];
    LCM server = FakeRobotServer.start(url);

    try (RobotalkClient c = new RobotalkClient(url, "fake", 3.0)) {
      reply_t r = new reply_t();
      // Another instance's, another session's: never filed.
      reply_package_t p = FakeRobotServer.floodPackage(c.clientId(), 8, 1234, r);
      byte[] flood = FakeRobotServer.encode(p);
      String replies = String.format("ROBOTALK/fake/REPLY/%016x", c.clientId());
      long before = FakeRobotServer.usedHeap();
      int sent = 40_000;
      for (int i = 0; i < sent; ++i) {
        server.publish(replies, flood, 0, flood.length);
        if (i % 200 == 199) Thread.sleep(2);  // within what the socket buffers take
      }
      Thread.sleep(1000);  // the program is busy elsewhere: nothing drains the inbox
      long grown = FakeRobotServer.usedHeap() - before;
      System.out.printf("%d reply packages of %d bytes while idle: heap grew %.1f MiB%n", sent, flood.length,
          grown / 1048576.0);
      c.pause(0.2);  // the next call drains what was kept
      if (grown > 32L << 20) {
        System.out.println("FAIL: the client kept every message it was sent");
        System.exit(1);
      }
    }
    System.out.println("PASS");
    System.exit(0);
  }
}
