# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the study's tests: the morea binary and small synthetic problems."""
from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from study import common  # noqa: E402

# A fixed point x corresponds to the moving point x + SHIFT_MM (whole voxels of 2 mm).
SPACING = 2.0
SHIFT_VOXELS = (2, -1, 3)           # x, y, z
SHIFT_MM = tuple(SPACING * s for s in SHIFT_VOXELS)
ORIGIN = (-31.0, -27.0, 12.0)


@pytest.fixture(scope="session")
def morea():
    try:
        return common.find_morea(os.environ.get("MOREA"))
    except SystemExit:
        pytest.skip("morea binary not found (set $MOREA)")


def _image(array, sitk):
    img = sitk.GetImageFromArray(array)
    img.SetSpacing((SPACING,) * 3)
    img.SetOrigin(ORIGIN)
    return img


def _scene(shape, centre_vox):
    """A ball (the structure) inside a smooth textured blob, as [z, y, x] arrays."""
    z, y, x = np.meshgrid(*[np.arange(n, dtype=float) for n in shape], indexing="ij")
    cx, cy, cz = centre_vox
    r2 = (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2
    ball = (r2 <= 6.0 ** 2).astype(np.uint8)
    texture = (0.3 * np.exp(-r2 / (2 * 9.0 ** 2))
               + 0.1 * np.sin((x - cx) / 2.5) * np.cos((y - cy) / 3.0) * np.cos((z - cz) / 4.0))
    image = (0.2 + texture + 0.5 * ball).astype(np.float32)
    return image, ball


@pytest.fixture(scope="session")
def translated_problem(tmp_path_factory):
    """A problem folder whose moving image is the fixed one translated by
    SHIFT_MM: moving(x + SHIFT) = fixed(x)."""
    import SimpleITK as sitk
    d = tmp_path_factory.mktemp("translated")
    shape = (36, 34, 32)                       # z, y, x
    centre = (15.0, 16.0, 17.0)                # x, y, z voxel
    fixed, fball = _scene(shape, centre)
    moved_centre = tuple(c + s for c, s in zip(centre, SHIFT_VOXELS))
    moving, mball = _scene(shape, moved_centre)
    (d / "fixed_masks").mkdir()
    (d / "moving_masks").mkdir()
    sitk.WriteImage(_image(fixed, sitk), str(d / "fixed.nii.gz"))
    sitk.WriteImage(_image(moving, sitk), str(d / "moving.nii.gz"))
    sitk.WriteImage(_image(fball, sitk), str(d / "fixed_masks" / "ball.nii.gz"))
    sitk.WriteImage(_image(mball, sitk), str(d / "moving_masks" / "ball.nii.gz"))
    return d


def have_elastix():
    return shutil.which("elastix") is not None and shutil.which("transformix") is not None
