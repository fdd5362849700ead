# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""MOREA in the study: `morea register` on the raw problem with a study
parameter file and a seed. `morea register` preprocesses with the same keys as
`morea preprocess` did for the study's problem folder, so its fields lie on the
same grid (checked here). The chosen solution is the one `morea register`
selects as best guidance (the archive's solution with the lowest guidance
objective: the best contour match), and its fields are copied as the run's
fixed_to_moving / moving_to_fixed.
"""
from __future__ import annotations

import shutil
import time
from pathlib import Path

from . import common

CHOSEN = "best_guidance"


def run(morea: str, raw_args: list[str], parameters: Path, problem: Path, out_dir: Path,
        seed: int, threads: int = 2) -> dict:
    import SimpleITK as sitk
    out_dir.mkdir(parents=True, exist_ok=True)
    reg = out_dir / "register"
    log = out_dir / "morea.log"
    if log.exists():
        log.unlink()
    start = time.perf_counter()
    seconds = common.run_command(
        [morea, "register", *raw_args, "--parameters", parameters, "--set", f"seed={seed}",
         "--select", "best-guidance,knee", "--checkpoint-every", "0", "--threads", str(threads),
         "-o", reg], log)
    summary = common.read_json(reg / "summary.json")
    sol = reg / CHOSEN
    for name, role in (("fixed_to_moving", "fixed"), ("moving_to_fixed", "moving")):
        src = sol / f"preprocessed_{name}.nii.gz"
        arr, img = common.read_field(src)
        ref = sitk.ReadImage(str(common.problem_image(problem, role)))
        if not common.same_grid(img, ref):
            raise RuntimeError(f"{src} is not on the study problem's {role} grid: "
                               "the study's preprocessing and morea register's differ")
        shutil.copyfile(src, out_dir / f"{name}.nii.gz")
    for p in (reg / "checkpoint.bin",):
        if p.exists():
            p.unlink()
    chosen = summary["solutions"][CHOSEN]
    record = {
        "method": "morea", "seed": seed, "parameters": str(parameters), "chosen": CHOSEN,
        "chosen_objectives": {k: chosen[k] for k in ("magnitude", "intensity", "guidance", "id")},
        "front_size": summary.get("front_size"), "generations": summary.get("generations"),
        "backend": summary.get("backend"),
        "seconds": {"registration": seconds, "total": time.perf_counter() - start,
                    **{f"morea_{k}": v for k, v in summary.get("seconds", {}).items()}},
    }
    common.write_json(out_dir / "run.json", record)
    return record
