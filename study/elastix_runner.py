# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""elastix on a preprocessed problem: the paper's unidirectional B-spline
registration (study/params/elastix_bspline.txt), preceded by the same
registration of the composite mask images (appendix C), and conversion of the
result to the fields `morea evaluate` reads.

elastix's transform maps fixed points to moving points, so `transformix -def all`
gives the fixed-to-moving displacement on the fixed grid directly (the composed
mask-step and image-step transforms). The moving-to-fixed field is its numerical
inverse on the moving grid (fixed-point iteration, common.invert_field); the
paper instead fits a second B-spline with the DisplacementMagnitudePenalty
metric. `morea evaluate` uses the inverse only for the inverse-consistency score,
which for elastix therefore measures the numerical inversion.
"""
from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

from . import common

PARAMETER_FILE = common.PARAMS_DIR / "elastix_bspline.txt"
PAPER_ITERATIONS = 10000
PAPER_GRID_SPACING = 2.0
PAPER_SPATIAL_SAMPLES = 20000
PAPER_PARAMETER_ESTIMATION = "Original"


def elastix_binaries() -> tuple[str, str]:
    elastix = shutil.which("elastix")
    transformix = shutil.which("transformix")
    if not elastix or not transformix:
        raise RuntimeError("elastix/transformix not found (Debian package 'elastix')")
    return elastix, transformix


def elastix_version() -> str:
    import subprocess
    elastix, _ = elastix_binaries()
    out = subprocess.run([elastix, "--version"], capture_output=True, text=True).stdout
    return out.strip().splitlines()[0] if out.strip() else "unknown"


def write_parameter_file(path: Path, weight: float, seed: int, iterations: int,
                         grid_spacing: float, spatial_samples: int,
                         parameter_estimation: str = PAPER_PARAMETER_ESTIMATION) -> None:
    text = common.fill_placeholders(PARAMETER_FILE.read_text(), {
        "iterations": iterations, "random_seed": seed,
        "regularization_weight": repr(float(weight)), "grid_spacing": repr(float(grid_spacing)),
        "spatial_samples": spatial_samples, "parameter_estimation": parameter_estimation})
    path.write_text(text)


def export_fields(transform_parameters: Path, problem: Path, out_dir: Path,
                  work: Path, threads: int) -> dict:
    """transformix -def all on the fixed grid -> fixed_to_moving.nii.gz, and its
    numerical inverse on the moving grid -> moving_to_fixed.nii.gz."""
    import SimpleITK as sitk
    _, transformix = elastix_binaries()
    defdir = work / "transformix"
    defdir.mkdir(parents=True, exist_ok=True)
    common.run_command([transformix, "-def", "all", "-tp", transform_parameters, "-out", defdir, "-threads", str(threads)], work / "transformix.log")
    field, field_img = common.read_field(defdir / "deformationField.nii.gz")
    fixed_ref = sitk.ReadImage(str(common.problem_image(problem, "fixed")))
    moving_ref = sitk.ReadImage(str(common.problem_image(problem, "moving")))
    if not common.same_grid(field_img, fixed_ref):
        raise RuntimeError("transformix field is not on the fixed grid")
    common.write_field(out_dir / "fixed_to_moving.nii.gz", field, fixed_ref)
    inverse, info = common.invert_field(field, fixed_ref, moving_ref)
    common.write_field(out_dir / "moving_to_fixed.nii.gz", inverse, moving_ref)
    return {"inversion": info}


def run(problem: Path, out_dir: Path, weight: float, seed: int, iterations: int,
        grid_spacing: float = PAPER_GRID_SPACING, spatial_samples: int = PAPER_SPATIAL_SAMPLES,
        threads: int = 2, composite_masks: bool = True,
        parameter_estimation: str = PAPER_PARAMETER_ESTIMATION) -> dict:
    """One elastix registration; writes out_dir/{fixed_to_moving,moving_to_fixed}.nii.gz
    and returns the run record (times, settings)."""
    elastix, _ = elastix_binaries()
    out_dir.mkdir(parents=True, exist_ok=True)
    work = out_dir / "work"
    if work.exists():
        shutil.rmtree(work)
    work.mkdir()
    params = work / "parameters.txt"
    write_parameter_file(params, weight, seed, iterations, grid_spacing, spatial_samples,
                         parameter_estimation)
    fixed = common.problem_image(problem, "fixed")
    moving = common.problem_image(problem, "moving")
    log = work / "elastix.log"
    start = time.perf_counter()
    initial = []
    seconds_masks = 0.0
    if composite_masks:
        fixed_comp, moving_comp = common.write_composite_masks(problem, work / "composite")
        mask_dir = work / "mask_step"
        mask_dir.mkdir()
        seconds_masks = common.run_command(
            [elastix, "-f", fixed_comp, "-m", moving_comp, "-p", params, "-out", mask_dir,
             "-threads", str(threads)], log)
        initial = ["-t0", mask_dir / "TransformParameters.0.txt"]
    image_dir = work / "image_step"
    image_dir.mkdir()
    seconds_images = common.run_command(
        [elastix, "-f", fixed, "-m", moving, "-p", params, "-out", image_dir,
         "-threads", str(threads)] + initial, log)
    seconds_registration = time.perf_counter() - start
    info = export_fields(image_dir / "TransformParameters.0.txt", problem, out_dir, work, threads)
    record = {
        "method": "elastix", "version": elastix_version(), "regularization_weight": weight,
        "seed": seed, "iterations_per_resolution": iterations, "grid_spacing_mm": grid_spacing,
        "spatial_samples": spatial_samples, "composite_masks": composite_masks,
        "parameter_estimation": parameter_estimation,
        "seconds": {"mask_step": seconds_masks, "image_step": seconds_images,
                    "registration": seconds_registration,
                    "total": time.perf_counter() - start},
        **info,
    }
    common.write_json(out_dir / "run.json", record)
    # The B-spline coefficient files are large; keep only the final transforms.
    for p in work.glob("*/IterationInfo*"):
        p.unlink()
    return record


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--problem", required=True, type=Path)
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--weight", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--iterations", type=int, default=PAPER_ITERATIONS)
    ap.add_argument("--grid-spacing", type=float, default=PAPER_GRID_SPACING)
    ap.add_argument("--samples", type=int, default=PAPER_SPATIAL_SAMPLES)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--parameter-estimation", default=PAPER_PARAMETER_ESTIMATION,
                    choices=["Original", "DisplacementDistribution"])
    ap.add_argument("--no-composite-masks", action="store_true")
    a = ap.parse_args(argv)
    rec = run(a.problem, a.out, a.weight, a.seed, a.iterations, a.grid_spacing, a.samples,
              a.threads, not a.no_composite_masks, a.parameter_estimation)
    print(rec)


if __name__ == "__main__":
    main()
