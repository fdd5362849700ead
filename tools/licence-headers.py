#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Every source file of the project begins with its copyright and licence lines.

  tools/licence-headers.py --check [ROOT]   lists the files without them; exit 1 if any
  tools/licence-headers.py --write [ROOT]   adds them where they are missing

Source files: those git tracks or would track (not ignored) with a code or
build extension. The two lines go first, after a shebang (scripts) or a
doctype (HTML), in the file's own comment syntax.
"""
import pathlib
import subprocess
import sys

COPYRIGHT = "Copyright 2026 The MultiObjectiveRegistration authors"
SPDX = "SPDX-License-Identifier: Apache-2.0"

LINE = {".h": "//", ".hxx": "//", ".cxx": "//", ".cu": "//", ".cuh": "//", ".c": "//", ".js": "//",
        ".py": "#", ".sh": "#", ".cmake": "#", ".toml": "#", ".wrap": "#", ".in": "#", ".supp": "#"}
BLOCK = {".css": ("/* ", " */"), ".html": ("<!-- ", " -->")}


def syntax(path):
    if path.name == "CMakeLists.txt":
        return "#", ""
    if path.suffix in LINE:
        return LINE[path.suffix] + " ", ""
    return BLOCK.get(path.suffix)


def source_files(root):
    listed = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"], cwd=root,
                            capture_output=True, text=True, check=True).stdout.split("\n")
    for name in listed:
        path = root / name
        if name and path.is_file() and syntax(path) and not name.startswith("bench/results/"):
            yield path


def header(path):
    start, end = syntax(path)
    return [f"{start}{COPYRIGHT}{end}".rstrip() + "\n", f"{start}{SPDX}{end}".rstrip() + "\n"]


def has_header(lines):
    return any(COPYRIGHT in line for line in lines[:4]) and any(SPDX in line for line in lines[:5])


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else "--check"
    root = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else pathlib.Path(__file__).resolve().parent.parent)
    missing = []
    for path in source_files(root):
        lines = path.read_text(encoding="utf-8").splitlines(keepends=True)
        if has_header(lines):
            continue
        missing.append(path.relative_to(root))
        if mode == "--write":
            keep = 1 if lines and (lines[0].startswith("#!") or lines[0].lower().startswith("<!doctype")) else 0
            path.write_text("".join(lines[:keep] + header(path) + lines[keep:]), encoding="utf-8")
    if mode == "--check" and missing:
        print("source files without the licence header (tools/licence-headers.py --write adds it):")
        for path in missing:
            print(f"  {path}")
        return 1
    if mode == "--write":
        print(f"headers added to {len(missing)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
