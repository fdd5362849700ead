# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""study/front_scores.py: the front members of a small registration scored,
one row each, in guidance order, matching `morea evaluate` of that member."""
from __future__ import annotations

import csv
import json
import subprocess

import pytest

from study import front_scores


def _run(cmd):
    """Runs a morea command; a failure shows its exit status and the end of its stderr."""
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        pytest.fail(f"{cmd[1]} exited with {done.returncode}: {done.stderr[-2000:]}")


@pytest.fixture(scope="module")
def registered(morea, translated_problem, tmp_path_factory):
    out = tmp_path_factory.mktemp("front") / "reg"
    cmd = [morea, "register", "--problem", str(translated_problem), "-o", str(out), "--select", "all",
           "--checkpoint-every", "0", "--threads", "2"]
    for kv in ("ea_population_size=16", "ea_num_generations=3", "ea_archive_size=40",
               "morea_mesh_num_points=40", "preprocess_rigid_structure=none", "seed=3"):
        cmd += ["--set", kv]
    _run(cmd)
    return out


def test_every_member_is_scored_in_guidance_order(morea, registered, tmp_path):
    problem = registered / "preprocessed"
    rows = front_scores.front_scores(registered, problem, morea, jobs=2)
    with open(registered / "front.csv", newline="") as f:
        front = list(csv.DictReader(f))
    assert len(rows) == len(front) >= 2
    assert sorted(r["id"] for r in rows) == sorted(r["id"] for r in front)
    guidance = [float(r["guidance"]) for r in rows]
    assert guidance == sorted(guidance)
    # One member's row is what `morea evaluate` says of it.
    row = rows[-1]
    out = tmp_path / "one.json"
    _run([morea, "evaluate", "--problem", str(problem), "--field",
          str(registered / f"solution_{row['id']}" / "preprocessed_fixed_to_moving.nii.gz"), "-o", str(out)])
    one = json.loads(out.read_text())
    assert row["dice:ball"] == pytest.approx(one["structures"]["ball"]["dice"])
    assert row["jacobian_nonpositive_fraction"] == one["jacobian_nonpositive_fraction"]
    front_scores.write_csv(rows, tmp_path / "scores.csv")
    with open(tmp_path / "scores.csv", newline="") as f:
        assert len(list(csv.DictReader(f))) == len(rows)


def test_a_front_written_without_its_members_is_refused(morea, registered, tmp_path):
    partial = tmp_path / "partial"
    partial.mkdir()
    (partial / "front.csv").write_text((registered / "front.csv").read_text())
    with pytest.raises(FileNotFoundError, match="--select all or --select spread:N"):
        front_scores.front_scores(partial, registered / "preprocessed", morea)


def test_only_the_members_written_are_scored(morea, registered, tmp_path):
    """A front written with --select spread:N has N solution folders: those are scored."""
    partial = tmp_path / "partial"
    partial.mkdir()
    (partial / "front.csv").write_text((registered / "front.csv").read_text())
    with open(registered / "front.csv", newline="") as f:
        ids = [r["id"] for r in csv.DictReader(f)][:2]
    for i in ids:
        (partial / f"solution_{i}").symlink_to(registered / f"solution_{i}")
    rows = front_scores.front_scores(partial, registered / "preprocessed", morea, jobs=2)
    assert sorted(r["id"] for r in rows) == sorted(ids)
    assert all(r["dice:ball"] is not None for r in rows)
