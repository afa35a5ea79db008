/* The C client example against hostile datagrams (review8): lcm-gen's C
 * decoders allocate `count * sizeof(element)` as soon as they read a
 * declared count, before checking it against the bytes that follow, and a
 * failed decode frees nothing. One ANNOUNCE of 46 bytes declaring millions
 * of robots made the client allocate (and leak) hundreds of MiB.
 * Runs under scripts/netns_run.sh:
 *   c_hostile_datagram_test URL
 * While rtc_connect() looks for a robot nobody serves, a second thread sends
 * such ANNOUNCEs; the process's address space must not grow by more than
 * 1 GiB (four of them). Exit 0 pass, 1 fail. */
#define _POSIX_C_SOURCE 200809L
#include <lcm/lcm.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "robotalk_c_client.h"
#include "robotalk_msgs_announce_t.h"

static const char* url;
enum { kDatagrams = 40 };

static long vm_size_kib(void) {
  FILE* f = fopen("/proc/self/status", "r");
  char line[256];
  long kib = -1;
  while (f && fgets(line, sizeof line, f))
    if (sscanf(line, "VmSize: %ld", &kib) == 1) break;
  if (f) fclose(f);
  return kib;
}

/* An ANNOUNCE declaring `n` robots and carrying none. */
static int hostile_announce(uint8_t* buf, int size, int32_t n) {
  robotalk_msgs_announce_t a;
  memset(&a, 0, sizeof a);
  a.url_hint = "";
  int len = robotalk_msgs_announce_t_encode(buf, 0, size, &a);
  if (len < 4) return -1;
  /* num_robots is the last field before the (empty) robots array. */
  buf[len - 4] = (uint8_t)(n >> 24), buf[len - 3] = (uint8_t)(n >> 16);
  buf[len - 2] = (uint8_t)(n >> 8), buf[len - 1] = (uint8_t)n;
  return len;
}

static void* send_hostile(void* arg) {
  (void)arg;
  lcm_t* lcm = lcm_create(url);
  if (!lcm) return NULL;
  uint8_t buf[256];
  /* 256 MiB of robot_info_t each */
  const int32_t n = (int32_t)((256u << 20) / sizeof(robotalk_msgs_robot_info_t));
  const int len = hostile_announce(buf, sizeof buf, n);
  struct timespec pause = {0, 20 * 1000 * 1000};
  nanosleep(&pause, NULL);
  for (int i = 0; i < kDatagrams && len > 0; ++i) {
    lcm_publish(lcm, "ROBOTALK/ANNOUNCE", buf, (unsigned)len);
    nanosleep(&pause, NULL);
  }
  lcm_destroy(lcm);
  return NULL;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: c_hostile_datagram_test URL\n");
    return 2;
  }
  url = argv[1];
  const long before = vm_size_kib();
  pthread_t sender;
  pthread_create(&sender, NULL, send_hostile, NULL);
  char err[512] = "";
  rtc_client* c = rtc_connect(url, "nobody", 1.5, err, sizeof err); /* nobody serves it: fails */
  pthread_join(sender, NULL);
  rtc_close(c);
  const long grown = vm_size_kib() - before;
  printf("%d hostile ANNOUNCEs (each declaring 256 MiB of robots): address space grew %ld MiB (%s)\n",
         kDatagrams, grown / 1024, err);
  /* glibc reserves a 64 MiB arena for each thread that allocates (the
   * sender's, LCM's receive thread) besides their stacks: 144 MiB with the
   * check; without it, 10,384 MiB. */
  if (grown > 1024 * 1024) {
    printf("FAIL: the decoder allocated what the datagrams declared, not what they carried\n");
    return 1;
  }
  printf("PASS\n");
  return 0;
}
