#!/usr/bin/env bash
# Installs the Debian 12 packages this module builds and tests against.
# Safe to run repeatedly; needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake git pkg-config
  libinsighttoolkit5-dev   # ITK 5.2 (IO incl. GDCM/DICOM, registration v4, filters)
  libdcmtk-dev             # DICOM RT Structure Set import (dcmrt)
  libtet1.5-dev            # TetGen: constrained Delaunay tetrahedralisation of the mesh
  libvtk9-dev              # VTK: structure surfaces (marching cubes, decimation), .vtu export
  libtomlplusplus-dev      # TOML parameter files
  libcli11-dev             # command-line parsing
  nlohmann-json3-dev       # JSON outputs
  libgtest-dev libgmock-dev
  libpng-dev zlib1g-dev
  xz-utils                 # tests unpack the DICOM test archive
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
echo "dependencies: ok"
