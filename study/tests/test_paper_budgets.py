# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The data pairs at the paper's budgets (lung-paper, abdomen-paper): the same
problem as the first study's pairs, MOREA's paper configuration on a GPU with
the raw files carried to it, and the abdominal pair's acceptance checks; without
registering anything."""
from __future__ import annotations

import tomllib

import pytest

from study import common, pairs, report, run_study
from study.tests.test_phantom_suite import _run, _study

PREPROCESSING = ("preprocess_isotropic_spacing", "preprocess_rigid_structure", "preprocess_crop_structure",
                 "preprocess_crop_margin", "preprocess_intensity_min", "preprocess_intensity_max",
                 "preprocess_fov_threshold", "evaluation_border_margin")


@pytest.mark.parametrize("name", sorted(pairs.PAPER_BUDGET))
def test_paper_budget_pairs_register_the_first_studys_problem(name):
    pair, base = pairs.make(name, False), pairs.make(pairs.PAPER_BUDGET[name], False)
    assert pair.name == name and pair.morea_on_gpu and not base.morea_on_gpu
    assert pair.data_pair == base.data_pair == base.name
    assert [c.column for c in pair.criteria] == [c.column for c in base.criteria]
    assert pair.morea_parameters.name == f"morea_{base.name}_paper.toml"
    assert run_study.default_profile(pair, False) == "paper"
    p = tomllib.loads(pair.morea_parameters.read_text())
    small = tomllib.loads(base.morea_parameters.read_text())
    # The preprocessing keys decide the problem every method is scored on.
    for key in PREPROCESSING:
        assert p.get(key) == small.get(key), key
    paper = tomllib.loads((common.REPO_ROOT / "examples" / "paper_parameters.toml").read_text())
    for key in ("ea_num_generations", "ea_population_size", "ea_num_clusters", "ea_archive_size",
                "ea_adaptive_steering_activated_at_num_generations", "morea_mesh_num_points",
                "morea_sampling_rate"):
        assert p[key] == paper[key], key
    assert p["morea_mesh_surface_structures"] == small["morea_mesh_surface_structures"]
    # The study's MOREA is the paper's configuration, steering included; the
    # tighter steering is a side row, and only that key differs there.
    assert pair.morea_variants["default"] == []
    assert p.get("ea_adaptive_steering_guidance_threshold", 1.5) == 1.5
    steering = ["--set", "ea_adaptive_steering_guidance_threshold=1.1"]
    assert pair.morea_variants["steering-1.1"] == steering
    if name == "abdomen-paper":
        longer = ["--set", "ea_num_generations=1000"]
        assert pair.morea_variants["1000-generations"] == longer
        assert pair.morea_variants["1000-generations-steering-1.1"] == longer + steering
    # Steering off is a side row of the lung pair only, and only that key differs.
    if name == "lung-paper":
        assert pair.morea_variants["no-steering"] == ["--set", "ea_adaptive_steering_enabled=false"]
    else:
        assert "no-steering" not in pair.morea_variants
    assert p.get("ea_adaptive_steering_enabled", True) is True


def test_job_carries_a_data_pairs_files(tmp_path, monkeypatch):
    data = tmp_path / "data"
    d = data / "abdomen-cbct-pair"
    (d / "CB07_masks").mkdir(parents=True)
    for f in ("CB02.mha", "CB07.mha", "CB02_labels.mha", "CB02_labels.txt",
              "CB07_masks/Stomach_duo_CBCT.mha", "CB07_masks/Bowel_sm_CBCT.mha"):
        (d / f).write_text(f)
    study, out = _study(tmp_path, monkeypatch, "abdomen-paper")
    study.args.data = str(data)
    pairs.resolve(study.pair, data, out, "morea")
    study.write_morea_job()
    job = common.read_json(out / "morea_job.json")
    assert "phantom_arguments" not in job
    assert job["raw_args"][:4] == ["--fixed", "{raw}/abdomen-cbct-pair/CB02.mha",
                                   "--moving", "{raw}/abdomen-cbct-pair/CB07.mha"]
    assert "Stomach_duo_CBCT={raw}/abdomen-cbct-pair/CB02_labels.mha:Stomach_duo_CBCT" in job["raw_args"]
    # Each file once; the label map's names travel with it.
    assert job["raw_files"] == ["abdomen-cbct-pair/CB02.mha", "abdomen-cbct-pair/CB07.mha",
                                "abdomen-cbct-pair/CB02_labels.mha", "abdomen-cbct-pair/CB02_labels.txt",
                                "abdomen-cbct-pair/CB07_masks/Stomach_duo_CBCT.mha",
                                "abdomen-cbct-pair/CB07_masks/Bowel_sm_CBCT.mha"]
    assert not any(str(data) in a for a in job["raw_args"])
    script = (common.REPO_ROOT / "bench" / "run-study-morea.sh").read_text()
    assert "raw_files" in script and 'raw="$pd/raw"' in script


def _organ_scores(stomach, bowel, jac=0.0):
    s = lambda dice, hd95: {"dice": dice, "hausdorff_mm": hd95, "hausdorff95_mm": hd95,
                            "mean_surface_distance_mm": 1.0}
    return {"landmarks": None, "jacobian_nonpositive_fraction": jac,
            "structures": {"Stomach_duo_CBCT": s(*stomach), "Bowel_sm_CBCT": s(*bowel)}}


def test_abdomen_acceptance_against_the_better_competitor(tmp_path, monkeypatch):
    study, out = _study(tmp_path, monkeypatch, "abdomen-paper")
    for seed in (1, 2):
        _run(out, "ants", "w0", seed, _organ_scores((0.93, 3.0), (0.89, 25.8)), {"seconds": {"registration": 1}})
        _run(out, "elastix", "w1", seed, _organ_scores((0.70, 9.0), (0.60, 20.0)), {"seconds": {"registration": 1}})
        _run(out, "morea", "default", seed, _organ_scores((0.85, 4.2), (0.80, 15.0), jac=0.0 if seed == 1 else 1e-6),
             {"seconds": {"registration": 1}})
        # The knee, scored beside the chosen solution by the GPU script: a side row, no checks.
        _run(out, "morea", "default-knee", seed, _organ_scores((0.5, 20.0), (0.5, 30.0), jac=0.5),
             {"seconds": {"registration": 1}, "chosen": "knee"})
    study.settings["ants"]["weights"] = [0.0]
    study.settings["elastix"]["weights"] = [1.0]
    chosen = study.chosen_rows(study.collect())
    assert chosen["morea:knee"][0] == "default-knee" and len(chosen["morea:knee"][1]) == 2
    assert report.method_label("morea:knee") == "MOREA (knee)"
    assert [t["comparison"].split(" vs ")[0] for t in report.mann_whitney(chosen, study.pair)] == ["MOREA"] * 4
    checks = {c["check"]: c for c in report.acceptance(study.pair, chosen)}
    assert set(checks) == {"stomach Dice >= the better competitor (ANTs SyN)",
                           "stomach HD95 <= the better competitor (ANTs SyN)",
                           "bowel Dice >= the better competitor (ANTs SyN)",
                           "bowel HD95 <= the better competitor (elastix)",
                           "no voxel with Jacobian <= 0, worst seed"}
    assert not checks["stomach Dice >= the better competitor (ANTs SyN)"]["passed"]
    assert checks["stomach Dice >= the better competitor (ANTs SyN)"]["reference"] == pytest.approx(0.93)
    assert checks["bowel HD95 <= the better competitor (elastix)"]["passed"]
    assert checks["bowel HD95 <= the better competitor (elastix)"]["reference"] == pytest.approx(20.0)
    assert not checks["no voxel with Jacobian <= 0, worst seed"]["passed"]
    # The first study's pair (MOREA on the CPU, reduced budgets) has no such checks.
    assert report.acceptance(pairs.make("abdomen", False), chosen) == []


def test_a_knee_is_recorded_as_the_knee():
    from study import morea_record
    solutions = {name: {"magnitude": m, "intensity": 0.1, "guidance": g, "id": i}
                 for name, m, g, i in (("best_guidance", 3.0, 0.2, 7), ("knee", 1.0, 0.3, 9))}
    summary = {"solutions": solutions, "seconds": {"command": 30.0}}
    rec = morea_record.record(summary, 2, "p.toml", "default-knee", 31.0, solution="knee")
    assert rec["chosen"] == "knee" and rec["chosen_objectives"]["id"] == 9
    assert morea_record.record(summary, 2, "p.toml", "default", 31.0)["chosen_objectives"]["id"] == 7
