#!/usr/bin/env bash
# Each binary's options as its --help lists them are the options its page
# documents, and the other way round. A page marks where a binary's options
# are documented (a table or a synopsis) with two HTML comments:
#   <!-- options: robotalk-server -->  ...  <!-- /options -->
# and every "--word" token between them counts; from --help, every "--word"
# token it prints, but those the opening comment lists as another program's:
#   <!-- options: robotalk-keygen; not its own: --key --clients --> A binary whose --help does not exit 0 with some text is
# reported and skipped (each binary's own --help is tested in
# tests/tools/version_options_test.sh and its successors).
#   doc_options_test.sh SOURCE_DIR BINARY=PAGE...   (PAGE relative to SOURCE_DIR)
set -euo pipefail
source=$1
shift
. "$(dirname "$0")/../lib.sh"  # $tmp, check
options() { { grep -oE -- '--[a-z][a-z0-9-]*[a-z0-9]' || true; } | sort -u; }
for pair in "$@"; do
  bin=${pair%%=*} page=${pair#*=}
  name=$(basename "$bin")
  if ! timeout 20 "$bin" --help >"$tmp/help" 2>&1 || ! [ -s "$tmp/help" ]; then
    echo "SKIP: $name --help does not work yet; its page is not checked"
    continue
  fi
  options <"$tmp/help" >"$tmp/from_help"
  awk -v name="$name" 'index($0, "<!-- options: " name " -->") == 1 ||
                        index($0, "<!-- options: " name "; not its own: ") == 1 { on = 1; found = 1; print >"/dev/stderr"; next }
    on && $0 == "<!-- /options -->" { on = 0 } on { print }
    END { if (!found) exit 3 }' "$source/$page" >"$tmp/region" 2>"$tmp/marker" ||
    { echo "FAIL: $page has no <!-- options: $name --> region"; failures=$((failures + 1)); continue; }
  options <"$tmp/region" >"$tmp/from_page"
  # Options of other programs that --help names ("give the client --key FILE").
  sed -n 's/.*; not its own: \(.*\) -->.*/\1/p' "$tmp/marker" | tr ' ' '\n' | options >"$tmp/not_own"
  stale=$(comm -13 "$tmp/from_help" "$tmp/not_own" | tr '\n' ' ')
  check "$name: what $page calls not its own is in --help (not there: $stale)" test -z "$stale"
  comm -23 "$tmp/from_help" "$tmp/not_own" >"$tmp/own" && mv "$tmp/own" "$tmp/from_help"
  missing=$(comm -23 "$tmp/from_help" "$tmp/from_page" | tr '\n' ' ')
  # (--help may go unlisted in its own text.)
  extra=$(comm -13 "$tmp/from_help" "$tmp/from_page" | { grep -vx -- --help || true; } | tr '\n' ' ')
  check "$name: every option of --help is in $page (missing: $missing)" test -z "$missing"
  check "$name: every option in $page is in --help (not in --help: $extra)" test -z "$extra"
done
echo "$pass checks passed, $failures failed"
[ "$failures" -eq 0 ]
