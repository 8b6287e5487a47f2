#!/usr/bin/env bash
# Install the Debian 12 packages Granary needs (only those missing) and build it
# into build/. Never removes a package: apt-get runs with --no-remove.
# Usage: tools/setup.sh [extra cmake arguments]
#
# VTK: Granary builds against the VTK 9 that ParaView ships (package
# paraview-dev), so that ParaView with its Python module (python3-paraview,
# pvbatch, used by the rendering test and tools/render.py) is installed beside
# it. On Debian 12 libvtk9-dev and python3-paraview conflict; where libvtk9-dev
# is already installed it is kept and used, and ParaView's Python is not
# installed (the rendering test then says it is skipped). CMake finds either
# VTK without flags.
#
# Run as root, through sudo (the build then belongs to the user who called
# sudo), or as a user who may run sudo (only apt-get is run through it).
set -euo pipefail
cd "$(dirname "$0")/.."

installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

packages=(cmake g++ make libeigen3-dev libopenmpi-dev openmpi-bin catch2
          python3-numpy python3-scipy python3-matplotlib clang libclang-rt-14-dev clang-format)
if installed libvtk9-dev; then
  echo "setup: libvtk9-dev is installed; building against it (ParaView's Python cannot be installed beside it)"
else
  # ParaView's VTK for the build; ParaView's Python and a virtual X server for
  # rendering pictures of the dumps without a display
  packages+=(paraview-dev python3-paraview xvfb xauth)
fi
# LIGGGHTS is the reference of the agreement tests and benchmarks. Without its
# recommends: they would pull python3-paraview, which would remove libvtk9-dev
# where that is the VTK in use (ParaView itself is installed above otherwise).
optional=(liggghts liggghts-doc)

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: not root and no sudo: run as root to install packages" >&2; exit 1; }
  SUDO=(sudo)
fi
apt_install() {
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-remove --no-install-recommends "$@"
}

missing=() missing_opt=()
for p in "${packages[@]}"; do installed "$p" || missing+=("$p"); done
for p in "${optional[@]}"; do installed "$p" || missing_opt+=("$p"); done
if [ ${#missing[@]} -gt 0 ] || [ ${#missing_opt[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]} ${missing_opt[*]}"
  "${SUDO[@]}" apt-get update
  if [ ${#missing[@]} -gt 0 ]; then
    apt_install "${missing[@]}"
  fi
  if [ ${#missing_opt[@]} -gt 0 ]; then
    apt_install "${missing_opt[@]}" ||
      echo "setup: LIGGGHTS could not be installed; the agreement tests skip or use stored LIGGGHTS output"
  fi
else
  echo "setup: all packages present"
fi

# Through sudo, build as the calling user so that build/ stays theirs.
source tools/caller.sh
AS_USER=()
if sudo_caller >/dev/null; then AS_USER=(sudo -u "$(sudo_caller)" -H); fi
jobs=$(nproc 2>/dev/null || echo 2)
"${AS_USER[@]}" cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@"
"${AS_USER[@]}" cmake --build build -j "$jobs"
