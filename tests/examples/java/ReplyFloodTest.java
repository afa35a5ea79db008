// The Java client example under a flood of well-formed replies in its own
// session (review15): it filed every reply it read by its id, whatever the id,
// in a map it never emptied, so a sender on the LAN (open mode: the session
// and server ids travel in every package) naming fresh ids grew the heap
// without bound while the program waited in a call.
// Runs under scripts/netns_run.sh:
//   java -cp ... ReplyFloodTest URL
// Plays a server for robot 'fake' (announces it, answers the hello), connects,
// then sends 30,000 reply packages of the client's session, each with one
// reply of 2 KiB under an id the client never used, while the program waits
// in pause(); the heap may grow by at most 16 MiB. Exit 0 pass, 1 fail.
import lcm.lcm.LCM;
import robotalk.client.RobotalkClient;
import robotalk_msgs.reply_package_t;
import robotalk_msgs.reply_t;

public final class ReplyFloodTest {
  public static void main(String[] args) throws Exception {
    String url = args[0];
    LCM server = FakeRobotServer.start(url);

    try (RobotalkClient c = new RobotalkClient(url, "fake", 3.0)) {
      String replies = String.format("ROBOTALK/fake/REPLY/%016x", c.clientId());
      long before = FakeRobotServer.usedHeap();
      int sent = 30_000;
      Thread flooder = new Thread(() -> {
        try {
          reply_t r = new reply_t();
          // The client's own session: filed.
          reply_package_t p = FakeRobotServer.floodPackage(c.clientId(), c.serverId(), c.sessionId(), r);
          for (int i = 0; i < sent; ++i) {
            r.id = 1_000_000 + i;  // never one of the client's
            byte[] b = FakeRobotServer.encode(p);
            server.publish(replies, b, 0, b.length);
            if (i % 50 == 49) Thread.sleep(2);  // within what the client drains
          }
        } catch (Exception e) {
          throw new RuntimeException(e);
        }
      });
      flooder.start();
      while (flooder.isAlive()) c.pause(0.2);  // the program waits in a call: it reads and files
      c.pause(0.5);
      long grown = FakeRobotServer.usedHeap() - before;
      System.out.printf("%d reply packages of %d replies each under fresh ids: heap grew %.1f MiB%n", sent, 1,
          grown / 1048576.0);
      if (grown > 16L << 20) {
        System.out.println("FAIL: the client kept every reply it was sent, under any id");
        System.exit(1);
      }
    }
    System.out.println("PASS");
    System.exit(0);
  }
}
