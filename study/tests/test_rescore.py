# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""`python -m study rescore`: the baseline and every finished run are scored
again by `morea evaluate` without registering anything; the new scores replace
the old ones in the tables, the run times stay those of run.json, and runs
without fields (or failed runs) are left as they were."""
from __future__ import annotations

import csv
import shutil

import numpy as np
import pytest

from study import common, evaluation, run_study
from conftest import SHIFT_MM


def _fields(problem, d):
    import SimpleITK as sitk
    fixed_ref = sitk.ReadImage(str(problem / "fixed.nii.gz"))
    moving_ref = sitk.ReadImage(str(problem / "moving.nii.gz"))
    shape = fixed_ref.GetSize()[::-1] + (3,)
    common.write_field(d / "fixed_to_moving.nii.gz", np.broadcast_to(SHIFT_MM, shape), fixed_ref)
    common.write_field(d / "moving_to_fixed.nii.gz",
                       np.broadcast_to(np.negative(SHIFT_MM), shape), moving_ref)


def _stale(path, **extra_mm):
    """Scores as an earlier `morea evaluate` might have written them: the
    named structure distances of 'ball' moved by the given amounts."""
    s = common.read_json(path)
    for key, delta in extra_mm.items():
        s["structures"]["ball"][key] += delta
    common.write_json(path, s)
    return s


def _rows(out):
    with open(out / "results.csv") as f:
        return list(csv.DictReader(f))


def test_rescore_replaces_scores_only(morea, translated_problem, tmp_path):
    out = tmp_path / "study"
    problem = out / "problem"
    shutil.copytree(translated_problem, problem)
    # Baseline and a finished MOREA run, with stale HD95 / MSD in their scores.
    (out / "baseline").mkdir(parents=True)
    true_base = evaluation.evaluate(morea, problem, out / "baseline" / "scores.json")
    _stale(out / "baseline" / "scores.json", hausdorff95_mm=1.5)
    run = out / "runs" / "morea" / "default" / "seed1"
    run.mkdir(parents=True)
    _fields(problem, run)
    true_run = evaluation.evaluate(morea, problem, run / "scores.json",
                                   run / "fixed_to_moving.nii.gz", run / "moving_to_fixed.nii.gz")
    _stale(run / "scores.json", hausdorff95_mm=2.0, mean_surface_distance_mm=0.5)
    common.write_json(run / "run.json", {"seconds": {"registration": 12.5}})
    # A run whose fields were deleted keeps its scores; a failed run stays failed.
    kept = out / "runs" / "ants" / "w1" / "seed1"
    kept.mkdir(parents=True)
    kept_scores = common.read_json(run / "scores.json")
    kept_scores["structures"]["ball"]["hausdorff95_mm"] = 99.0
    common.write_json(kept / "scores.json", kept_scores)
    failed = out / "runs" / "elastix" / "w1" / "seed1"
    failed.mkdir(parents=True)
    common.write_json(failed / "failed.json", {"error": "test"})

    assert run_study.main(["rescore", "--pair", "phantom", "--out", str(out),
                           "--morea", morea]) == 0

    assert not (run / "rescore.json").exists()
    rows = {(r["method"], r["config"]): r for r in _rows(out)}
    base, morea_row = rows[("rigid baseline", "")], rows[("morea", "default")]
    for row, true in ((base, true_base), (morea_row, true_run)):
        s = true["structures"]["ball"]
        assert float(row["hd95:ball"]) == pytest.approx(s["hausdorff95_mm"], abs=1e-9)
        assert float(row["msd:ball"]) == pytest.approx(s["mean_surface_distance_mm"], abs=1e-9)
        assert float(row["dice:ball"]) == pytest.approx(s["dice"], abs=1e-12)
        assert float(row["hd:ball"]) == pytest.approx(s["hausdorff_mm"], abs=1e-9)
    assert float(morea_row["seconds"]) == 12.5
    assert float(rows[("ants", "w1")]["hd95:ball"]) == 99.0
    assert rows[("elastix", "w1")]["failed"] == "1"
    log = (out / "logs" / "study.log").read_text()
    assert "rescored 2 results" in log
    assert "changed: hd95 (up to 2), msd (up to 0.5); unchanged:" in log
    assert "runs/ants/w1/seed1 has no fields" in log
