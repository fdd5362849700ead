# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The pelvis phantom (written by `morea phantom`, MOREA_BIN) shared by the tests."""
import os
import subprocess

import numpy as np
import pytest
import SimpleITK as sitk

TINY = {"ea_population_size": 12, "ea_num_clusters": 2, "ea_archive_size": 30, "morea_mesh_num_points": 80,
        "morea_sampling_rate": 0.2, "preprocess_isotropic_spacing": 4.0,
        "ea_adaptive_steering_activated_at_num_generations": 3, "ea_num_generations": 5}
STRUCTURES = ("bladder", "bones", "rectum")


@pytest.fixture(scope="session")
def phantom(tmp_path_factory):
    folder = tmp_path_factory.mktemp("phantom")
    subprocess.run([os.environ["MOREA_BIN"], "phantom", "--spacing", "3", "-o", str(folder)], check=True,
                   capture_output=True)
    read = lambda name: sitk.ReadImage(str(folder / name))  # noqa: E731
    return {"folder": folder, "fixed": read("fixed.nii.gz"), "moving": read("moving.nii.gz"),
            "masks": {s: (read(f"fixed_masks/{s}.nii.gz"), read(f"moving_masks/{s}.nii.gz")) for s in STRUCTURES}}


def dice(a, b):
    """Dice of two masks (SimpleITK images or arrays)."""
    view = lambda m: sitk.GetArrayViewFromImage(m) if isinstance(m, sitk.Image) else np.asarray(m)  # noqa: E731
    a, b = view(a) > 0, view(b) > 0
    return 2.0 * np.logical_and(a, b).sum() / (a.sum() + b.sum())
