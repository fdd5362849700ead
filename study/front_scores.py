# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Scores of the solutions of a MOREA front (standard library only, so that
bench/run-study-morea.sh can use it on a GPU machine without the study's packages).

A registration written with `morea register --select all` has one folder
solution_<id> per front member (`--select spread:N`: N members spread over
the front). Each is scored on the study problem by
`morea evaluate` (all landmarks, then each landmark kind), several at a time,
and the scores go into one CSV row per solution with its objective values from
front.csv: how TRE and Dice vary along the front, so that a rule choosing a
solution can be judged on every member rather than only the chosen one.

    python3 -m study.front_scores REGISTER_DIR PROBLEM_DIR OUT.csv --morea BIN
            [--landmarks DIR] [--jobs N]
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from study.landmark_kinds import sets as landmark_sets

STRUCTURE_SCORES = ("dice", "hausdorff95_mm")


def _evaluate(morea: str, problem: Path, field: Path, out: Path, landmarks=None) -> dict:
    cmd = [morea, "evaluate", "--problem", str(problem), "--field", str(field), "-o", str(out)]
    if landmarks:
        cmd += ["--fixed-landmarks", str(landmarks[0]), "--moving-landmarks", str(landmarks[1])]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"morea evaluate failed on {field}: {done.stderr.strip()[-500:]}")
    return json.loads(out.read_text())


def score_solution(morea: str, problem: Path, solution: Path, kinds: dict, scratch: Path) -> dict:
    """One row: Jacobian, per-structure Dice/HD95, TRE over all landmarks and per kind."""
    field = solution / "preprocessed_fixed_to_moving.nii.gz"
    main = _evaluate(morea, problem, field, scratch / f"{solution.name}.json")
    row = {"tre_mean_mm": (main.get("landmarks") or {}).get("tre_mean_mm"),
           "jacobian_nonpositive_fraction": main.get("jacobian_nonpositive_fraction")}
    for name, s in sorted((main.get("structures") or {}).items()):
        for key in STRUCTURE_SCORES:
            row[f"{key}:{name}"] = s.get(key)
    for kind, files in kinds.items():
        k = _evaluate(morea, problem, field, scratch / f"{solution.name}.{kind}.json", files)
        row[f"tre_mean_mm:{kind}"] = (k.get("landmarks") or {}).get("tre_mean_mm")
    return row


def front_scores(register: Path, problem: Path, morea: str, landmarks: Path | None = None,
                 jobs: int = 4) -> list[dict]:
    """Rows sorted by guidance (best first): front.csv's columns plus the
    scores, for each member written as solution_<id> (`--select all`: the
    whole front; `--select spread:N`: N members spread over it)."""
    with open(register / "front.csv", newline="") as f:
        front = list(csv.DictReader(f))
    front = [r for r in front if (register / f"solution_{r['id']}").is_dir()]
    if not front:
        raise FileNotFoundError(f"{register}: no front member has a solution folder "
                                "(register with --select all or --select spread:N)")
    kinds = landmark_sets(landmarks) if landmarks else {}
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(max_workers=jobs) as pool:
        scored = pool.map(lambda r: score_solution(morea, problem, register / f"solution_{r['id']}",
                                                   kinds, Path(tmp)), front)
        rows = [{**r, **s} for r, s in zip(front, scored)]
    rows.sort(key=lambda r: float(r["guidance"]))
    return rows


def write_csv(rows: list[dict], out: Path) -> None:
    columns: list[str] = []
    for r in rows:
        columns += [c for c in r if c not in columns]
    tmp = out.with_name(out.name + ".tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(rows)
    tmp.replace(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m study.front_scores", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("register", type=Path)
    ap.add_argument("problem", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--morea", default="morea")
    ap.add_argument("--landmarks", type=Path, help="landmark sets per kind (study/landmark_kinds.py)")
    ap.add_argument("--jobs", type=int, default=max(1, (os.cpu_count() or 2) // 2))
    a = ap.parse_args(argv)
    try:
        rows = front_scores(a.register, a.problem, a.morea, a.landmarks, a.jobs)
    except (OSError, RuntimeError) as e:
        print(f"front_scores: {e}", file=sys.stderr)
        return 1
    write_csv(rows, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
