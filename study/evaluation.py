# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The study's one evaluation pipeline: `morea evaluate` on the study's problem
folder for every method, and the flattening of its scores.json into table rows."""
from __future__ import annotations

from pathlib import Path

from . import common


def evaluate(morea: str, problem: Path, out_json: Path, field: Path | None = None,
             inverse: Path | None = None, render: Path | None = None,
             focus: str | None = None, border_margin: float | None = None,
             landmark_sets: dict | None = None) -> dict:
    """`morea evaluate` of a field (None: the identity, the baseline) on the
    problem; with landmark_sets ({kind: (fixed file, moving file)}, the phantom
    suite's landmarks by kind) each set is scored too and its TRE block merged
    into the scores under "landmarks_by_kind" (study.landmark_kinds)."""
    cmd = [morea, "evaluate", "--problem", problem, "-o", out_json]
    if field is not None:
        cmd += ["--field", field]
    if inverse is not None:
        cmd += ["--inverse-field", inverse]
    if border_margin is not None:
        cmd += ["--border-margin", str(border_margin)]
    if render is not None:
        cmd += ["--render", render]
        if focus:
            cmd += ["--focus", focus]
    common.run_command(cmd, out_json.with_suffix(".log"))
    if not landmark_sets:
        return common.read_json(out_json)
    from . import landmark_kinds
    by_kind = {}
    for kind, (fixed_points, moving_points) in landmark_sets.items():
        kind_json = out_json.with_name(f"{out_json.stem}.{kind}.json")
        kind_cmd = [morea, "evaluate", "--problem", problem, "-o", kind_json,
                    "--fixed-landmarks", fixed_points, "--moving-landmarks", moving_points]
        if field is not None:
            kind_cmd += ["--field", field]
        if border_margin is not None:
            kind_cmd += ["--border-margin", str(border_margin)]
        common.run_command(kind_cmd, out_json.with_suffix(".log"))
        by_kind[kind] = common.read_json(kind_json)
        kind_json.unlink()
    merged = landmark_kinds.merge(common.read_json(out_json), by_kind)
    common.write_json(out_json, merged)
    return merged


def flatten(scores: dict) -> dict:
    """scores.json of `morea evaluate` -> flat columns:
    dice:S, hd:S, hd95:S, msd:S per structure, tre_mean_mm, tre_sd_mm, tre_max_mm,
    landmarks, tre_mean_mm:K, tre_max_mm:K, landmarks:K per landmark kind K (phantom
    suite), jacobian_nonpositive_fraction, ic_mean_mm, ic_max_mm."""
    row = {}
    for name, s in sorted(scores.get("structures", {}).items()):
        row[f"dice:{name}"] = s["dice"]
        row[f"hd:{name}"] = s["hausdorff_mm"]
        row[f"hd95:{name}"] = s["hausdorff95_mm"]
        row[f"msd:{name}"] = s["mean_surface_distance_mm"]
    lm = scores.get("landmarks")
    if lm:
        row["tre_mean_mm"] = lm["tre_mean_mm"]
        row["tre_sd_mm"] = lm["tre_sd_mm"]
        row["tre_max_mm"] = lm["tre_max_mm"]
        row["landmarks"] = lm["count"]
    for kind, klm in sorted((scores.get("landmarks_by_kind") or {}).items()):
        row[f"tre_mean_mm:{kind}"] = klm["tre_mean_mm"]
        row[f"tre_max_mm:{kind}"] = klm["tre_max_mm"]
        row[f"landmarks:{kind}"] = klm["count"]
    row["jacobian_nonpositive_fraction"] = scores.get("jacobian_nonpositive_fraction")
    ic = scores.get("inverse_consistency")
    if ic:
        row["ic_mean_mm"] = ic["mean_mm"]
        row["ic_max_mm"] = ic["max_mm"]
    row["border_margin_mm"] = scores.get("border_margin_mm")
    return row
