# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Cross-check of `morea evaluate`'s Dice, Hausdorff and 95th-percentile
Hausdorff against pymia (the package the MOREA paper used) on the same masks:
the phantom's structures, unregistered and after a whole-voxel translation
(for which the warped moving mask is exactly the shifted mask)."""
from __future__ import annotations

import numpy as np
import pytest

from study import common, evaluation

pymia_metric = pytest.importorskip("pymia.evaluation.metric")
pymia_evaluator = pytest.importorskip("pymia.evaluation.evaluator")

DICE_TOL = 1e-6
DIST_TOL_MM = 1e-3


@pytest.fixture(scope="module")
def phantom(morea, tmp_path_factory):
    d = tmp_path_factory.mktemp("phantom")
    common.run_command([morea, "phantom", "-o", d / "raw", "--spacing", "3"], d / "phantom.log")
    return d / "raw"


def pymia_scores(reference, prediction):
    """{metric: value} of pymia for two binary SimpleITK masks."""
    metrics = [pymia_metric.DiceCoefficient(),
               pymia_metric.HausdorffDistance(percentile=100, metric="HDRFDST"),
               pymia_metric.HausdorffDistance(percentile=95, metric="HDRFDST95")]
    ev = pymia_evaluator.SegmentationEvaluator(metrics, {1: "s"})
    ev.evaluate(prediction, reference, "case")
    return {r.metric: r.value for r in ev.results}


def shifted(mask, voxels):
    """Mask content moved by whole voxels (x, y, z) with zero fill: the moving
    mask pulled onto the fixed grid by the constant field voxels * spacing."""
    import SimpleITK as sitk
    a = sitk.GetArrayFromImage(mask)
    out = np.zeros_like(a)
    sx, sy, sz = voxels
    src = [slice(max(0, s), a.shape[i] + min(0, s)) for i, s in enumerate((sz, sy, sx))]
    dst = [slice(max(0, -s), a.shape[i] + min(0, -s)) for i, s in enumerate((sz, sy, sx))]
    out[tuple(dst)] = a[tuple(src)]
    img = sitk.GetImageFromArray(out)
    img.CopyInformation(mask)
    return img


def _compare(morea, phantom, tmp_path, voxels, keys):
    import SimpleITK as sitk
    fixed_ref = sitk.ReadImage(str(common.problem_image(phantom, "fixed")))
    field = None
    if any(voxels):
        shape = fixed_ref.GetSize()[::-1] + (3,)
        u = np.array(voxels, dtype=float) * np.array(fixed_ref.GetSpacing())
        field = tmp_path / "shift.nii.gz"
        common.write_field(field, np.broadcast_to(u, shape), fixed_ref)
    ours = evaluation.evaluate(morea, phantom, tmp_path / "scores.json", field, border_margin=0)
    checked = 0
    for name in common.structure_names(phantom):
        fixed = sitk.ReadImage(str(common.mask_path(phantom, "fixed", name))) > 0
        moving = sitk.ReadImage(str(common.mask_path(phantom, "moving", name))) > 0
        warped = shifted(sitk.Cast(moving, sitk.sitkUInt8), voxels)
        if sitk.GetArrayViewFromImage(warped).sum() == 0:
            continue
        ref = sitk.Cast(fixed, sitk.sitkUInt8)
        theirs = pymia_scores(ref, warped)
        s = ours["structures"][name]
        for our_key, their_key, tol in keys:
            assert s[our_key] == pytest.approx(theirs[their_key], abs=tol), (name, our_key)
        checked += 1
    assert checked >= 3


@pytest.mark.parametrize("voxels", [(0, 0, 0), (2, -1, 3)])
def test_dice_and_hausdorff_agree_with_pymia(morea, phantom, tmp_path, voxels):
    _compare(morea, phantom, tmp_path, voxels,
             [("dice", "DICE", DICE_TOL), ("hausdorff_mm", "HDRFDST", DIST_TOL_MM)])


@pytest.mark.parametrize("voxels", [(0, 0, 0), (2, -1, 3)])
def test_hausdorff95_agrees_with_pymia(morea, phantom, tmp_path, voxels):
    _compare(morea, phantom, tmp_path, voxels, [("hausdorff95_mm", "HDRFDST95", DIST_TOL_MM)])
