#!/usr/bin/env bash
# Each binary's options as its --help lists them are the options its page
# documents, and the other way round. A page marks where a binary's options
# are documented (a table or a synopsis) with two HTML comments:
#   <!-- options: robotalk-server -->  ...  <!-- /options -->
# and every "--word" token between them counts; from --help, every "--word"
# token it prints. A binary whose --help does not exit 0 with some text is
# reported and skipped (each binary's own --help is tested in
# tests/tools/version_options_test.sh and its successors).
#   doc_options_test.sh SOURCE_DIR BINARY=PAGE...   (PAGE relative to SOURCE_DIR)
set -euo pipefail
source=$1
shift
. "$(dirname "$0")/../lib.sh"  # $tmp, check
options() { grep -oE -- '--[a-z][a-z0-9-]*[a-z0-9]' | sort -u; }
for pair in "$@"; do
  bin=${pair%%=*} page=${pair#*=}
  name=$(basename "$bin")
  if ! timeout 20 "$bin" --help >"$tmp/help" 2>&1 || ! [ -s "$tmp/help" ]; then
    echo "SKIP: $name --help does not work yet; its page is not checked"
    continue
  fi
  options <"$tmp/help" >"$tmp/from_help"
  awk -v name="$name" '$0 == "<!-- options: " name " -->" { on = 1; found = 1; next }
    on && $0 == "<!-- /options -->" { on = 0 } on { print }
    END { if (!found) exit 3 }' "$source/$page" >"$tmp/region" ||
    { echo "FAIL: $page has no <!-- options: $name --> region"; failures=$((failures + 1)); continue; }
  options <"$tmp/region" >"$tmp/from_page"
  missing=$(comm -23 "$tmp/from_help" "$tmp/from_page" | tr '\n' ' ')
  extra=$(comm -13 "$tmp/from_help" "$tmp/from_page" | tr '\n' ' ')
  check "$name: every option of --help is in $page (missing: $missing)" test -z "$missing"
  check "$name: every option in $page is in --help (not in --help: $extra)" test -z "$extra"
done
echo "$pass checks passed, $failures failed"
[ "$failures" -eq 0 ]
