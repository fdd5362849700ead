# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""MOREA in the study: `morea register` on the raw problem with a study
parameter file and a seed. `morea register` preprocesses with the same keys as
`morea preprocess` did for the study's problem folder, starting from the
problem's pre-alignment (`--initial-transform problem/rigid_fixed_to_moving.tfm`,
so that a run elsewhere, bench/run-study-morea.sh, preprocesses identically), so
its fields lie on the same grid (checked here). The chosen solution is the one
`morea register` selects as best guidance (the archive's solution with the
lowest guidance objective: the best contour match), and its fields are copied
as the run's fixed_to_moving / moving_to_fixed; the front as front.csv.
"""
from __future__ import annotations

import shutil
import time
from pathlib import Path

from . import common, morea_record

CHOSEN = morea_record.CHOSEN
SELECT = "best-guidance,knee"
INITIAL_TRANSFORM = "rigid_fixed_to_moving.tfm"


def register_arguments(raw_args: list[str], parameters, seed: int, extra_args: list[str],
                       initial_transform: Path | None, output: Path) -> list[str]:
    """`morea register` arguments of one study run (bench/run-study-morea.sh
    builds the same list)."""
    args = ["register", *raw_args, "--parameters", str(parameters), "--set", f"seed={seed}",
            *extra_args, "--select", SELECT, "--checkpoint-every", "0"]
    if initial_transform is not None:
        args += ["--initial-transform", str(initial_transform)]
    return args + ["-o", str(output)]


def run(morea: str, raw_args: list[str], parameters: Path, problem: Path, out_dir: Path,
        seed: int, threads: int = 2, extra_args: list[str] | None = None,
        config: str = "default") -> dict:
    import SimpleITK as sitk
    out_dir.mkdir(parents=True, exist_ok=True)
    reg = out_dir / "register"
    log = out_dir / "morea.log"
    if log.exists():
        log.unlink()
    initial = problem / INITIAL_TRANSFORM
    start = time.perf_counter()
    seconds = common.run_command(
        [morea, *register_arguments(raw_args, parameters, seed, list(extra_args or []),
                                    initial if initial.exists() else None, reg)[:-2],
         "--threads", str(threads), "-o", reg], log)
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
    if (reg / "front.csv").exists():
        shutil.copyfile(reg / "front.csv", out_dir / "front.csv")
    for p in (reg / "checkpoint.bin",):
        if p.exists():
            p.unlink()
    record = morea_record.record(summary, seed, str(parameters), config, seconds,
                                 time.perf_counter() - start, extra_args=extra_args)
    common.write_json(out_dir / "run.json", record)
    return record
