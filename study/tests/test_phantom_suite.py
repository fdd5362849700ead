# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The phantom suite's pairs, the competitors' "paper" profile with its
convergence check, the landmark kinds, and the pieces bench/run-study-morea.sh
shares with the study (records, the preprocessing check), without registering
anything."""
from __future__ import annotations

import argparse
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from study import common, evaluation, landmark_kinds, morea_record, morea_runner, pairs, report
from study import run_study

SUITE = ["phantom-pelvis", "phantom-emptying", "phantom-gas", "phantom-static"]


@pytest.mark.parametrize("name", SUITE)
def test_suite_pairs_use_the_paper_configuration(name):
    pair = pairs.make(name, quick=False)
    assert pair.phantom_case == pairs.PHANTOM_SUITE[name][0]
    assert not pair.needs_data and pair.landmarks_by_kind
    # Truth known: the best competitor configuration and the convergence check
    # go by the mean TRE of all landmarks; bone TRE and the organ are criteria too.
    assert pair.criteria[0].column == "tre_mean_mm" and not pair.criteria[0].higher_is_better
    columns = [c.column for c in pair.criteria]
    assert f"dice:{pair.primary_structure}" in columns and "tre_mean_mm:bone" in columns
    assert "dice:bladder" in columns
    assert set(pair.morea_variants) == {"default", "no-bone-guidance"}
    assert pair.morea_variants["default"] == []
    assert pair.morea_variants["no-bone-guidance"] == [
        "--set", "problem_guidance_selection=bladder,rectum,bowel"]
    p = tomllib.loads(pair.morea_parameters.read_text())
    paper = tomllib.loads((common.REPO_ROOT / "examples" / "paper_parameters.toml").read_text())
    for key in ("ea_num_generations", "ea_population_size", "ea_num_clusters", "ea_archive_size",
                "ea_adaptive_steering_activated_at_num_generations", "morea_mesh_num_points",
                "morea_sampling_rate", "morea_rigid_weight", "morea_image_metric",
                "morea_guidance_metric", "morea_mesh_generation_method", "problem_guidance_selection",
                "morea_mesh_shell_offsets", "morea_mesh_shell_fraction"):
        assert p[key] == paper[key], key
    assert p["morea_rigid_strain_limit"] == 0.03
    assert p["preprocess_isotropic_spacing"] == 4.0 and p["preprocess_crop_margin"] == 80.0
    # Only the pelvis case moves its bones (the table moves).
    assert p["preprocess_rigid_structure"] == ("bones" if name == "phantom-pelvis" else "none")
    assert pair.morea_parameters.read_text().startswith(
        "# Copyright 2026 The MultiObjectiveRegistration authors\n"
        "# SPDX-License-Identifier: Apache-2.0\n")


def test_existing_pairs_are_unchanged():
    assert pairs.NAMES[:3] == ["lung", "abdomen", "phantom"]
    ph = pairs.make("phantom", quick=True)
    assert ph.phantom_case is None and ph.morea_variants == {"default": []}
    assert ph.morea_parameters.name == "morea_phantom_quick.toml"
    assert pairs.phantom_arguments(ph) == []
    assert pairs.phantom_arguments(pairs.make("phantom-gas", False)) == ["--case", "gas-pocket"]
    with pytest.raises(SystemExit):
        pairs.make("phantom-nonsense", False)


def test_paper_profile_is_the_papers_at_its_voxel_size():
    # At the paper's 1.5 mm voxels the proportions give exactly appendix C's values.
    s = run_study.resolve_settings(run_study.PAPER, 1.5)
    assert s["elastix"]["grid_spacing"] == pytest.approx(2.0)
    assert s["ants"]["cc_radius"] == 8
    assert s["ants"]["iterations"] == (2000, 1000, 500, 250)
    s4 = run_study.resolve_settings(run_study.PAPER, 4.0)
    assert s4["elastix"]["grid_spacing"] == pytest.approx(16.0 / 3.0, abs=1e-3)
    assert s4["ants"]["cc_radius"] == 3
    assert "grid_spacing_voxels" in run_study.PAPER["elastix"]   # the profile itself is untouched
    assert run_study.resolve_settings(run_study.REDUCED, None)["ants"]["cc_radius"] == 4
    with pytest.raises(ValueError):
        run_study.resolve_settings(run_study.PAPER, None)
    assert run_study.scaled_iterations("ants", s4, 2) == (4000, 2000, 1000, 500)
    assert run_study.scaled_iterations("elastix", s4, 2) == 2 * s4["elastix"]["iterations"]
    assert run_study.config_name("elastix", 1.0, 2) == "w1-x2"
    assert run_study.config_name("ants", 0.0) == "w0"
    assert run_study.config_name("morea", None, variant="no-bone-guidance") == "no-bone-guidance"
    assert run_study.default_profile(pairs.make("phantom-static", False), False) == "paper"
    assert run_study.default_profile(pairs.make("lung", False), False) == "reduced"
    assert run_study.default_profile(pairs.make("phantom", True), True) == "quick"


def test_relative_change():
    assert run_study.relative_change(2.0, 2.01) == pytest.approx(0.005)
    assert run_study.relative_change(2.0, 2.0) == 0.0
    assert run_study.relative_change(None, 1.0) is None
    assert run_study.relative_change(float("nan"), 1.0) is None
    assert run_study.relative_change(0.0, 1.0) == math.inf


def _points(path, pts):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("point\n%d\n" % len(pts) + "".join("%g %g %g\n" % p for p in pts))


def test_landmark_kinds_split_and_merge(tmp_path):
    problem = tmp_path / "problem"
    kinds = ["bone", "soft", "bone", "wall"]
    _points(problem / "fixed_landmarks.txt", [(i, 0, 0) for i in range(4)])
    _points(problem / "moving_landmarks.txt", [(i, 1, 0) for i in range(4)])
    sets = landmark_kinds.split(kinds, problem, tmp_path / "lm")
    assert list(sets) == ["bone", "wall", "soft"]               # the suite's order
    header, bone = landmark_kinds.read_points(sets["bone"][1])
    assert header == "point" and bone == ["0 1 0", "2 1 0"]
    assert landmark_kinds.sets(tmp_path / "lm").keys() == sets.keys()
    assert landmark_kinds.sets(tmp_path / "none") == {}
    with pytest.raises(ValueError):
        landmark_kinds.split(kinds[:3], problem, tmp_path / "bad")
    main = {"landmarks": {"tre_mean_mm": 2.0, "tre_sd_mm": 1.0, "tre_max_mm": 3.0, "count": 4},
            "structures": {}, "jacobian_nonpositive_fraction": 0.0}
    merged = landmark_kinds.merge(main, {
        "bone": {"landmarks": {"tre_mean_mm": 0.1, "tre_max_mm": 0.2, "count": 2}},
        "soft": {"landmarks": None}})
    row = evaluation.flatten(merged)
    assert row["tre_mean_mm"] == 2.0 and row["tre_mean_mm:bone"] == 0.1
    assert row["tre_max_mm:bone"] == 0.2 and row["landmarks:bone"] == 2
    assert "tre_mean_mm:soft" not in row
    assert report.column_label("tre_mean_mm:bone") == "bone TRE mm"


def _scores(tre, bone=0.1, dice=0.9, jac=0.0):
    return {"landmarks": {"tre_mean_mm": tre, "tre_sd_mm": 0.0, "tre_max_mm": tre, "count": 90},
            "landmarks_by_kind": {"bone": {"tre_mean_mm": bone, "tre_max_mm": bone, "count": 13}},
            "structures": {"bladder": {"dice": dice, "hausdorff_mm": 1.0, "hausdorff95_mm": 1.0,
                                       "mean_surface_distance_mm": 0.5}},
            "jacobian_nonpositive_fraction": jac}


def _run(out, method, config, seed, scores, rec):
    d = out / "runs" / method / config / f"seed{seed}"
    d.mkdir(parents=True)
    common.write_json(d / "scores.json", scores)
    common.write_json(d / "run.json", rec)


def _study(tmp_path, monkeypatch, pair="phantom-emptying"):
    monkeypatch.setattr(run_study.common, "find_morea", lambda explicit=None: "morea")
    out = tmp_path / "study"
    (out / "problem").mkdir(parents=True)
    common.write_json(out / "problem" / "preprocess.json", {"spacing_mm": 4.0})
    args = argparse.Namespace(out=str(out), pair=pair, quick=False, profile=None, morea=None,
                              data=None, threads=2, seeds=None, sweep_seeds=1, skip=None,
                              local_morea=False, no_convergence_check=False, retry_failed=False)
    return run_study.Study(args), out


def test_convergence_check_and_acceptance(tmp_path, monkeypatch):
    study, out = _study(tmp_path, monkeypatch)
    assert study.profile_name == "paper" and study.settings["convergence_check"]
    assert study.settings["ants"]["cc_radius"] == 3
    # The sweep (seed 1): ANTs w0 and elastix w1 are best by mean TRE.
    for w, tre in ((0.0, 2.0), (1.0, 2.5), (10.0, 3.0)):
        _run(out, "ants", f"w{w:g}", 1, _scores(tre, dice=0.95),
             {"iterations": [2000, 1000, 500, 250], "iterations_used": [10, 13, 21, 12],
              "seconds": {"registration": 40.0}})
    for w, tre in ((0.0, 3.1), (1.0, 3.0)):
        _run(out, "elastix", f"w{w:g}", 1, _scores(tre),
             {"iterations_per_resolution": 200, "seconds": {"registration": 100.0}})
    assert study.best_weight("ants") == 0.0 and study.best_weight("elastix") == 1.0
    # Twice the iterations: ANTs unchanged (converged), elastix 2 % better (not).
    _run(out, "ants", "w0-x2", 1, _scores(2.0, dice=0.95),
         {"iterations": [4000, 2000, 1000, 500], "iterations_used": [10, 13, 21, 12],
          "seconds": {"registration": 41.0}})
    _run(out, "elastix", "w1-x2", 1, _scores(2.94),
         {"iterations_per_resolution": 400, "seconds": {"registration": 200.0}})
    conv = {c["method"]: c for c in study.convergence()}
    assert conv["ants"]["config"] == "w0" and conv["ants"]["relative_change"] == 0.0
    assert conv["ants"]["converged"] and conv["ants"]["iterations_used_doubled"] == [10, 13, 21, 12]
    assert conv["elastix"]["relative_change"] == pytest.approx(0.02)
    assert not conv["elastix"]["converged"]
    assert conv["elastix"]["iterations"] == 200 and conv["elastix"]["iterations_doubled"] == 400
    # The doubled runs are no candidates for the best configuration.
    assert study.best_weight("elastix") == 1.0
    # Not converged: doubled again (800 iterations); one row per doubling.
    ran = []
    monkeypatch.setattr(study, "run_one", lambda m, w, seed, scale=1, variant="default":
                        ran.append((m, w, seed, scale)))
    study.settings["elastix"]["weights"] = [0.0, 1.0]
    study.settings["ants"]["weights"] = [0.0, 1.0, 10.0]
    study.settings["seeds"] = 0
    study.sweep_and_repeat()
    assert ("elastix", 1.0, 1, 4) in ran and ("ants", 0.0, 1, 4) not in ran
    _run(out, "elastix", "w1-x4", 1, _scores(2.939),
         {"iterations_per_resolution": 800, "seconds": {"registration": 400.0}})
    steps = [c for c in study.convergence() if c["method"] == "elastix"]
    assert [c["config"] for c in steps] == ["w1", "w1-x2"]
    assert steps[1]["iterations"] == 400 and steps[1]["iterations_doubled"] == 800
    assert steps[1]["converged"] and steps[1]["relative_change"] < 0.001
    ran.clear()
    study.sweep_and_repeat()  # converged at x4: nothing beyond it
    assert ("elastix", 1.0, 1, 8) not in ran
    monkeypatch.undo()
    monkeypatch.setattr(run_study.common, "find_morea", lambda explicit=None: "morea")
    # MOREA, both configurations, from the GPU (no fields).
    for seed in (1, 2):
        _run(out, "morea", "default", seed, _scores(2.1, bone=0.2, dice=0.96),
             {"seconds": {"registration": 30.0}, "host": "NVIDIA H200, 16 host cores"})
        _run(out, "morea", "no-bone-guidance", seed, _scores(2.4, bone=0.6, dice=0.96),
             {"seconds": {"registration": 30.0}})
    for seed in (2,):
        _run(out, "ants", "w0", seed, _scores(2.0, dice=0.95), {"seconds": {"registration": 40.0}})
    rows = study.collect()
    chosen = study.chosen_rows(rows)
    assert set(chosen) == {"morea", "morea:no-bone-guidance", "ants", "elastix"}
    assert chosen["ants"][0] == "w0" and len(chosen["ants"][1]) == 2
    assert report.method_keys(chosen) == ["morea", "morea:no-bone-guidance", "elastix", "ants"]
    checks = {c["check"]: c for c in report.acceptance(study.pair, chosen)}
    tre = checks["mean TRE (all landmarks) <= ANTs SyN + 0.2 mm"]
    assert tre["passed"] and tre["reference"] == pytest.approx(2.2)
    assert checks["bladder Dice >= ANTs SyN"]["passed"]
    assert checks["bone TRE <= 0.5 mm, MOREA, worst seed"]["passed"]
    assert not checks["bone TRE <= 0.5 mm, MOREA (no bone guidance), worst seed"]["passed"]
    assert checks["no voxel with Jacobian <= 0, MOREA, worst seed"]["passed"]
    # MOREA runs missing here are not registered on this CPU without --local-morea.
    assert study.run_one("morea", None, 3) is None
    assert not (out / "runs" / "morea" / "default" / "seed3").exists()


def test_morea_job_for_the_gpu(tmp_path, monkeypatch):
    study, out = _study(tmp_path, monkeypatch, "phantom-static")
    raw = out / "raw"
    (raw / "fixed_masks").mkdir(parents=True)
    (raw / "fixed.nii.gz").write_bytes(b"fixed")
    (raw / "fixed_masks" / "bladder.nii.gz").write_bytes(b"mask")
    (out / "problem" / morea_runner.INITIAL_TRANSFORM).write_text("identity")
    study.write_morea_job()
    job = common.read_json(out / "morea_job.json")
    assert job["pair"] == "phantom-static" and job["phantom_arguments"] == ["--case", "static-bones"]
    assert job["raw_args"] == ["--problem", "{raw}"]
    assert job["initial_transform"] == "problem/rigid_fixed_to_moving.tfm"
    assert job["seeds"] == [1, 2, 3, 4, 5] and job["select"] == morea_runner.SELECT
    assert job["variants"]["no-bone-guidance"][-1].startswith("problem_guidance_selection=")
    assert (out / "morea_parameters.toml").read_text() == study.pair.morea_parameters.read_text()
    assert morea_record.md5_check(raw, job["raw_md5"]) == []
    (raw / "fixed.nii.gz").write_bytes(b"other")
    assert morea_record.md5_check(raw, job["raw_md5"]) == ["fixed.nii.gz: differs from the study's"]
    # The GPU script runs the same `morea register` as the study's runner.
    script = (common.REPO_ROOT / "bench" / "run-study-morea.sh").read_text()
    assert f"select={morea_runner.SELECT}\n" in script
    assert '--select "$select" --checkpoint-every 0' in script
    args = morea_runner.register_arguments(["--problem", "raw"], "p.toml", 3, ["--set", "x=1"],
                                           Path("t.tfm"), Path("o"))
    assert args == ["register", "--problem", "raw", "--parameters", "p.toml", "--set", "seed=3",
                    "--set", "x=1", "--select", "best-guidance,knee", "--checkpoint-every", "0",
                    "--initial-transform", "t.tfm", "-o", "o"]


def test_morea_record_from_summary():
    summary = {"solutions": {"best_guidance": {"magnitude": 1.0, "intensity": 0.1, "guidance": 0.2,
                                               "id": 7, "voxel_fold_repair": {}}},
               "front_size": 100, "generations": 500, "backend": "cuda", "threads": 16,
               "seconds": {"command": 30.0, "optimisation": 20.0}}
    rec = morea_record.record(summary, 2, "p.toml", "default", 31.0, host="H200")
    assert rec["chosen_objectives"] == {"magnitude": 1.0, "intensity": 0.1, "guidance": 0.2, "id": 7}
    assert rec["seconds"]["registration"] == 31.0 and rec["seconds"]["morea_optimisation"] == 20.0
    assert rec["host"] == "H200" and rec["config"] == "default" and rec["backend"] == "cuda"


def test_preprocessing_check_reads_mha_and_nifti(tmp_path):
    sitk = pytest.importorskip("SimpleITK")
    reg, problem = tmp_path / "reg", tmp_path / "problem"
    (reg / "preprocessed").mkdir(parents=True)
    problem.mkdir()
    rng = np.random.default_rng(1)
    for role in ("fixed", "moving"):
        img = sitk.GetImageFromArray(rng.random((5, 6, 7)).astype(np.float32))
        img.SetSpacing((4.0, 4.0, 4.0))
        img.SetOrigin((-10.5, 3.0, 7.25))
        sitk.WriteImage(img, str(reg / "preprocessed" / f"{role}.mha"), True)
        sitk.WriteImage(img, str(problem / f"{role}.nii.gz"))
    for side in ("fixed", "moving"):
        _points(reg / "preprocessed" / f"{side}_landmarks.txt", [(1, 2, 3)])
        _points(problem / f"{side}_landmarks.txt", [(1, 2, 3)])
    grid, values = morea_record.read_mha(reg / "preprocessed" / "fixed.mha")
    assert grid == {"size": [7, 6, 5], "spacing": [4.0, 4.0, 4.0], "origin": [-10.5, 3.0, 7.25]}
    assert morea_record.read_nifti_gz(problem / "fixed.nii.gz")[0] == grid
    assert len(values) == 210
    assert morea_record.check(reg, problem) == []
    # Another pre-alignment: the moving voxels and landmarks differ.
    moved = sitk.GetImageFromArray(rng.random((5, 6, 7)).astype(np.float32))
    moved.CopyInformation(sitk.ReadImage(str(problem / "moving.nii.gz")))
    sitk.WriteImage(moved, str(problem / "moving.nii.gz"))
    _points(problem / "moving_landmarks.txt", [(1, 2, 3.5)])
    problems = morea_record.check(reg, problem)
    assert any(p.startswith("moving: voxels differ") for p in problems)
    assert "moving landmarks differ from the problem's" in problems


def test_gpu_script_keeps_experiments_apart(tmp_path):
    """MOREA_STUDY_SET (an experiment's overrides) without MOREA_STUDY_LABEL is
    refused before anything runs, so an experiment never lands among the study's runs."""
    import os
    import subprocess
    script = common.REPO_ROOT / "bench" / "run-study-morea.sh"
    env = dict(os.environ, MOREA_BIN="/bin/true", MOREA_STUDY_WORK=str(tmp_path / "work"),
               MOREA_STUDY_SET="morea_mesh_shell_offsets=8,20")
    env.pop("MOREA_STUDY_LABEL", None)
    done = subprocess.run(["bash", str(script), "run", str(tmp_path / "out")], env=env,
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert "MOREA_STUDY_LABEL" in done.stderr
    assert not (tmp_path / "work").exists() and not (tmp_path / "out").exists()


@pytest.mark.parametrize("front", ["some", "-3", "2x"])
def test_gpu_script_refuses_a_bad_front_count(tmp_path, front):
    """MOREA_STUDY_FRONT is a number of solutions spread over the front or
    "all"; anything else is refused before anything runs."""
    import os
    import subprocess
    script = common.REPO_ROOT / "bench" / "run-study-morea.sh"
    env = dict(os.environ, MOREA_BIN="/bin/true", MOREA_STUDY_WORK=str(tmp_path / "work"), MOREA_STUDY_FRONT=front)
    done = subprocess.run(["bash", str(script), "run", str(tmp_path / "out")], env=env,
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert "MOREA_STUDY_FRONT" in done.stderr
    assert not (tmp_path / "work").exists() and not (tmp_path / "out").exists()
