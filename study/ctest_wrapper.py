# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Runs the study's pytest tests or its quick study under CTest; exits 77
(CTest: skipped) when a package or elastix is missing, so a build without the
study's dependencies still passes its tests."""
import importlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

REQUIRED = ["numpy", "scipy", "matplotlib", "SimpleITK", "ants", "pymia", "pytest"]


def main() -> int:
    missing = []
    for name in REQUIRED:
        try:
            importlib.import_module(name)
        except Exception:
            missing.append(name)
    if not shutil.which("elastix") or not shutil.which("transformix"):
        missing.append("elastix (Debian package)")
    if missing:
        print("study test skipped, missing: " + ", ".join(missing)
              + " (scripts/install-deps.sh installs them)")
        return 77
    root = Path(__file__).resolve().parent.parent
    env = dict(os.environ, PYTHONPATH=str(root) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    kind, args = sys.argv[1], sys.argv[2:]
    cmd = [sys.executable, "-m", "pytest"] + args if kind == "pytest" else \
          [sys.executable, "-m", "study"] + args
    return subprocess.call(cmd, env=env, cwd=os.getcwd())


if __name__ == "__main__":
    sys.exit(main())
