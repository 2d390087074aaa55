#!/usr/bin/env bash
# Installs the Debian 12 packages animrt needs to build, test and run.
# Skips apt entirely when everything is already there.
set -euo pipefail

packages=(
  build-essential cmake make pkg-config lld
  libserialport-dev libyaml-cpp-dev libeigen3-dev libcli11-dev libspdlog-dev libfmt-dev
  nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-serial rt-tests
  libsndfile1-dev libsamplerate0-dev libaubio-dev libasound2-dev libltc-dev espeak-ng praat sptk sox
  libmodbus-dev mbpoll python3-pymodbus python3-serial-asyncio
  libmujoco-dev libqhull-dev libopenmpi-dev openmpi-bin gnuplot-nox
  libgl-dev libopengl-dev  # MuJoCo's CMake package looks for OpenGL
  librecast-dev  # navigation-mesh crowds (controllers/herd)
  can-utils qemu-system-x86 busybox-static cpio  # HIL tier (tests/hil/run)
  clang libclang-rt-14-dev  # fuzz harnesses (tests/fuzz, make fuzz)
  zlib1g-dev  # gzip-compressed mesh sequences (controllers/seqnet)
  libzstd-dev  # MCAP recordings' chunks (animrt run --record)
  libirrlicht-doc openarena-data unzip  # real MD2/MD3 clips for tests/seqnet
  # The sequence network (controllers/learn/seqnet/torch); Debian's libtorch falls
  # back to the slow reference BLAS without OpenBLAS.
  libtorch-dev libopenblas0-openmp
  # The dashboard: its HTTP server (and the tests' client), the page's 3-D
  # view and charts served from Debian, and the headless-browser test.
  libcpp-httplib-dev libjs-three libjs-chart.js
  chromium chromium-driver python3-selenium
  # A figure's computer: the service's readiness and watchdog (sd_notify),
  # the Debian packages (make deb) and their checks (systemd-analyze, lintian),
  # the arm64 cross toolchain and emulator (make test-arm64; its arm64 -dev
  # libraries are extracted into a sysroot by packaging/arm64-sysroot, never
  # installed: libyaml-cpp-dev:arm64 would replace the host's libyaml-cpp-dev).
  libsystemd-dev systemd dpkg-dev lintian crossbuild-essential-arm64 qemu-user-static
  # The packages installed into a fresh Debian 12 root (make test-install:
  # mmdebstrap, fetching from Debian's archive; it also builds the arm64
  # sysroot of make test-arm64) and that root booted with
  # systemd (make test-boot: an ext4 image written by mkfs.ext4 -d, read
  # back by debugfs; depmod for the guest's modules). uidmap: mmdebstrap run
  # by a user (its unshare mode) needs newuidmap to build the sysroot.
  mmdebstrap uidmap e2fsprogs kmod
)
# npm for the MCAP test's reader (below): Debian's, unless a Node.js with npm
# is installed already (Debian's npm package conflicts with other Node builds).
command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    sudo="sudo"
  fi
  echo "installing: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The MCAP test's independent reader (@mcap/core from the npm registry, at the
# versions its lock file pins): Node 20 and npm come with the machine.
reader="$(dirname "$0")/../tests/mcap_reader"
if [ ! -d "$reader/node_modules/@mcap/core" ] || [ "$reader/package-lock.json" -nt "$reader/node_modules" ]; then
  (cd "$reader" && npm ci --no-audit --no-fund --silent)
fi
