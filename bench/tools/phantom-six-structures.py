#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""A problem folder with six guidance structures from the pelvis phantom.

Reads a folder written by `morea phantom` and writes one in the same layout
in which the bones and the bowel are each split in two at their centroid's
x (left and right), so that the guidance has six structures (bladder, rectum,
bones_left, bones_right, bowel_left, bowel_right) besides the body: the
benchmark's many-structure case (bench/filter-benchmark.md).

Usage: phantom-six-structures.py PHANTOM_DIR OUTPUT_DIR   (needs SimpleITK)
"""
import pathlib
import shutil
import sys

import numpy as np
import SimpleITK as sitk


def split(mask):
    """The mask's voxels with physical x below and above its centroid's x."""
    a = sitk.GetArrayViewFromImage(mask)  # z, y, x
    zyx = np.argwhere(a > 0)
    xs = np.array([mask.TransformIndexToPhysicalPoint((int(i), int(j), int(k)))[0] for k, j, i in zyx])
    centre = xs.mean()
    halves = []
    for keep in (xs < centre, xs >= centre):
        out = np.zeros_like(a)
        sel = zyx[keep]
        out[sel[:, 0], sel[:, 1], sel[:, 2]] = 1
        img = sitk.GetImageFromArray(out)
        img.CopyInformation(mask)
        halves.append(img)
    return halves


def main(source, target):
    source, target = pathlib.Path(source), pathlib.Path(target)
    target.mkdir(parents=True, exist_ok=True)
    for name in ("fixed.nii.gz", "moving.nii.gz", "fixed_landmarks.txt", "moving_landmarks.txt"):
        shutil.copy(source / name, target / name)
    for side in ("fixed", "moving"):
        out = target / f"{side}_masks"
        out.mkdir(exist_ok=True)
        for name in ("bladder", "rectum", "body"):
            shutil.copy(source / f"{side}_masks" / f"{name}.nii.gz", out / f"{name}.nii.gz")
        for name in ("bones", "bowel"):
            left, right = split(sitk.ReadImage(str(source / f"{side}_masks" / f"{name}.nii.gz"), sitk.sitkUInt8))
            sitk.WriteImage(left, str(out / f"{name}_left.nii.gz"), True)
            sitk.WriteImage(right, str(out / f"{name}_right.nii.gz"), True)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
