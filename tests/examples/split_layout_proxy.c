/* Test fixture: makes a robotalk-server that runs on one URL look like a
 * server with the split traffic layout (announce_t.TRAFFIC_SPLIT, docs/protocol.md),
 * so the client examples' split path is tested whatever layout the server
 * itself uses. From the server's URL S to the main URL udpm://G:P?opts:
 *   S -> P      ROBOTALK/ANNOUNCE (traffic_layout rewritten to SPLIT), CONFIG, STATE
 *   P+1 -> S    ROBOTALK/<robot>/HELLO and REQUEST
 *   S -> P+2+b  ROBOTALK/<robot>/REPLY/<client> and HELLO/<client>, b = client id mod 64
 *   split_layout_proxy SERVER_URL MAIN_URL SECONDS
 * Runs for SECONDS, then exits 0. */
#define _POSIX_C_SOURCE 200809L
#include <lcm/lcm.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <time.h>

#include "robotalk_msgs_announce_t.h"

static lcm_t* server_lcm;
static lcm_t* main_lcm;
static lcm_t* request_lcm;
static lcm_t* reply_lcms[64];
static char main_url[512];

/* "udpm://G:P?opts" -> "udpm://G:(P+delta)?opts". */
static void shifted(const char* url, int delta, char* out, size_t len) {
  const char* colon = strchr(url + strlen("udpm://"), ':');
  char* end = NULL;
  long port = strtol(colon + 1, &end, 10);
  snprintf(out, len, "%.*s:%ld%s", (int)(colon - url), url, port + delta, end);
}

static lcm_t* reply_lcm(uint64_t client_id) {
  int b = (int)(client_id % 64);
  if (!reply_lcms[b]) {
    char url[512];
    shifted(main_url, 2 + b, url, sizeof url);
    reply_lcms[b] = lcm_create(url);
  }
  return reply_lcms[b];
}

static void from_server(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  (void)user;
  const char* last = strrchr(channel, '/');
  if (strcmp(channel, "ROBOTALK/ANNOUNCE") == 0) {
    robotalk_msgs_announce_t a;
    if (robotalk_msgs_announce_t_decode(rbuf->data, 0, (int)rbuf->data_size, &a) < 0) return;
    a.traffic_layout = ROBOTALK_MSGS_ANNOUNCE_T_TRAFFIC_SPLIT;
    robotalk_msgs_announce_t_publish(main_lcm, channel, &a);
    robotalk_msgs_announce_t_decode_cleanup(&a);
  } else if (strstr(channel, "/REPLY/") || (strstr(channel, "/HELLO/") && strlen(last + 1) == 16)) {
    uint64_t client_id = strtoull(last + 1, NULL, 16);
    lcm_publish(reply_lcm(client_id), channel, rbuf->data, rbuf->data_size);
  } else if ((strcmp(last, "/CONFIG") == 0 || strcmp(last, "/STATE") == 0)) {
    lcm_publish(main_lcm, channel, rbuf->data, rbuf->data_size);
  }
}

static void to_server(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  (void)user;
  lcm_publish(server_lcm, channel, rbuf->data, rbuf->data_size);
}

int main(int argc, char** argv) {
  if (argc != 4 || strncmp(argv[2], "udpm://", 7) != 0) {
    fprintf(stderr, "usage: split_layout_proxy SERVER_URL udpm://G:P?opts SECONDS\n");
    return 2;
  }
  snprintf(main_url, sizeof main_url, "%s", argv[2]);
  char request_url[512];
  shifted(main_url, 1, request_url, sizeof request_url);
  server_lcm = lcm_create(argv[1]);
  main_lcm = lcm_create(main_url);
  request_lcm = lcm_create(request_url);
  if (!server_lcm || !main_lcm || !request_lcm) return 1;
  lcm_subscribe(server_lcm, "ROBOTALK/.*", from_server, NULL);
  lcm_subscribe(request_lcm, "ROBOTALK/[^/]+/(HELLO|REQUEST)", to_server, NULL);
  struct timespec t0, now;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  const double seconds = atof(argv[3]);
  do {
    fd_set fds;
    FD_ZERO(&fds);
    int a = lcm_get_fileno(server_lcm), b = lcm_get_fileno(request_lcm);
    FD_SET(a, &fds);
    FD_SET(b, &fds);
    struct timeval tv = {.tv_sec = 0, .tv_usec = 50000};
    if (select((a > b ? a : b) + 1, &fds, NULL, NULL, &tv) > 0) {
      if (FD_ISSET(a, &fds)) lcm_handle(server_lcm);
      if (FD_ISSET(b, &fds)) lcm_handle(request_lcm);
    }
    clock_gettime(CLOCK_MONOTONIC, &now);
  } while ((now.tv_sec - t0.tv_sec) + (now.tv_nsec - t0.tv_nsec) * 1e-9 < seconds);
  return 0;
}
