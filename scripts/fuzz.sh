#!/usr/bin/env bash
# Fuzzes every decoder the server and the client run on received bytes, and
# URDF import, with libFuzzer (docs/fuzzing.md).
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET ...]     default 60 s, every target
# Targets: package reply_package robot_state config announce urdf hello hello_answer.
# Installs clang and libFuzzer's runtime when missing (Debian 12: clang +
# libclang-rt-14-dev) and the project's own packages, builds with clang, ASan
# and UBSan into build-fuzz/, writes seed corpora from valid messages, then
# runs each target for the given time. Corpora grow in build-fuzz/corpus/<target>
# from run to run. A crash leaves its input in build-fuzz/artifacts/<target>/;
# once fixed, copy it to tests/fuzz/regressions/<target>/ where the regular
# test suite replays it. Exit status 1 when any target crashed.
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_PER_TARGET=${1:-60}
shift || true
ALL_TARGETS=(package reply_package robot_state config announce urdf hello hello_answer)
TARGETS=("$@")
((${#TARGETS[@]})) || TARGETS=("${ALL_TARGETS[@]}")
BUILD_DIR=build-fuzz
JOBS=${ROBOTALK_JOBS:-$(nproc)}

# The project's packages (the PACKAGES list of setup.sh) plus the fuzzing ones.
eval "$(sed -n '/^PACKAGES=(/,/^)/p' scripts/setup.sh)"
PACKAGES+=(clang libclang-rt-14-dev)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "fuzz: installing missing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DROBOTALK_FUZZ=ON -DROBOTALK_SANITIZE=address >/dev/null
nice -n 19 cmake --build "$BUILD_DIR" -j"$JOBS" --target robotalk-fuzz-seeds \
  $(printf 'fuzz_%s ' "${TARGETS[@]}")

seeds=$BUILD_DIR/seeds
rm -rf "$seeds"
urdfs=(models/*.urdf)
[ -d ../shared/robots ] && urdfs+=(../shared/robots/*.urdf)
"$BUILD_DIR/tests/fuzz/robotalk-fuzz-seeds" "$seeds" "${urdfs[@]}"
# URDF words for the urdf target: libFuzzer splices them into its inputs.
cat >"$BUILD_DIR/urdf.dict" <<'DICT'
"<robot name=\"r\">"
"</robot>"
"<link name=\"a\"/>"
"<link name=\"b\">"
"</link>"
"<joint name=\"j\" type=\"revolute\">"
"type=\"continuous\""
"type=\"prismatic\""
"type=\"planar\""
"type=\"floating\""
"type=\"fixed\""
"</joint>"
"<parent link=\"a\"/>"
"<child link=\"b\"/>"
"<origin xyz=\"0 0 1\" rpy=\"0 0 1\"/>"
"<axis xyz=\"0 0 1\"/>"
"<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>"
"<mimic joint=\"j\" multiplier=\"2\" offset=\"1\"/>"
"<inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>"
"<robotalk>"
"</robotalk>"
"<control_frame name=\"f\" link=\"b\" xyz=\"0 0 0\" servo=\"setpoint\"/>"
"<servo joint=\"j\" types=\"setpoint speed force\"/>"
"<base type=\"differential\"/>"
"<!--"
"-->"
"<![CDATA["
"]]>"
"<?xml version=\"1.0\"?>"
"nan"
"inf"
"1e308"
DICT

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
crashed=()
summary=()
for t in "${TARGETS[@]}"; do
  corpus=$BUILD_DIR/corpus/$t
  artifacts=$BUILD_DIR/artifacts/$t
  mkdir -p "$corpus" "$artifacts"
  extra=()
  [ "$t" = urdf ] && extra+=(-dict="$BUILD_DIR/urdf.dict")
  dirs=("$corpus")
  [ -d "$seeds/$t" ] && dirs+=("$seeds/$t")
  [ -d "tests/fuzz/regressions/$t" ] && dirs+=("tests/fuzz/regressions/$t")
  log=$BUILD_DIR/fuzz_$t.log
  echo "fuzz: $t for ${SECONDS_PER_TARGET} s (log: $log)"
  # -rss_limit_mb: an input that makes a decoder allocate gigabytes is a bug.
  # -timeout: one input taking over 10 s is a hang.
  status=0
  nice -n 19 "$BUILD_DIR/tests/fuzz/fuzz_$t" -max_total_time="$SECONDS_PER_TARGET" -rss_limit_mb=2048 \
    -timeout=10 -print_final_stats=1 -artifact_prefix="$artifacts/" "${extra[@]}" "${dirs[@]}" \
    >"$log" 2>&1 || status=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  size=$(find "$corpus" -type f | wc -l)
  line="$t: ${execs:-?} runs, ${rate:-?} exec/s, corpus $size inputs"
  if [ "$status" -ne 0 ]; then
    crashed+=("$t")
    line+=", CRASHED (exit $status): $(grep -m1 -E 'ERROR: |==ERROR|runtime error|terminate called|out-of-memory|deadly signal' "$log" || true)"
    line+=" -> $(ls -t "$artifacts" | head -1)"
  fi
  summary+=("$line")
done
printf 'fuzz: %s\n' "${summary[@]}"
if ((${#crashed[@]})); then
  echo "fuzz: crashes in: ${crashed[*]}; inputs in $BUILD_DIR/artifacts/<target>/" >&2
  exit 1
fi
