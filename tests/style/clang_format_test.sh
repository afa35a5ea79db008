#!/usr/bin/env bash
# Every tracked C++ file is clean under the committed .clang-format.
# Usage: clang_format_test.sh SOURCE_DIR
set -euo pipefail
cd "$1"
if ! command -v clang-format >/dev/null; then
  echo "SKIP: clang-format is not installed"
  exit 0
fi
if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "SKIP: $1 is not a git checkout (the file list comes from git ls-files)"
  exit 0
fi
files=()
while IFS= read -r f; do
  [ -f "$f" ] || continue
  files+=("$f")
done < <(git ls-files '*.cpp' '*.h' '*.hpp' '*.cc' '*.c')
# Many files to a clang-format, on every core (one process per file spent most
# of its time starting clang-format). When any is unclean, the files its
# messages name (all of them, if it names none) are checked again one by one:
# the verdict is each file's own, as before.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
candidates=()
if ((${#files[@]})) && ! printf '%s\0' "${files[@]}" |
  xargs -0 -n 64 -P "$(nproc)" clang-format --dry-run -Werror >/dev/null 2>"$log"; then
  while IFS= read -r f; do
    [ -f "$f" ] && candidates+=("$f")
  done < <(sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: .*/\1/p' "$log" | sort -u)
  ((${#candidates[@]})) || candidates=("${files[@]}")
fi
unclean=()
for f in ${candidates[@]+"${candidates[@]}"}; do
  clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || unclean+=("$f")
done
if ((${#unclean[@]})); then
  echo "not clean under .clang-format (run: clang-format -i FILE):"
  printf '  %s\n' "${unclean[@]}"
  exit 1
fi
echo "all $(git ls-files '*.cpp' '*.h' '*.hpp' '*.cc' '*.c' | wc -l) C++ files are clean under .clang-format"
