# Sourced by the web tests that need robotalk-web serving but not its page
# (web_fd_limit_test.sh, web_ws_cap_test.sh, web_http_cap_test.sh). REQUIRES: $tmp, a folder.
# start_bare_web WEB WWW PORT LCM_PORT [NOFILE]: starts WEB on PORT (LCM on
# udpm://239.255.76.67:LCM_PORT?ttl=0; `ulimit -n NOFILE` when given) in the
# background, its pid in $pid and its output in $tmp/web.log, ended and $tmp
# removed at exit; waits for its "open http" line, exits 1 without it.
start_bare_web() {
  local web=$1 www=$2 port=$3 lcm_port=$4 nofile=${5:-}
  mkdir -p "$tmp/node_modules/three" "$tmp/node_modules/urdf-loader"  # the page is not loaded: names suffice
  (if [ -n "$nofile" ]; then ulimit -n "$nofile"; fi
   exec "$web" --port "$port" --lcm-url "udpm://239.255.76.67:$lcm_port?ttl=0" --www "$www" \
     --node-modules "$tmp/node_modules") >"$tmp/web.log" 2>&1 &
  pid=$!
  trap 'kill $pid 2>/dev/null; wait $pid 2>/dev/null; rm -rf "$tmp"' EXIT
  for _ in $(seq 50); do grep -qs "open http" "$tmp/web.log" && break; sleep 0.1; done  # -s: not yet made
  grep -q "open http" "$tmp/web.log" || { echo "FAIL: robotalk-web did not start:"; cat "$tmp/web.log"; exit 1; }
}
