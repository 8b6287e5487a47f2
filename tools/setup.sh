#!/usr/bin/env bash
# Install the Debian 12 packages Granary needs (when missing) and build it into build/.
# Usage: tools/setup.sh [extra cmake arguments]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake g++ make libeigen3-dev libopenmpi-dev openmpi-bin libvtk9-dev catch2
          python3-numpy python3-scipy python3-matplotlib clang libclang-rt-14-dev)
# LIGGGHTS is the reference the agreement tests and benchmarks compare against.
optional=(liggghts)
missing=()
for p in "${packages[@]}" "${optional[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "Installing: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y "${packages[@]}"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y "${optional[@]}" ||
    echo "LIGGGHTS could not be installed; agreement tests use the stored LIGGGHTS output"
fi

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j "$jobs"
