#!/usr/bin/env bash
# Packs programs built here, the shared libraries they need that a bare GPU
# machine lacks (ITK, VTK, HDF5, toml++, ...), and data files into one
# archive, device-carry/bundle.tar.xz, for a run on a remote GPU machine
# (see bench/README.md). On that machine:
#   mkdir -p /tmp/b && tar xJf device-carry/bundle.tar.xz -C /tmp/b
#   LD_LIBRARY_PATH=/tmp/b/lib /tmp/b/bin/PROGRAM ...
# Usage: scripts/device-bundle.sh [--data FILE_OR_DIR]... [--lib FILE]... PROGRAM...
# (--lib: a library to carry as it is, e.g. bench/tools' profiler.)
set -euo pipefail
cd "$(dirname "$0")/.."
data=()
libs=()
programs=()
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data+=("$2"); shift 2 ;;
    --lib) libs+=("$2"); shift 2 ;;
    *) programs+=("$1"); shift ;;
  esac
done
[ ${#programs[@]} -gt 0 ] || { echo "usage: $0 [--data PATH]... [--lib FILE]... PROGRAM..." >&2; exit 2; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib" "$stage/data"
for p in "${programs[@]}"; do
  cp "$p" "$stage/bin/"
  strip --strip-unneeded "$stage/bin/$(basename "$p")"
  # The C and C++ runtimes of the GPU machine are newer and compatible; the
  # rest comes along.
  ldd "$p" | awk '/=> \// {print $3}' | grep -v -E '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s|ld-linux[^/]*)\.so' |
    while read -r lib; do
      [ -e "$stage/lib/$(basename "$lib")" ] || cp -L "$lib" "$stage/lib/"
    done
done
strip --strip-unneeded "$stage"/lib/*.so* 2>/dev/null || true
for l in "${libs[@]}"; do cp "$l" "$stage/lib/"; done
for d in "${data[@]}"; do cp -r "$d" "$stage/data/"; done
mkdir -p device-carry
tar cJf device-carry/bundle.tar.xz -C "$stage" .
du -h device-carry/bundle.tar.xz
