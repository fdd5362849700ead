#!/usr/bin/env bash
# Packs programs built here, the shared libraries they need that a bare GPU
# machine lacks (ITK, VTK, HDF5, toml++, ...), and data files into one
# archive, device-carry/bundle.tar.xz, for a run on a remote GPU machine
# (see bench/README.md). On that machine:
#   mkdir -p /tmp/b && tar xJf device-carry/bundle.tar.xz -C /tmp/b
#   LD_LIBRARY_PATH=/tmp/b/lib /tmp/b/bin/PROGRAM ...
# Usage: tools/device-bundle.sh [--data FILE_OR_DIR]... [--lib FILE]... [--python PACKAGE_DIR] PROGRAM...
# (--lib: a library to carry as it is, e.g. bench/tools' profiler.)
# --python: this machine's Python (the interpreter, its standard library and
# numpy from build/study-venv) and the package folder given (build/python/morea),
# for a GPU machine whose Python is another version than the extension's:
#   PYTHONHOME=/tmp/b PYTHONPATH=/tmp/b/site LD_LIBRARY_PATH=/tmp/b/lib /tmp/b/bin/python3 SCRIPT
set -euo pipefail
cd "$(dirname "$0")/.."
data=()
libs=()
programs=()
python_package=""
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data+=("$2"); shift 2 ;;
    --lib) libs+=("$2"); shift 2 ;;
    --python) python_package="$2"; shift 2 ;;
    *) programs+=("$1"); shift ;;
  esac
done
[ ${#programs[@]} -gt 0 ] || [ -n "$python_package" ] || { echo "usage: $0 [--data PATH]... [--lib FILE]... PROGRAM..." >&2; exit 2; }
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
  find "$stage/site" -name __pycache__ -prune -exec rm -rf {} +
fi
strip --strip-unneeded "$stage"/lib/*.so* 2>/dev/null || true
for l in "${libs[@]}"; do cp "$l" "$stage/lib/"; done
for d in "${data[@]}"; do cp -r "$d" "$stage/data/"; done
out=${MOREA_BUNDLE:-device-carry/bundle.tar.xz} # where the archive goes
mkdir -p "$(dirname "$out")"
tar cJf "$out" -C "$stage" .
du -h "$out"
