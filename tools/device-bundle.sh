#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Packs programs built here, the shared libraries they need that a bare GPU
# machine lacks (ITK, VTK, HDF5, toml++, ...), and data files into one
# archive, device-carry/bundle.tar.xz, for a run on a remote GPU machine
# (see bench/README.md). On that machine:
#   mkdir -p /tmp/b && tar xJf device-carry/bundle.tar.xz -C /tmp/b
#   LD_LIBRARY_PATH=/tmp/b/lib /tmp/b/bin/PROGRAM ...
# Usage: tools/device-bundle.sh [--data FILE_OR_DIR]... [--lib FILE]... [--python PACKAGE_DIR]
#          [--python-site SITE_PACKAGES] [--python-dist NAME]... PROGRAM...
# (--lib: a library to carry as it is, e.g. bench/tools' profiler.)
# --python: this machine's Python (the interpreter, its standard library and
# numpy from build/study-venv) and the package folder given (build/python/morea),
# for a GPU machine whose Python is another version than the extension's:
#   PYTHONHOME=/tmp/b PYTHONPATH=/tmp/b/site LD_LIBRARY_PATH=/tmp/b/lib /tmp/b/bin/python3 SCRIPT
# --python-dist: with --python, a distribution installed in SITE_PACKAGES (a
# venv of this machine's Python, e.g. one with `pip install dask distributed`)
# and every distribution it requires, copied into the bundle's site folder
# (e.g. --python-dist distributed for morea.cohort's batches); those whose
# modules the bundle holds already (numpy) are left as they are.
set -euo pipefail
cd "$(dirname "$0")/.."
data=()
libs=()
programs=()
python_package=""
python_site=""
python_dists=()
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data+=("$2"); shift 2 ;;
    --lib) libs+=("$2"); shift 2 ;;
    --python) python_package="$2"; shift 2 ;;
    --python-site) python_site="$2"; shift 2 ;;
    --python-dist) python_dists+=("$2"); shift 2 ;;
    *) programs+=("$1"); shift ;;
  esac
done
[ ${#programs[@]} -gt 0 ] || [ -n "$python_package" ] || { echo "usage: $0 [--data PATH]... [--lib FILE]... [--python DIR [--python-site DIR] [--python-dist NAME]...] PROGRAM..." >&2; exit 2; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib" "$stage/data"
# The shared libraries `$1` needs that a bare GPU machine lacks: the C and
# C++ runtimes there are newer and compatible; the rest comes along.
carry_libraries() {
  ldd "$1" | awk '/=> \// {print $3}' | grep -v -E '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s|ld-linux[^/]*)\.so' |
    while read -r lib; do
      [ -e "$stage/lib/$(basename "$lib")" ] || cp -L "$lib" "$stage/lib/"
    done || true # none to carry
}
for p in "${programs[@]}"; do
  cp "$p" "$stage/bin/"
  strip --strip-unneeded "$stage/bin/$(basename "$p")"
  carry_libraries "$p"
done
if [ -n "$python_package" ]; then
  version=$(build/study-venv/bin/python -c 'import sys; print("%d.%d" % sys.version_info[:2])')
  cp "$(readlink -f build/study-venv/bin/python)" "$stage/bin/python3"
  mkdir -p "$stage/lib/python$version" "$stage/site"
  tar cf - -C "/usr/lib/python$version" --exclude=test --exclude=idlelib --exclude=tkinter --exclude=ensurepip \
    --exclude=lib2to3 --exclude=__pycache__ --exclude='config-*' . | tar xf - -C "$stage/lib/python$version"
  for m in "$stage/lib/python$version"/lib-dynload/*.so; do carry_libraries "$m"; done
  site=build/study-venv/lib/python$version/site-packages
  cp -r "$site/numpy" "$site/numpy.libs" "$stage/site/"
  cp -r "$python_package" "$stage/site/"
  for m in "$stage/site/$(basename "$python_package")"/*.so; do
    strip --strip-unneeded "$m"
    carry_libraries "$m"
  done
  if [ ${#python_dists[@]} -gt 0 ]; then
    [ -n "$python_site" ] || { echo "--python-dist needs --python-site SITE_PACKAGES" >&2; exit 2; }
    build/study-venv/bin/python - "$python_site" "$stage/site" "${python_dists[@]}" <<'EOF_PY'
# Copies the named distributions and what they require (markers evaluated for
# this Python) from a site-packages folder, with their dist-info.
import importlib.metadata as md
import os
import re
import shutil
import sys

site, target, names = sys.argv[1], sys.argv[2], sys.argv[3:]
try:
    from packaging.requirements import Requirement
except ImportError:
    from pip._vendor.packaging.requirements import Requirement
norm = lambda n: re.sub(r"[-_.]+", "-", n).lower()  # noqa: E731
found = {norm(d.metadata["Name"]): d for d in md.distributions(path=[site])}
seen, todo, copied = set(), [(n, set()) for n in names], []
while todo:
    name, extras = todo.pop()
    key = norm(name)
    if key in seen:
        continue
    if key not in found:
        sys.exit(f"device-bundle: {name} is not installed in {site}")
    seen.add(key)
    dist = found[key]
    files = [str(f) for f in dist.files or [] if not str(f).startswith("..") and "__pycache__" not in str(f)]
    tops = {f.split("/")[0] for f in files if not f.split("/")[0].endswith((".dist-info", ".data"))}
    if any(os.path.exists(os.path.join(target, t)) for t in tops):
        continue  # carried already (numpy)
    for f in files:
        os.makedirs(os.path.join(target, os.path.dirname(f)), exist_ok=True)
        shutil.copy2(os.path.join(site, f), os.path.join(target, f))
    copied.append(f"{dist.metadata['Name']} {dist.version}")
    for text in dist.requires or []:
        r = Requirement(text)
        if r.marker is None or any(r.marker.evaluate({"extra": e}) for e in (extras or {""})):
            todo.append((r.name, set(r.extras)))
print("python distributions:", ", ".join(sorted(copied)))
EOF_PY
  fi
  find "$stage/site" -name __pycache__ -prune -exec rm -rf {} +
fi
strip --strip-unneeded "$stage"/lib/*.so* 2>/dev/null || true
for l in "${libs[@]}"; do cp "$l" "$stage/lib/"; done
for d in "${data[@]}"; do cp -r "$d" "$stage/data/"; done
out=${MOREA_BUNDLE:-device-carry/bundle.tar.xz} # where the archive goes
mkdir -p "$(dirname "$out")"
tar cJf "$out" -C "$stage" .
du -h "$out"
