// The Java client's checked decoding (examples/java_client/.../MessageCheck.java):
// each schema accepts what lcm-gen's Java encoder writes (arrays and strings in
// every place, trailing bytes too), refuses every truncation of it, a declared
// count past the end, a negative one and a string without its NUL.
//   java -cp ... robotalk.client.MessageCheckTest       Exit 0 pass, 1 fail.
package robotalk.client;

import java.io.ByteArrayOutputStream;
import java.io.DataOutputStream;
import java.io.IOException;
import java.util.Arrays;
import lcm.lcm.LCMEncodable;
import robotalk_msgs.announce_t;
import robotalk_msgs.config_header_t;
import robotalk_msgs.control_frame_t;
import robotalk_msgs.dof_t;
import robotalk_msgs.hello_answer_t;
import robotalk_msgs.joint_t;
import robotalk_msgs.link_t;
import robotalk_msgs.reply_package_t;
import robotalk_msgs.reply_t;
import robotalk_msgs.robot_config_t;
import robotalk_msgs.robot_info_t;
import robotalk_msgs.root_link_t;

public final class MessageCheckTest {
  private static int failures = 0;

  private static void check(boolean ok, String what) {
    if (!ok) {
      ++failures;
      System.out.println("FAIL: " + what);
    }
  }

  private static byte[] encode(LCMEncodable m) throws IOException {
    ByteArrayOutputStream bytes = new ByteArrayOutputStream();
    m.encode(new DataOutputStream(bytes));
    return bytes.toByteArray();
  }

  // Accepted whole and with trailing bytes; every strict prefix refused.
  private static void checkEncoding(String what, byte[] b, MessageCheck.Field[] schema) {
    check(MessageCheck.fits(b, schema), what + ": the whole encoding (" + b.length + " bytes) is refused");
    byte[] longer = Arrays.copyOf(b, b.length + 120);
    Arrays.fill(longer, b.length, longer.length, (byte) 0xab);
    check(MessageCheck.fits(longer, schema), what + ": trailing bytes are refused");
    for (int n = 0; n < b.length; ++n)
      check(!MessageCheck.fits(Arrays.copyOf(b, n), schema),
          what + ": a truncation to " + n + " of " + b.length + " bytes passes");
  }

  private static robot_info_t robot(String name, String driver) {
    robot_info_t r = new robot_info_t();
    r.name = name;
    r.driver = driver;
    return r;
  }

  public static void main(String[] args) throws IOException {
    announce_t a = new announce_t();
    a.url_hint = "hint";
    a.robots = new robot_info_t[] {robot("pioneer", "kinematic"), robot("arm", "ode")};
    a.num_robots = 2;
    checkEncoding("announce_t", encode(a), MessageCheck.ANNOUNCE);
    a.robots = new robot_info_t[0];
    a.num_robots = 0;
    byte[] b = encode(a);
    b[b.length - 4] = 0x10;  // num_robots, the last field before the (empty) robots
    check(!MessageCheck.fits(b, MessageCheck.ANNOUNCE), "a huge num_robots passes");
    b[b.length - 4] = (byte) 0xff;
    check(!MessageCheck.fits(b, MessageCheck.ANNOUNCE), "a negative num_robots passes");

    hello_answer_t h = new hello_answer_t();
    h.refusal = "refused for a reason";
    checkEncoding("hello_answer_t", encode(h), MessageCheck.HELLO_ANSWER);

    reply_t one = new reply_t();
    one.id = 1;
    one.message = "ok";
    one.values = new double[] {1, 2, 3};
    one.num_values = 3;
    reply_t two = new reply_t();
    two.id = 2;
    two.message = "";
    two.values = new double[0];
    reply_package_t r = new reply_package_t();
    r.panic_refusal = "";
    r.replies = new reply_t[] {one, two};
    r.num_replies = 2;
    b = encode(r);
    checkEncoding("reply_package_t", b, MessageCheck.REPLY_PACKAGE);
    for (int i = 0; i + 2 < b.length; ++i) {  // "ok" and its NUL: drop the NUL
      if (b[i] == 'o' && b[i + 1] == 'k' && b[i + 2] == 0) {
        byte[] copy = b.clone();
        copy[i + 2] = 'x';
        check(!MessageCheck.fits(copy, MessageCheck.REPLY_PACKAGE), "a string without NUL passes");
      }
    }

    link_t link = new link_t();
    link.name = "base";
    joint_t joint = new joint_t();
    joint.name = "pan";
    joint.dofs = new dof_t[] {new dof_t(), new dof_t()};
    joint.num_dofs = 2;
    joint.mimic_leader = -1;
    control_frame_t frame = new control_frame_t();
    frame.name = "camera";
    robot_config_t cfg = new robot_config_t();
    cfg.header = new config_header_t();
    cfg.robot_name = "pioneer";
    cfg.links = new link_t[] {link};
    cfg.num_links = 1;
    cfg.joints = new joint_t[] {joint};
    cfg.num_joints = 1;
    cfg.frames = new control_frame_t[] {frame};
    cfg.num_frames = 1;
    cfg.roots = new root_link_t[] {new root_link_t()};
    cfg.num_roots = 1;
    checkEncoding("robot_config_t", encode(cfg), MessageCheck.ROBOT_CONFIG);

    System.out.println((failures == 0 ? "PASS" : "FAIL") + " (" + failures + " failures)");
    System.exit(failures == 0 ? 0 : 1);
  }
}
