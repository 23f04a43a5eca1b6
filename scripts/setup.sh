#!/usr/bin/env bash
# Installs every Debian package op2gs needs and builds it (Release).
# Idempotent and non-interactive: safe to run again; only missing packages are
# installed and the build is incremental.
#
# Usage: scripts/setup.sh [--no-build] [--stages-only] [--portable] [--build-dir DIR] [--tests]
#   --tests        also installs what only the tests need (headless Chromium and
#                  python3 for the report and viewer tests, clang for fuzzing, Slurm)
#   --stages-only  builds only the stage executables (what the pipeline runs),
#                  not the tests and benchmarks (the demo: a quarter less to compile)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$root/build"
do_build=1
targets=()
with_tests=0
portable=OFF
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) do_build=0 ;;
    --stages-only) targets=(--target op2gs_stages) ;;
    --portable) portable=ON ;;
    --build-dir) build_dir="$2"; shift ;;
    --tests) with_tests=1 ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done

packages=(
  build-essential cmake ninja-build pkg-config git
  libopencv-dev libopenimageio-dev openimageio-tools libpng-dev zlib1g-dev libtbb-dev libeigen3-dev
  libceres-dev libgtest-dev libgmock-dev libbenchmark-dev nlohmann-json3-dev
  libcli11-dev libfmt-dev libspdlog-dev libnanoflann-dev libsqlite3-dev libicu-dev colmap clang-format
)

# The tests also drive headless Chromium (the report and its 3D viewer,
# served by python3), build the fuzz harnesses with clang and its sanitizer
# runtimes (libclang-rt-14-dev, only recommended by clang) and bring up a
# one-node Slurm cluster (whose free ports `ss`, of iproute2, finds: a
# minimal Debian has no iproute2).
if [ "$with_tests" -eq 1 ]; then
  packages+=(chromium python3 clang libclang-rt-14-dev slurm-wlm munge iproute2)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -q
  $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all Debian packages present"
fi

if [ "$do_build" -eq 1 ]; then
  cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DOP2GS_PORTABLE="$portable"
  cmake --build "$build_dir" --parallel "$(nproc)" "${targets[@]}"
fi
