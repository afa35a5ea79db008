// The Java client example against hostile datagrams (review9): lcm-gen's Java
// decoders create a declared array (new T[count]) before reading it, and a
// message that did not decode threw IOException out of the waiting call. One
// ANNOUNCE declaring 2^31 - 1 robots made RobotalkClient's connect throw
// OutOfMemoryError; one that did not decode (a torn or foreign datagram), an
// EOFException: anyone on the network could keep the client from its robot.
// Runs under scripts/netns_run.sh:
//   java -cp ... HostileAnnounceTest URL
// While the client looks for a robot nobody serves, a thread sends hostile
// ANNOUNCEs (huge declared counts, a truncated one, another type's bytes); the
// client must end as without them: RobotalkException "no robot 'nobody'
// announced". Exit 0 pass, 1 fail.
import java.io.ByteArrayOutputStream;
import java.io.DataOutputStream;
import java.util.Arrays;
import lcm.lcm.LCM;
import robotalk.client.RobotalkClient;
import robotalk_msgs.announce_t;
import robotalk_msgs.robot_info_t;

public final class HostileAnnounceTest {
  // An ANNOUNCE declaring `n` robots and carrying none (num_robots is its last 4 bytes).
  static byte[] declaring(int n) throws Exception {
    announce_t a = new announce_t();
    a.url_hint = "";
    a.robots = new robot_info_t[0];
    ByteArrayOutputStream bytes = new ByteArrayOutputStream();
    a.encode(new DataOutputStream(bytes));
    byte[] b = bytes.toByteArray();
    b[b.length - 4] = (byte) (n >> 24);
    b[b.length - 3] = (byte) (n >> 16);
    b[b.length - 2] = (byte) (n >> 8);
    b[b.length - 1] = (byte) n;
    return b;
  }

  public static void main(String[] args) throws Exception {
    String url = args[0];
    byte[][] hostile = {declaring(Integer.MAX_VALUE), declaring(100_000_000), declaring(3),
        Arrays.copyOf(declaring(0), 20), "not an announce_t at all".getBytes("UTF-8")};
    LCM out = new LCM(url);
    Thread sender = new Thread(() -> {
      try {
        for (int i = 0; i < 40; ++i) {
          Thread.sleep(25);
          byte[] b = hostile[i % hostile.length];
          out.publish("ROBOTALK/ANNOUNCE", b, 0, b.length);
        }
      } catch (Exception e) {
        throw new RuntimeException(e);
      }
    });
    sender.start();
    String outcome;
    try (RobotalkClient c = new RobotalkClient(url, "nobody", 1.5)) {
      outcome = "connected to a robot nobody serves (client " + c.clientId() + ")";
    } catch (RobotalkClient.RobotalkException e) {
      outcome = e.getMessage();
    } catch (Throwable e) {
      outcome = "threw " + e;
    }
    sender.join();
    out.close();
    System.out.println("40 hostile ANNOUNCEs while connecting: " + outcome);
    if (!outcome.startsWith("no robot 'nobody' announced")) {
      System.out.println("FAIL: a hostile datagram ended the connect (expected: no robot 'nobody' announced)");
      System.exit(1);
    }
    System.out.println("PASS");
    System.exit(0);
  }
}
