// Decodes an encoded robotalk_msgs.robot_config_t from a file with the
// generated Java bindings, verifies its hash as docs/configuration_message.md
// describes, and prints one summary line (the format of write_config.cpp).
import java.nio.file.Files;
import java.nio.file.Paths;
import robotalk_msgs.robot_config_t;

public class DecodeConfig {
  // FNV-1a 64 over the encoding with the 8 bytes of header.hash (12..19) zero.
  static long configHash(byte[] encoded) {
    byte[] b = encoded.clone();
    for (int i = 12; i < 20; i++) b[i] = 0;
    long h = 0xcbf29ce484222325L;
    for (byte x : b) {
      h ^= (x & 0xff);
      h *= 0x100000001b3L;
    }
    return h;
  }

  public static void main(String[] args) throws Exception {
    byte[] bytes = Files.readAllBytes(Paths.get(args[0]));
    robot_config_t msg = new robot_config_t(bytes);
    int dofs = 0;
    for (int j = 0; j < msg.num_joints; j++) dofs += msg.joints[j].num_dofs;
    System.out.printf("robot=%s links=%d joints=%d frames=%d roots=%d dofs=%d hash=0x%016x verified=%s%n",
        msg.robot_name, msg.num_links, msg.num_joints, msg.num_frames, msg.num_roots, dofs,
        msg.header.hash, configHash(bytes) == msg.header.hash ? "yes" : "no");
  }
}
