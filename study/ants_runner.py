# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""ANTs SyN on a preprocessed problem, with the paper's command (appendix C,
"multivariate registration with composite masks"), run through antspyx's
bundled antsRegistration, and conversion of its transforms to the fields
`morea evaluate` reads.

antsRegistration writes 0GenericAffine.mat (the centre-of-mass initialisation
on the composite masks), 1Warp.nii.gz and 1InverseWarp.nii.gz (both on the fixed
grid). The fixed-to-moving field is the composition [1Warp, 0GenericAffine]
resampled on the fixed grid; the moving-to-fixed field is [inverse of
0GenericAffine, 1InverseWarp] on the moving grid. Both are composed by
antsApplyTransforms (`--output [field, 1]`).

Like the paper, the run is made seed-dependent by perturbing the smoothing
sigmas with small deterministic deltas: normal, capped to +-0.1 (level 1,
sigma 3), +-0.05 (sigma 2), +-0.01 (sigma 1); seed 0 means no perturbation.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from . import common

PAPER_ITERATIONS = (2000, 1000, 500, 250)
PAPER_CC_RADIUS = 8
PAPER_GRADIENT_STEP = 1.0
PAPER_UPDATE_REGULARIZATION = 4.0


def sigma_deltas(seed: int) -> tuple[float, float, float]:
    import numpy as np
    if seed == 0:
        return (0.0, 0.0, 0.0)
    rng = np.random.default_rng(seed)
    d3, d2, d1 = rng.normal(0.0, [0.05, 0.025, 0.005])
    return (float(np.clip(d3, -0.1, 0.1)), float(np.clip(d2, -0.05, 0.05)),
            float(np.clip(d1, -0.01, 0.01)))


def registration_arguments(fixed, moving, fixed_comp, moving_comp, prefix: str, seed: int,
                           total_regularization: float, iterations, cc_radius: int,
                           gradient_step: float, update_regularization: float,
                           composite_masks: bool = True) -> list[str]:
    d3, d2, d1 = sigma_deltas(seed)
    levels = "x".join(str(int(i)) for i in iterations)
    shrink = "x".join(str(2 ** k) for k in reversed(range(len(iterations))))
    sigmas_base = [3 + d3, 2 + d2, 1 + d1, 0.0][-len(iterations):] if len(iterations) <= 4 else None
    if sigmas_base is None:
        raise ValueError("at most 4 levels")
    sigmas = "x".join(f"{s:.6f}" for s in sigmas_base) + "vox"
    init_f, init_m = (fixed_comp, moving_comp) if composite_masks else (fixed, moving)
    args = [
        "--verbose", "1",
        "--random-seed", str(seed),
        "--dimensionality", "3",
        "--float", "0",
        "--collapse-output-transforms", "1",
        "--output", f"[{prefix},{prefix}Warped.nii.gz,{prefix}InverseWarped.nii.gz]",
        "--interpolation", "Linear",
        "--use-histogram-matching", "0",
        "--winsorize-image-intensities", "[0.005,0.995]",
        "--initial-moving-transform", f"[{init_f},{init_m},1]",
        "--transform", f"SyN[{gradient_step},{update_regularization},{total_regularization}]",
    ]
    if composite_masks:
        args += ["--metric", f"CC[{fixed_comp},{moving_comp},1,{cc_radius}]"]
    args += [
        "--metric", f"CC[{fixed},{moving},1,{cc_radius}]",
        "--convergence", f"[{levels},1e-6,10]",
        "--shrink-factors", shrink,
        "--smoothing-sigmas", sigmas,
    ]
    return args


def _ants(threads: int):
    os.environ["ITK_GLOBAL_DEFAULT_NUMBER_OF_THREADS"] = str(threads)
    import ants  # noqa: E402  (the thread count must be set first)
    from ants.internal import get_lib_fn
    return ants, get_lib_fn


def ants_version() -> str:
    try:
        from importlib.metadata import version
        return "antspyx " + version("antspyx")
    except Exception:
        return "antspyx unknown"


def iterations_used(log: Path) -> list[int]:
    """Iterations antsRegistration ran per level (its DIAGNOSTIC lines): a level
    ends at its cap or earlier, when the convergence value over the last 10
    iterations falls below 1e-6."""
    used = []
    for line in Path(log).read_text(errors="replace").splitlines():
        if line.startswith("XXDIAGNOSTIC"):
            used.append(0)
        elif used and line.lstrip().startswith("1DIAGNOSTIC"):
            used[-1] += 1
    return used


def compose_field(get_lib_fn, reference: Path, transforms: list[str], output: Path,
                  log: Path) -> None:
    """antsApplyTransforms -r reference -t ... -o [output,1]: the composition as
    one displacement field on the reference grid."""
    args = ["-d", "3", "-r", str(reference), "-o", f"[{output},1]", "--float", "0", "-v", "0"]
    for t in transforms:
        args += ["-t", t]
    with open(log, "a") as f:
        f.write("antsApplyTransforms " + " ".join(args) + "\n")
    status = get_lib_fn("antsApplyTransforms")(args)
    if status not in (0, None) or not output.exists():
        raise RuntimeError(f"antsApplyTransforms failed ({status}): {args}")


def run(problem: Path, out_dir: Path, total_regularization: float, seed: int,
        iterations=PAPER_ITERATIONS, cc_radius: int = PAPER_CC_RADIUS,
        gradient_step: float = PAPER_GRADIENT_STEP,
        update_regularization: float = PAPER_UPDATE_REGULARIZATION,
        threads: int = 2, composite_masks: bool = True) -> dict:
    ants, get_lib_fn = _ants(threads)
    import SimpleITK as sitk
    out_dir.mkdir(parents=True, exist_ok=True)
    work = out_dir / "work"
    work.mkdir(exist_ok=True)
    for p in work.iterdir():
        if p.is_file():
            p.unlink()
    fixed = common.problem_image(problem, "fixed")
    moving = common.problem_image(problem, "moving")
    fixed_comp, moving_comp = common.write_composite_masks(problem, work / "composite")
    prefix = str(work / "syn_")
    args = registration_arguments(fixed, moving, fixed_comp, moving_comp, prefix, seed,
                                  total_regularization, iterations, cc_radius, gradient_step,
                                  update_regularization, composite_masks)
    log = work / "ants.log"
    with open(log, "w") as f:
        f.write("antsRegistration " + " ".join(args) + "\n")
    start = time.perf_counter()
    # antsRegistration prints to the process's stdout: send it to the log.
    sys.stdout.flush()
    saved = os.dup(1)
    with open(log, "a") as f:
        os.dup2(f.fileno(), 1)
        try:
            status = get_lib_fn("antsRegistration")(args)
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)
    seconds_registration = time.perf_counter() - start
    affine, warp, inverse_warp = (Path(prefix + "0GenericAffine.mat"), Path(prefix + "1Warp.nii.gz"),
                                  Path(prefix + "1InverseWarp.nii.gz"))
    if status not in (0, None) or not warp.exists():
        raise RuntimeError(f"antsRegistration failed ({status}); see {log}")
    fwd = out_dir / "fixed_to_moving.nii.gz"
    inv = out_dir / "moving_to_fixed.nii.gz"
    tmp_fwd, tmp_inv = work / "fwd.nii.gz", work / "inv.nii.gz"
    compose_field(get_lib_fn, fixed, [str(warp), str(affine)], tmp_fwd, log)
    compose_field(get_lib_fn, moving, [f"[{affine},1]", str(inverse_warp)], tmp_inv, log)
    # Rewrite through SimpleITK: double vectors on exactly the problem's grids.
    for src, dst, role in ((tmp_fwd, fwd, "fixed"), (tmp_inv, inv, "moving")):
        arr, img = common.read_field(src)
        ref = sitk.ReadImage(str(common.problem_image(problem, role)))
        if not common.same_grid(img, ref):
            raise RuntimeError(f"composed field {src} is not on the {role} grid")
        common.write_field(dst, arr, ref)
    for p in (Path(prefix + "Warped.nii.gz"), Path(prefix + "InverseWarped.nii.gz"), tmp_fwd, tmp_inv):
        if p.exists():
            p.unlink()
    record = {
        "method": "ants", "version": ants_version(), "total_regularization": total_regularization,
        "seed": seed, "iterations": list(iterations), "iterations_used": iterations_used(log),
        "cc_radius": cc_radius,
        "gradient_step": gradient_step, "update_regularization": update_regularization,
        "composite_masks": composite_masks, "sigma_deltas": sigma_deltas(seed),
        "seconds": {"registration": seconds_registration,
                    "total": time.perf_counter() - start},
    }
    common.write_json(out_dir / "run.json", record)
    return record


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--problem", required=True, type=Path)
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--total-regularization", type=float, default=0.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--iterations", default="x".join(map(str, PAPER_ITERATIONS)))
    ap.add_argument("--cc-radius", type=int, default=PAPER_CC_RADIUS)
    ap.add_argument("--gradient-step", type=float, default=PAPER_GRADIENT_STEP)
    ap.add_argument("--update-regularization", type=float, default=PAPER_UPDATE_REGULARIZATION)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--no-composite-masks", action="store_true")
    a = ap.parse_args(argv)
    rec = run(a.problem, a.out, a.total_regularization, a.seed,
              [int(x) for x in a.iterations.split("x")], a.cc_radius, a.gradient_step,
              a.update_regularization, a.threads, not a.no_composite_masks)
    print(rec)


if __name__ == "__main__":
    main()
