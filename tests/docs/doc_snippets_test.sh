#!/usr/bin/env bash
# Every fenced code block of README.md and docs/*.md is checked as what its
# language says it is:
#   cpp    compiled and linked against the installed package, one target per
#          snippet (tests/docs/snippets); a complete program as it is, a
#          fragment inside a wrapper its marker describes
#   sh     bash -n; with the marker "run", run in a private network namespace
#          with the installed tools first on PATH and HOME in a temporary folder
#   cmake  every robotalk:: target it names is one the package exports
#   java   compiled by javac against the installed bindings (where javac is)
#   xml    well-formed (a fragment's "..." lines dropped)
#   python parsed (ast.parse: the syntax of Python 3)
#   text   not code: output, diagrams, synopses; left alone
# A fence with no language fails (write ```text when it is not code).
# A marker is an HTML comment on the line just before the fence:
#   <!-- snippet: body(robotalk::RobotClient& client) -->  statements, run as
#        the body of a function with those parameters; they see the #include
#        lines of the page's C++ snippets up to this one (as a reader does)
#   <!-- snippet: file -->      top-level declarations: compiled, not linked
#   <!-- snippet: program include=my_driver.h -->  force-includes a header of
#        tests/docs/support (what the page leaves to the reader)
#   <!-- snippet: run -->       (sh) runs it
#   <!-- snippet: fragment -->  (xml, java) a piece of a whole
#   doc_snippets_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(cd "$1" && pwd) source=$(cd "$2" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lib.sh"  # $tmp, check
# The lead's pages, not yet tagged: their untagged fences are taken as text.
untagged_ok=" docs/architecture.md "

cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log"
mkdir -p "$tmp/blocks" "$tmp/cpp" "$tmp/java"
n=0
for doc in README.md $(cd "$source" && ls docs/*.md); do
  awk -v doc="$doc" -v out="$tmp/blocks" -v first="$n" -f "$here/extract_snippets.awk" "$source/$doc"
  n=$(find "$tmp/blocks" -name '*.meta' | wc -l)
done

fail() { echo "FAIL: $1"; failures=$((failures + 1)); }
prelude='#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>'
declare -A page_includes=()
declare -A cpp_origin=()
skipped=""

for meta in "$tmp/blocks"/*.meta; do
  read -r doc line lang marker <"$meta"
  src=${meta%.meta}.src
  id=$(basename "$meta" .meta)
  where="$doc:$line"
  kind=${marker%% *}
  [[ $marker != body\(* ]] || kind="${marker%%)*})"
  include=""
  case " $marker " in *" include="*) include=$(sed 's/.* include=\([^ ]*\).*/\1/' <<<" $marker ") ;; esac
  case $lang in
    cpp)
      page_includes[$doc]+=$(grep '^#include' "$src" || true)$'\n'
      if [ "$kind" = "-" ]; then
        grep -q 'int main(' "$src" && kind=program ||
          { fail "$where: a C++ fragment without a marker (body(...), file or program)"; continue; }
      fi
      {
        [ -z "$include" ] || echo "#include \"$include\""
        case $kind in
          program)
            echo "#line $((line + 1)) \"$doc\""
            cat "$src"
            ;;
          file)
            echo "$prelude"
            echo "${page_includes[$doc]}"
            echo "#line $((line + 1)) \"$doc\""
            cat "$src"
            ;;
          body\(*)
            echo "$prelude"
            echo "${page_includes[$doc]}"
            echo "void Snippet(${kind#body(}"  # the marker's ")" closes the list
            echo "{"
            echo "#line $((line + 1)) \"$doc\""
            sed 's|^#include.*||' "$src"
            echo "}"
            echo "int main() {}  // Snippet is linked (external linkage), never run"
            ;;
          *)
            fail "$where: unknown C++ marker '$marker'"
            continue
            ;;
        esac
      } >"$tmp/cpp/$([ "$kind" = file ] && echo obj || echo prog)_$id.cpp"
      cpp_origin[$id]=$where
      ;;
    sh)
      check "$where: bash -n" bash -n "$src"
      if [ "$kind" = run ]; then
        mkdir -p "$tmp/run_$id/home"
        ln -s "$source/models" "$source/examples" "$tmp/run_$id/"
        # The snippet's own background jobs are stopped when it ends.
        rc=0
        (cd "$tmp/run_$id" && PATH="$tmp/prefix/bin:$PATH" HOME="$tmp/run_$id/home" \
          LCM_DEFAULT_URL="udpm://239.255.76.67:7743?ttl=0" ROBOTALK_KNOWN_SERVERS="" \
          timeout 120 "$source/scripts/netns_run.sh" bash -c \
          'trap "rc=\$?; j=\$(jobs -p); [ -z \"\$j\" ] || kill \$j 2>/dev/null; wait; exit \$rc" EXIT; set -e; . "$1"' \
          run "$src" \
          >"$tmp/run_$id.log" 2>&1) || rc=$?
        case $rc in
          0) pass=$((pass + 1)) ;;
          77) skipped+=" $where" ;;
          *) fail "$where: running it (exit $rc)"; cat "$tmp/run_$id.log" ;;
        esac
      fi
      ;;
    cmake)
      for t in $(grep -o 'robotalk::[a-z_]*' "$src" | sort -u); do
        check "$where: $t is an exported target" grep -q "add_library($t " "$tmp/prefix/lib/cmake/robotalk/robotalkTargets.cmake"
      done
      check "$where: finds the package" grep -q 'find_package(robotalk' "$src"
      ;;
    java)
      if ! command -v javac >/dev/null; then
        skipped+=" $where(no javac)"
        continue
      fi
      [ "$kind" = "-" ] && { fail "$where: a Java fragment without a marker"; continue; }
      mkdir -p "$tmp/java/$id"
      params=${kind#body(}
      { echo "import robotalk_msgs.*;"
        echo "class Snippet { static void run(${params} throws Exception {"
        cat "$src"
        echo "}}"; } >"$tmp/java/$id/Snippet.java"
      jars=$(find "$tmp/prefix" /usr/share/java -name 'robotalk_lcmtypes.jar' -o -name 'lcm.jar' | tr '\n' ':')
      check "$where: javac" javac -d "$tmp/java/$id" -cp "$jars" "$tmp/java/$id/Snippet.java"
      ;;
    xml)
      check "$where: well-formed XML" python3 -c 'import sys, xml.dom.minidom
xml.dom.minidom.parseString("".join(l for l in open(sys.argv[1]) if l.strip() != "..."))' "$src"
      ;;
    python)
      check "$where: Python syntax" python3 -c 'import ast, sys; ast.parse(open(sys.argv[1]).read())' "$src"
      ;;
    text) ;;
    untagged)
      case $untagged_ok in *" $doc "*) ;; *) fail "$where: a fence with no language (\`\`\`text if it is not code)" ;; esac
      ;;
    *) fail "$where: no check for language '$lang'" ;;
  esac
done

# The C++ snippets, one target each, so one failure names its snippet.
cmake -S "$here/snippets" -B "$tmp/cpp_build" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DSNIPPET_DIR="$tmp/cpp" \
  -DSUPPORT_DIR="$here/support" >"$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log"; exit 1; }
# All of them in one make on every core (not one make per snippet: each paid
# make's start-up, and the cores stood idle); a snippet whose program or object
# is missing afterwards (a failure, or one make left when it stopped) is built
# again on its own: its verdict and its log.
cmake --build "$tmp/cpp_build" -j"$(nproc)" >"$tmp/build_all.log" 2>&1 || true
built() {  # built TARGET: its program (prog_*) or its object (obj_*) is there
  case $1 in
    prog_*) test -x "$tmp/cpp_build/$1" ;;
    *) compgen -G "$tmp/cpp_build/CMakeFiles/$1.dir/$1.*.o" >/dev/null ;;
  esac
}
for f in "$tmp/cpp"/*.cpp; do
  target=$(basename "$f" .cpp)
  id=${target#*_}
  if built "$target" || cmake --build "$tmp/cpp_build" --target "$target" >"$tmp/build_$id.log" 2>&1; then
    pass=$((pass + 1))
  else
    fail "${cpp_origin[$id]}: does not compile"
    grep -m 8 -E "error|undefined reference" "$tmp/build_$id.log" || tail -20 "$tmp/build_$id.log"
  fi
done
[ -z "$skipped" ] || echo "SKIP (tools missing here):$skipped"
echo "$n blocks; $pass checks passed, $failures failed"
[ "$failures" -eq 0 ]
