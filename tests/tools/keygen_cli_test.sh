#!/usr/bin/env bash
# robotalk-keygen from the outside: the pair's files and modes, the .pub line,
# refusal to overwrite, --fingerprint, --help/--version, bad options.
#   keygen_cli_test.sh PATH/TO/robotalk-keygen
set -u
keygen=$1
. "$(dirname "$0")/../lib.sh"  # $tmp, check

# A pair, whatever the umask.
(umask 000; "$keygen" --out "$tmp/alice" >"$tmp/out" 2>"$tmp/err")
check "keygen exits 0" test $? -eq 0
check "secret file has mode 600" test "$(stat -c %a "$tmp/alice")" = 600
check "public file has mode 644" test "$(stat -c %a "$tmp/alice.pub")" = 644
check "pub line is 'ed25519:<64 hex> alice'" grep -qE '^ed25519:[0-9a-f]{64} alice$' "$tmp/alice.pub"
check "secret file holds the v1 seed line" grep -qE '^robotalk-secret-key-v1 [0-9a-f]{64}$' "$tmp/alice"
check "output prints the fingerprint" grep -qE '^fingerprint +rt:[0-9a-f]{4}(:[0-9a-f]{4}){3}$' "$tmp/out"
check "nothing on stderr" test ! -s "$tmp/err"

# --fingerprint of the secret and of the public file agree with what keygen printed.
fp=$(sed -n 's/^fingerprint *//p' "$tmp/out")
check "fingerprint of .pub" test "$("$keygen" --fingerprint "$tmp/alice.pub" | cut -d' ' -f1)" = "$fp"
check "fingerprint of secret" test "$("$keygen" --fingerprint "$tmp/alice" | cut -d' ' -f1)" = "$fp"

# --name.
"$keygen" --out "$tmp/k2" --name robot-op@lab >/dev/null 2>&1
check "--name is written" grep -qE ' robot-op@lab$' "$tmp/k2.pub"

# Never overwrites: same file, exit 1, one line naming it, old key intact.
before=$(cat "$tmp/alice")
"$keygen" --out "$tmp/alice" >"$tmp/out" 2>"$tmp/err"
check "overwrite exits 1" test $? -eq 1
check "overwrite error names the file" grep -q "$tmp/alice" "$tmp/err"
check "overwrite error is one line" test "$(wc -l <"$tmp/err")" -eq 1
check "old secret key intact" test "$(cat "$tmp/alice")" = "$before"

# A too-open secret key is refused by --fingerprint, naming the mode.
chmod 644 "$tmp/alice"
"$keygen" --fingerprint "$tmp/alice" >/dev/null 2>"$tmp/err"
check "open secret key exits 1" test $? -eq 1
check "open secret key error names mode 0644" grep -q "mode 0644" "$tmp/err"

# Bad arguments, --help, --version.
"$keygen" >/dev/null 2>"$tmp/err"
check "no --out exits 2 (a usage error, as every tool)" test $? -eq 2
check "no --out says so" grep -q -- "--out FILE is required" "$tmp/err"
"$keygen" --frobnicate >/dev/null 2>"$tmp/err"
check "unknown option exits 2 (a usage error, as every tool)" test $? -eq 2
check "unknown option named as every tool names it" grep -q -- "unknown option '--frobnicate' (see --help)" "$tmp/err"
# A known option without its value is named so (before: "unknown or incomplete option '--out'").
"$keygen" --out >/dev/null 2>"$tmp/err"
check "a trailing --out exits 2" test $? -eq 2
check "a trailing --out needs a value: $(cat "$tmp/err")" grep -q -- "^robotalk-keygen: --out needs a value" "$tmp/err"
"$keygen" --out "$tmp/bad" --name "two words" >/dev/null 2>&1
check "bad name exits 1" test $? -eq 1
check "bad name writes nothing" test ! -e "$tmp/bad"
"$keygen" --help >"$tmp/out"
check "--help exits 0 with usage" grep -q "^usage: robotalk-keygen" "$tmp/out"
"$keygen" --version >"$tmp/out"
check "--version prints a version" grep -qE '^robotalk-keygen [0-9]+\.[0-9]+\.[0-9]+$' "$tmp/out"

echo "keygen_cli: $pass passed, $failures failed"
test "$failures" -eq 0
