# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The registration problems of the study: raw inputs (as `morea` options),
the MOREA parameter file (whose preprocessing keys define the problem every
method is scored on) and the most-deforming structure with the scores that
decide the competitors' best configuration and the statistical tests."""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from . import common

DEFAULT_DATA = common.REPO_ROOT.parent / "shared" / "data"


@dataclass
class Criterion:
    column: str          # column of results.csv
    higher_is_better: bool
    label: str


@dataclass
class Pair:
    name: str
    description: str
    morea_parameters: Path
    primary_structure: str
    criteria: list[Criterion]             # the first decides the best configuration
    raw_args: list[str] = field(default_factory=list)   # filled by resolve()
    needs_data: bool = True
    # A case of `morea phantom` (the phantom suite), written under out/raw.
    phantom_case: str | None = None
    # MOREA configurations: name -> extra `morea register` arguments. "default"
    # is the one the tests compare; the others are reported beside it.
    morea_variants: dict[str, list[str]] = field(default_factory=lambda: {"default": []})
    # Score the landmarks per kind (phantom.json's landmark_kinds).
    landmarks_by_kind: bool = False
    # MOREA at the paper's configuration: it runs on a GPU
    # (bench/run-study-morea.sh), not in `study run` (unless --local-morea).
    morea_on_gpu: bool = False
    # The data pair whose images it registers (lung, abdomen), or "".
    data_pair: str = ""


# The phantom suite at the paper's MOREA configuration (the GPU runs MOREA):
# pair name -> (`morea phantom --case`, its most-deforming structure, what happens).
PHANTOM_SUITE = {
    "phantom-pelvis": ("pelvis", "bladder", "the bladder fills, the table moves"),
    "phantom-emptying": ("bladder-emptying", "bladder",
                         "the full bladder empties (ratio 11), the bowel descends"),
    "phantom-gas": ("gas-pocket", "rectum", "a gas pocket in the moving rectum only"),
    "phantom-static": ("static-bones", "bladder", "the bladder fills, the bones do not move"),
}
# Guidance without bones: every structure but bones and the body outline.
NO_BONE_GUIDANCE = "bladder,rectum,bowel"
# The data pairs at the paper's budgets: the same problems (3 mm) as "lung" and
# "abdomen", MOREA at the paper's configuration on a GPU, the competitors'
# paper profile.
PAPER_BUDGET = {"lung-paper": "lung", "abdomen-paper": "abdomen"}
NAMES = ["lung", "abdomen", "phantom", *PHANTOM_SUITE, *PAPER_BUDGET]


def data_dir(explicit: str | None = None) -> Path:
    return Path(explicit or os.environ.get("MOREA_SHARED_DATA_DIR") or DEFAULT_DATA)


def make(name: str, quick: bool) -> Pair:
    P = common.PARAMS_DIR
    if name in PAPER_BUDGET:
        pair = make(PAPER_BUDGET[name], quick)
        pair.name = name
        pair.description += ", at the paper's budgets (MOREA's paper configuration on a GPU)"
        pair.morea_parameters = P / f"morea_{pair.data_pair}_paper.toml"
        pair.morea_on_gpu = True
        # Beside the paper's configuration, never instead of it: adaptive
        # steering that keeps guidance within 1.1x the best rather than 1.5x
        # (bench/results/comparison-paper-budgets.md).
        steering = ["--set", "ea_adaptive_steering_guidance_threshold=1.1"]
        pair.morea_variants = {"default": [], "steering-1.1": steering}
        if pair.data_pair == "lung":
            # Steering cuts the front where ANTs's map lies in MOREA's
            # objective space (bench/results/comparison-paper-budgets.md).
            pair.morea_variants["no-steering"] = ["--set", "ea_adaptive_steering_enabled=false"]
        if pair.data_pair == "abdomen":
            # 500 generations are not converged on this pair
            # (bench/results/generation-budget.md).
            longer = ["--set", "ea_num_generations=1000"]
            pair.morea_variants.update({"1000-generations": longer, "1000-generations-steering-1.1": longer + steering})
        return pair
    if name == "lung":
        return Pair("lung", "lung CT pair (fixed baseline, moving followup; 51 landmark pairs)",
                    P / "morea_lung.toml", "lungs",
                    [Criterion("tre_mean_mm", False, "TRE mean (mm)"),
                     Criterion("dice:lungs", True, "lungs Dice"),
                     Criterion("hd95:lungs", False, "lungs HD95 (mm)")], data_pair="lung")
    if name == "abdomen":
        s = "Stomach_duo_CBCT"
        return Pair("abdomen", "abdominal CBCT pair (fixed CB02, moving CB07)",
                    P / "morea_abdomen.toml", s,
                    [Criterion(f"dice:{s}", True, "stomach Dice"),
                     Criterion(f"hd95:{s}", False, "stomach HD95 (mm)")], data_pair="abdomen")
    if name == "phantom":
        return Pair("phantom", "synthetic pelvis phantom (bladder filling), `morea phantom`",
                    P / ("morea_phantom_quick.toml" if quick else "morea_phantom.toml"), "bladder",
                    [Criterion("dice:bladder", True, "bladder Dice"),
                     Criterion("hd95:bladder", False, "bladder HD95 (mm)")],
                    needs_data=False)
    if name in PHANTOM_SUITE:
        case, organ, what = PHANTOM_SUITE[name]
        criteria = [Criterion("tre_mean_mm", False, "TRE mean (mm), all landmarks"),
                    Criterion(f"dice:{organ}", True, f"{organ} Dice"),
                    Criterion("tre_mean_mm:bone", False, "bone TRE mean (mm)"),
                    Criterion(f"hd95:{organ}", False, f"{organ} HD95 (mm)")]
        if organ != "bladder":
            criteria.insert(2, Criterion("dice:bladder", True, "bladder Dice"))
        return Pair(name, f"phantom suite, `morea phantom --case {case}` ({what})",
                    P / f"morea_{name.replace('-', '_')}.toml", organ, criteria,
                    needs_data=False, phantom_case=case, landmarks_by_kind=True, morea_on_gpu=True,
                    morea_variants={"default": [], "no-bone-guidance": [
                        "--set", f"problem_guidance_selection={NO_BONE_GUIDANCE}"]})
    raise SystemExit(f"unknown pair {name!r} ({', '.join(NAMES)})")


def resolve(pair: Pair, data: Path, out: Path, morea: str) -> None:
    """Fills pair.raw_args; for the phantom writes the raw pair under out/raw."""
    if pair.data_pair == "lung":
        d = data / "lung-ct-pair"
        _require(d)
        pair.raw_args = [
            "--fixed", str(d / "baseline.mha"), "--moving", str(d / "followup.mha"),
            "--fixed-structure", f"lungs={d / 'baseline_lung_mask.mha'}",
            "--moving-structure", f"lungs={d / 'followup_lung_mask.mha'}",
            "--fixed-landmarks", str(d / "baseline_landmarks51_mm.txt"),
            "--moving-landmarks", str(d / "followup_landmarks51_mm.txt")]
    elif pair.data_pair == "abdomen":
        d = data / "abdomen-cbct-pair"
        _require(d)
        args = ["--fixed", str(d / "CB02.mha"), "--moving", str(d / "CB07.mha")]
        for s in ("Stomach_duo_CBCT", "Bowel_sm_CBCT"):
            args += ["--fixed-structure", f"{s}={d / 'CB02_labels.mha'}:{s}",
                     "--moving-structure", f"{s}={d / 'CB07_masks' / (s + '.mha')}"]
        pair.raw_args = args
    else:
        raw = out / "raw"
        if not (raw / "phantom.json").exists():
            common.run_command([morea, "phantom", *phantom_arguments(pair), "-o", raw],
                               out / "logs" / "phantom.log")
        pair.raw_args = ["--problem", str(raw)]


def phantom_arguments(pair: Pair) -> list[str]:
    """`morea phantom` options of a phantom pair (spacing, noise and seed: the
    tool's defaults, 2 mm, 15 HU, seed 1, so that the GPU machine writes the same
    images again; the study's voxel size is its parameter file's)."""
    return ["--case", pair.phantom_case] if pair.phantom_case else []


def _require(d: Path) -> None:
    if not d.is_dir():
        raise FileNotFoundError(f"{d} not found (pass --data DIR or set MOREA_SHARED_DATA_DIR)")
