#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
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
  elastix                  # comparison study (study/): elastix 5.0.1 and transformix
  python3-venv python3-pip # comparison study and the Python package's tests: packages in a venv
  python3-dev pybind11-dev # the Python package (morea): its extension module
  chromium chromium-driver # the front navigator's test drives the page in a headless browser
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

# Comparison study (study/): Python packages from PyPI in a venv under the build
# folder (MOREA_STUDY_VENV overrides); study/CMakeLists.txt finds it there.
# A failed download leaves the study's CTest tests skipping, not failing.
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
VENV="${MOREA_STUDY_VENV:-$ROOT/build/study-venv}"
STUDY_PACKAGES=(numpy scipy matplotlib SimpleITK antspyx pymia pytest)
if [ ! -x "$VENV/bin/python" ]; then
  mkdir -p "$(dirname "$VENV")"
  /usr/bin/python3 -m venv "$VENV" || echo "warning: could not create $VENV" >&2
fi
if [ -x "$VENV/bin/python" ] && ! "$VENV/bin/python" -c "import numpy, scipy, matplotlib, SimpleITK, ants, pymia, pytest" 2>/dev/null; then
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check "${STUDY_PACKAGES[@]}" \
    || echo "warning: study packages not installed; the study's tests will be skipped" >&2
fi
echo "dependencies: ok"
