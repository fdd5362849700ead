#!/usr/bin/env python3
"""The phantom (written by `morea phantom -o PHANTOM`) registered from
SimpleITK images: the best-guidance solution applied to the moving image and
masks, its transform written, Dice before and after printed.

Usage: register_sitk.py PHANTOM_DIR OUTPUT_DIR [GENERATIONS]
"""
import pathlib
import sys

import numpy as np
import SimpleITK as sitk

import morea


def dice(a, b):
    a, b = sitk.GetArrayViewFromImage(a) > 0, sitk.GetArrayViewFromImage(b) > 0
    return 2.0 * np.logical_and(a, b).sum() / max(1, a.sum() + b.sum())


def main(phantom, output, generations=100):
    phantom, output = pathlib.Path(phantom), pathlib.Path(output)
    output.mkdir(parents=True, exist_ok=True)
    read = lambda path: sitk.ReadImage(str(phantom / path))  # noqa: E731
    fixed, moving = read("fixed.nii.gz"), read("moving.nii.gz")
    names = ("bladder", "rectum", "bones")
    masks = {n: (read(f"fixed_masks/{n}.nii.gz"), read(f"moving_masks/{n}.nii.gz")) for n in names}
    result = morea.register(fixed, moving, structures=masks, seed=1,
                            parameters={"ea_population_size": 48, "ea_num_clusters": 4, "ea_archive_size": 200,
                                        "ea_num_generations": generations, "morea_mesh_num_points": 300,
                                        "morea_sampling_rate": 0.5, "preprocess_isotropic_spacing": 3.0})
    print(result, result.backend_note)
    best = result.solutions[0]
    sitk.WriteTransform(best.fixed_to_moving, str(output / "fixed_to_moving.h5"))
    sitk.WriteImage(best.resample(moving, default_value=-1000), str(output / "warped_moving.nii.gz"))
    for n, (f, m) in masks.items():
        before = sitk.Resample(m, f, sitk.Transform(), sitk.sitkNearestNeighbor)
        print(f"{n:8s} Dice {dice(f, before):.3f} -> {dice(f, best.resample(m)):.3f}")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], *(int(a) for a in sys.argv[3:4]))
