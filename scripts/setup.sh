#!/usr/bin/env bash
# Installs impactlab's dependencies from Debian (only those missing) and builds
# it into ./build. Safe to run again.
# Usage: scripts/setup.sh [--cli | --bench | --no-build] [--tex]
#   (none)      build the command and the tests (and install snakemake, which the
#               archive workflow's test runs)
#   --bench     build everything: the command, the tests and the benchmarks (bench/)
#   --cli       build only the command (build/cli/impactlab) and its libraries
#   --no-build  install the dependencies only
#   --tex       also install Debian's TeX (texlive-latex-recommended, texlive-science),
#               with which a test compiles every LaTeX table of the report (without
#               it, that test is skipped); a few hundred MB, so only when asked
set -euo pipefail
cd "$(dirname "$0")/.."

tex=0
mode=""
for arg in "$@"; do
  case "$arg" in
    --tex) tex=1 ;;
    *) mode="$arg" ;;
  esac
done

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libceres-dev libopencv-dev libjpeg-dev libpng-dev libtiff-dev libhdf5-dev hdf5-tools
  libboost-dev libmetis-dev
  catch2 libcli11-dev libtomlplusplus-dev libfmt-dev nlohmann-json3-dev libxxhash-dev
  libjs-dygraphs chromium
)
[ "$tex" -eq 1 ] && packages+=(texlive-latex-recommended texlive-science)
# Snakemake runs the archive workflow (workflow/Snakefile, docs/campaigns.md); the
# command alone does not need it, the workflow's test and benchmark do.
[ "$mode" != --cli ] && packages+=(snakemake)

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

# The benchmarks are developers' programs (docs/benchmarks.md): left out of the
# test build, which they would lengthen by a fifth.
bench=OFF
case "$mode" in
  --no-build) exit 0 ;;
  --cli) target=(--target impactlab) ;;
  --bench) target=() bench=ON ;;
  "") target=() ;;
  *) echo "setup: unknown option $mode (expected --cli, --bench, --no-build or --tex)" >&2; exit 2 ;;
esac
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DIMPACTLAB_BUILD_BENCH=$bench >&2
cmake --build build -j2 "${target[@]}" >&2
