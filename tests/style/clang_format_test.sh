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
unclean=()
while IFS= read -r f; do
  [ -f "$f" ] || continue
  clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || unclean+=("$f")
done < <(git ls-files '*.cpp' '*.h' '*.hpp' '*.cc' '*.c')
if ((${#unclean[@]})); then
  echo "not clean under .clang-format (run: clang-format -i FILE):"
  printf '  %s\n' "${unclean[@]}"
  exit 1
fi
echo "all $(git ls-files '*.cpp' '*.h' '*.hpp' '*.cc' '*.c' | wc -l) C++ files are clean under .clang-format"
