# Sourced by the keyed example tests, after lib.sh: a keyed robotalk-server
# (kinematic Pioneer) with keys in $tmp: the server's ($tmp/server), alice's
# ($tmp/alice, listed with every right) and any other names given (made, not
# listed). Its log is $tmp/server.log; lib.sh stops it at exit.
#   start_keyed_server SERVER KEYGEN MODELS_DIR URL DURATION_S [OTHER_KEY...]
start_keyed_server() {
  local server_bin=$1 keygen=$2 models=$3 url=$4 duration=$5 k
  shift 5
  for k in server alice "$@"; do "$keygen" --out "$tmp/$k" >/dev/null || exit 1; done
  echo "$(cut -d' ' -f1 "$tmp/alice.pub") alice *=all" >"$tmp/clients"
  chmod 600 "$tmp/clients"
  start_pioneer "$tmp/server.log" --url "$url" --duration "$duration" \
    --key "$tmp/server" --clients "$tmp/clients"
}
