/* URL helpers of the C client (private to examples/c_client). Pure string
 * functions; thread-safe. */
#ifndef ROBOTALK_C_URL_H
#define ROBOTALK_C_URL_H

#include <stddef.h>

/* Writes url without RoboTalk's own option traffic=single|split (LCM does not
 * know it; the client takes the layout from ANNOUNCE). */
void rtc_lcm_url_of(const char* url, char* out, size_t len);

/* Writes "udpm://G:(P+delta)?opts" for url "udpm://G:P?opts" (no port: LCM's
 * 7667): a lane of the split traffic layout. 0, or -1 when url is not udpm or
 * the port would pass 65535. */
int rtc_shifted_url(const char* url, int delta, char* out, size_t len);

#endif
