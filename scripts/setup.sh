#!/usr/bin/env bash
# Installs the Debian 12 packages RoboTalk needs (only those missing) and
# configures + builds the project in ./build. Used by demo.sh and test.sh.
# Environment: ROBOTALK_BUILD_DIR (default build), ROBOTALK_BUILD_TARGETS.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake pkg-config clang-format
  liblcm-dev liblcm-bin liblcm-java liblcm-lua libglib2.0-dev
  libeigen3-dev libode-dev liburdfdom-dev libtinyxml-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  default-jdk-headless lua5.2
  iproute2 util-linux python3 python3-matplotlib
  libboost-dev nlohmann-json3-dev chromium chromium-driver
  libjchart2d-java xvfb x11-apps  # robotalk-spy (lcm-spy charts); its test: a virtual X server and xwd
  libsodium-dev
  lua-posix  # examples/lua_client: a sub-second monotonic clock (Lua 5.2 has none)
  cyclonedds-dev cyclonedds-tools  # robotalk-ros2: Cyclone DDS and its idlc
)
# robotalk-web's page modules come from the npm registry: Node.js and npm from
# Debian unless a node with npm is already installed (e.g. NodeSource's).
command -v npm >/dev/null || PACKAGES+=(nodejs npm)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "robotalk: installing missing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# three and urdf-loader for robotalk-web's page (tools/web/package.json,
# versions pinned by its package-lock.json), served from tools/web/node_modules.
if [ ! -f tools/web/node_modules/.package-lock.json ] ||
   [ tools/web/package-lock.json -nt tools/web/node_modules/.package-lock.json ]; then
  echo "robotalk: installing the web page's npm modules (tools/web)"
  (cd tools/web && npm ci --no-audit --no-fund --loglevel=error)
fi

BUILD_DIR=${ROBOTALK_BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROBOTALK_WERROR=ON >/dev/null
# ROBOTALK_BUILD_TARGETS (space-separated): build only these (scripts/bench.sh);
# default: everything.
targets=()
[ -n "${ROBOTALK_BUILD_TARGETS:-}" ] && read -r -a targets <<<"$ROBOTALK_BUILD_TARGETS"
cmake --build "$BUILD_DIR" -j"$(nproc)" ${targets[@]+--target "${targets[@]}"}
