#!/usr/bin/env bash
# Installs the dependencies, builds, and runs the default job on the embedded
# phantom (output in ./demo-out).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)" --target morea
./build/bin/morea demo -o demo-out
