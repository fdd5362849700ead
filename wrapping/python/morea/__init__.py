# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""MOREA: multi-objective deformable registration of 3D images with large
deformations, on the GPU when one is present.

    import SimpleITK as sitk, morea
    result = morea.register(fixed, moving, structures={"bladder": (fixed_mask, moving_mask)},
                            parameters={"ea_num_generations": 100}, seed=1)
    result.front                        # objective values of every solution found
    best = result.solutions[0]          # the best-guidance solution
    warped = best.resample(moving)      # the moving image on the fixed grid
    sitk.WriteTransform(best.fixed_to_moving, "fixed_to_moving.h5")

Images are SimpleITK images, itk images, morea.Image or 3D numpy arrays.
"""
import os
import sys

from ._images import Image
from ._problem import configured_registration
from ._results import RegistrationResult, Solution
from ._tools import evaluate, phantom, preprocess, read_rtstruct

__all__ = ["register", "preprocess", "evaluate", "phantom", "read_rtstruct", "Image", "RegistrationResult",
           "Solution", "batch"]


def batch(cohort, output=None, **options):
    """Runs a cohort of registrations (a CSV table or a list of dicts, one
    registration per row) on Dask; see morea.cohort.batch for the options."""
    from .cohort import batch as run_batch

    return run_batch(cohort, output, **options)


def _progress_bar(enabled):
    """A per-generation callback drawing a bar (tqdm when installed)."""
    if not enabled:
        return None
    state = {}
    try:
        from tqdm import tqdm
    except ImportError:
        tqdm = None

    def update(generation, total, front, best_guidance):
        if tqdm is not None:
            bar = state.get("bar")
            if bar is None:
                bar = state["bar"] = tqdm(total=total, unit="generation")
            bar.n = generation
            bar.set_postfix(front=front, guidance=f"{best_guidance:.4g}", refresh=False)
            bar.refresh()
            if generation >= total:
                bar.close()
        elif generation % 10 == 0 or generation == total:
            print(f"generation {generation}/{total}: front of {front}, best guidance {best_guidance:.4g}",
                  file=sys.stderr, flush=True)

    return update


def register(fixed, moving, structures=None, points=None, landmarks=None, parameters=None, backend="auto",
             select="best-guidance,knee", seed=None, checkpoint=None, checkpoint_every="30s", resume=False,
             initial_transform=None, progress=True, callback=None):
    """Registers `moving` onto `fixed` with MOREA; returns a RegistrationResult.

    structures: {name: (fixed_mask, moving_mask)}, masks on each image's grid
        (either may be None when `points` gives that side).
    points: {name: (fixed_points, moving_points)}, N x 3 contour points in mm.
    landmarks: (fixed_points, moving_points), corresponding, for evaluation.
    parameters: a TOML parameter file's path, or a dict of its keys.
    backend: "auto" (the GPU when present, else the CPU), "cuda", "cuda-exact", "cpu".
    select: the solutions to rasterise at once (best-guidance, knee,
        weighted:a:b:c, nearest:m:i:g, spread:N, all; comma-separated); any other later
        with result.choose().
    checkpoint: a file to write the optimiser's state to, every
        `checkpoint_every`: a number of generations (10) or a duration ("30s",
        "5min"); `resume` continues from it when it exists.
    initial_transform: a SimpleITK or itk linear transform (fixed -> moving points) used
        instead of the rigid pre-alignment.
    callback: called as callback(generation, total, front_size, best_guidance)
        after each generation; raising from it stops the run.
    Ctrl-C stops after the current generation and raises KeyboardInterrupt.
    """
    registration, fixed_image = configured_registration(fixed, moving, structures, points, landmarks, parameters,
                                                        initial_transform)
    if seed is not None:
        registration.set_parameter("seed", str(int(seed)))
    registration.set_backend(backend)
    registration.set_selection(select)
    if checkpoint is not None:
        registration.set_checkpoint(os.fspath(checkpoint), str(checkpoint_every), bool(resume))
    bar = _progress_bar(progress)

    def on_generation(generation, total, front, best_guidance):
        if bar is not None:
            bar(generation, total, front, best_guidance)
        if callback is not None:
            callback(generation, total, front, best_guidance)

    registration.run(on_generation if (bar or callback) else None)
    return RegistrationResult(registration, fixed_image)
