#!/usr/bin/env bash
# Installs impactlab's dependencies from Debian (only those missing) and builds
# it into ./build. Safe to run again.
# Usage: scripts/setup.sh [--cli | --no-build]
#   (none)      build everything: the command, the tests and the benchmarks
#   --cli       build only the command (build/cli/impactlab) and its libraries
#   --no-build  install the dependencies only
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libceres-dev libopencv-dev libjpeg-dev libhdf5-dev hdf5-tools libboost-dev
  catch2 libcli11-dev libtomlplusplus-dev libfmt-dev nlohmann-json3-dev libxxhash-dev
  libjs-dygraphs chromium
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

case "${1:-}" in
  --no-build) exit 0 ;;
  --cli) target=(--target impactlab) ;;
  "") target=() ;;
  *) echo "setup: unknown option $1 (expected --cli or --no-build)" >&2; exit 2 ;;
esac
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
cmake --build build -j2 "${target[@]}" >&2
