# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Landmark TRE per kind for the phantom suite (standard library only, so that
bench/run-study-morea.sh can use it on a GPU machine without the study's packages).

`morea phantom` writes phantom.json with one kind per landmark ("bone", "wall",
"organ", "soft"). `split` writes, per kind, the study problem's landmark files
(already in the preprocessed frame: the moving ones moved by the pre-alignment)
restricted to that kind, as elastix point files:
    DIR/landmarks/<kind>/{fixed,moving}_landmarks.txt
`morea evaluate --fixed-landmarks ... --moving-landmarks ...` scores each set;
`merge` puts each set's "landmarks" block into the run's scores.json under
"landmarks_by_kind" (evaluation.flatten turns it into tre_mean_mm:<kind> columns).

    python3 -m study.landmark_kinds merge OUT.json MAIN.json KIND=KIND.json ...
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

KINDS = ("bone", "wall", "organ", "soft")


def read_points(path: Path) -> tuple[str, list[str]]:
    """An elastix point file ("point" or "index", count, one point a line) ->
    (header word, point lines)."""
    lines = [ln.strip() for ln in Path(path).read_text().splitlines() if ln.strip()]
    if len(lines) < 2 or lines[0] not in ("point", "index"):
        raise ValueError(f"{path}: not an elastix point file")
    count = int(lines[1])
    points = lines[2:]
    if len(points) != count:
        raise ValueError(f"{path}: header says {count} points, found {len(points)}")
    return lines[0], points


def write_points(path: Path, header: str, points: list[str]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join([header, str(len(points))] + points) + "\n")


def split(kinds: list[str], problem: Path, out_dir: Path) -> dict[str, tuple[Path, Path]]:
    """Per kind present in `kinds` (one entry per landmark, in file order): the
    problem's fixed and moving landmark files restricted to that kind under
    out_dir/<kind>/. Returns {kind: (fixed file, moving file)}."""
    sides = {}
    for side in ("fixed", "moving"):
        header, points = read_points(problem / f"{side}_landmarks.txt")
        if len(points) != len(kinds):
            raise ValueError(f"{problem}/{side}_landmarks.txt has {len(points)} points, "
                             f"phantom.json names {len(kinds)} kinds")
        sides[side] = (header, points)
    result = {}
    for kind in sorted(set(kinds), key=lambda k: (KINDS.index(k) if k in KINDS else 99, k)):
        files = []
        for side in ("fixed", "moving"):
            header, points = sides[side]
            path = out_dir / kind / f"{side}_landmarks.txt"
            write_points(path, header, [p for p, k in zip(points, kinds) if k == kind])
            files.append(path)
        result[kind] = (files[0], files[1])
    return result


def sets(out_dir: Path) -> dict[str, tuple[Path, Path]]:
    """The landmark sets `split` wrote under out_dir (empty when none)."""
    result = {}
    if not out_dir.is_dir():
        return result
    for d in sorted(out_dir.iterdir(), key=lambda p: (KINDS.index(p.name) if p.name in KINDS
                                                      else 99, p.name)):
        f, m = d / "fixed_landmarks.txt", d / "moving_landmarks.txt"
        if f.exists() and m.exists():
            result[d.name] = (f, m)
    return result


def merge(main: dict, by_kind: dict[str, dict]) -> dict:
    """main scores.json + {kind: scores.json of that landmark set} -> main with
    "landmarks_by_kind": {kind: landmarks block}."""
    out = dict(main)
    out["landmarks_by_kind"] = {k: s.get("landmarks") for k, s in by_kind.items()
                                if s.get("landmarks")}
    return out


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) < 3 or argv[0] != "merge":
        print(__doc__, file=sys.stderr)
        return 2
    out, main_json, pairs = Path(argv[1]), Path(argv[2]), argv[3:]
    by_kind = {}
    for p in pairs:
        kind, _, path = p.partition("=")
        by_kind[kind] = json.loads(Path(path).read_text())
    merged = merge(json.loads(main_json.read_text()), by_kind)
    tmp = out.with_name(out.name + ".tmp")
    tmp.write_text(json.dumps(merged, indent=1, sort_keys=True))
    tmp.replace(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
