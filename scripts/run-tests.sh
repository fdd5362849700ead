#!/usr/bin/env bash
# Installs the dependencies, builds everything and runs all tests with CTest.
# Tests on the real patient data in ../shared/data skip themselves when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
