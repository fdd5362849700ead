#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# run-pytest.sh PYTHON TESTS_DIR: pytest on the package, or exit 77 (skipped)
# when the interpreter lacks numpy, SimpleITK or pytest.
set -euo pipefail
python=$1
tests=$2
if ! "$python" -c "import numpy, SimpleITK, pytest" 2>/dev/null; then
  echo "python.pytest: $python lacks numpy, SimpleITK or pytest; skipped"
  exit 77
fi
exec "$python" -m pytest -q -p no:cacheprovider "$tests"
