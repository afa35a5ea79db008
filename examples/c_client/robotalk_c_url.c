/* URL helpers of the C client: see robotalk_c_url.h. */
#include "robotalk_c_url.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* url without RoboTalk's own option traffic=single|split (LCM does not know
 * it; the layout is taken from ANNOUNCE anyway). */
void rtc_lcm_url_of(const char* url, char* out, size_t len) {
  const char* q = strchr(url, '?');
  if (!q) {
    snprintf(out, len, "%s", url);
    return;
  }
  snprintf(out, len, "%.*s", (int)(q - url), url);
  char sep = '?';
  for (const char* opt = q + 1; *opt;) {
    const char* end = strchr(opt, '&');
    size_t n = end ? (size_t)(end - opt) : strlen(opt);
    if (n > 0 && strncmp(opt, "traffic=", 8) != 0) {
      size_t used = strlen(out);
      snprintf(out + used, len - used, "%c%.*s", sep, (int)n, opt);
      sep = '&';
    }
    opt += n + (end ? 1 : 0);
  }
}

/* "udpm://G:P?opts" -> "udpm://G:(P+delta)?opts" (no port: LCM's 7667). 0, or
 * -1 when url is not udpm. */
int rtc_shifted_url(const char* url, int delta, char* out, size_t len) {
  const char* scheme = "udpm://";
  if (strncmp(url, scheme, strlen(scheme)) != 0) return -1;
  const char* host = url + strlen(scheme);
  const char* colon = strchr(host, ':');
  const char* query = strchr(host, '?');
  long port = 7667;
  const char* rest = query ? query : host + strlen(host);
  if (colon && (!query || colon < query)) {
    char* end = NULL;
    port = strtol(colon + 1, &end, 10);
    if (end == colon + 1 || port <= 0) return -1;
    rest = end;
  } else {
    colon = rest;
  }
  if (port + delta > 65535) return -1;
  snprintf(out, len, "%.*s:%ld%s", (int)(colon - url), url, port + delta, rest);
  return 0;
}
