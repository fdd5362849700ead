#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Installs the dependencies, builds everything and runs all tests with CTest.
# Tests on the real patient data in ../shared/data skip themselves when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
# The Python package as users install it: `pip install .` into a fresh venv
# (with itk for the itk tests and example), its tests against the installed
# package (they use build/bin/morea to write the phantom), then both examples.
venv="$PWD/build/pip-venv"
rm -rf "$venv"
/usr/bin/python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check ".[itk,test]"
(cd build && MOREA_BIN="$PWD/bin/morea" MOREA_REQUIRE_BROWSER=1 "$venv/bin/python" -m pytest -q -p no:cacheprovider \
  -W ignore::DeprecationWarning ../wrapping/python/tests)
for example in register_sitk register_itk; do
  "$venv/bin/python" "examples/$example.py" --generations 3 --output "build/examples/$example"
  test -s "build/examples/$example/registration.png"
done
# AddressSanitizer and UndefinedBehaviorSanitizer over the core and mesh
# tests and a small registration, in build-asan.
./scripts/run-sanitizers.sh
