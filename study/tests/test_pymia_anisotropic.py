# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Cross-check of `morea evaluate`'s surface distances against pymia on irregular
masks with anisotropic voxels. The random smooth blobs, speckle and scattered
voxels hold nearly all of the 256 2x2x2 neighbourhood codes (all ambiguous and
all non-planar ones among them), so a per-code surface area that differs from
pymia's shows in the area-weighted mean surface distance, computed here from
pymia's own surface elements (pymia has no such metric), if not in HD95."""
from __future__ import annotations

import numpy as np
import pytest

from study import evaluation

pymia_metric = pytest.importorskip("pymia.evaluation.metric")
pymia_evaluator = pytest.importorskip("pymia.evaluation.evaluator")

SPACING = (0.8, 1.7, 2.9)           # x, y, z (mm)
ORIGIN = (-12.0, 7.5, 30.0)
SHAPE = (26, 34, 40)                # z, y, x


def _blob(rng, sigma, quantile):
    from scipy import ndimage
    noise = ndimage.gaussian_filter(rng.standard_normal(SHAPE), sigma)
    return (noise > np.quantile(noise, quantile)).astype(np.uint8)


@pytest.fixture(scope="module")
def problem(tmp_path_factory):
    """Fixed and moving masks (pairs of unrelated random shapes) on one anisotropic grid."""
    import SimpleITK as sitk
    rng = np.random.default_rng(20240611)
    d = tmp_path_factory.mktemp("anisotropic")
    (d / "fixed_masks").mkdir()
    (d / "moving_masks").mkdir()

    def write(array, path):
        img = sitk.GetImageFromArray(array)
        img.SetSpacing(SPACING)
        img.SetOrigin(ORIGIN)
        sitk.WriteImage(img, str(path))

    write(rng.random(SHAPE).astype(np.float32), d / "fixed.nii.gz")
    write(rng.random(SHAPE).astype(np.float32), d / "moving.nii.gz")
    shapes = {"smooth": (3.0, 0.7), "lumpy": (1.5, 0.6), "speckle": (0.7, 0.8), "sparse": (0.0, 0.97)}
    for name, (sigma, quantile) in shapes.items():
        write(_blob(rng, sigma, quantile), d / "fixed_masks" / f"{name}.nii.gz")
        write(_blob(rng, sigma, quantile), d / "moving_masks" / f"{name}.nii.gz")
    return d, list(shapes)


def test_surface_distances_agree_with_pymia_on_anisotropic_irregular_masks(morea, problem, tmp_path):
    import SimpleITK as sitk
    folder, names = problem
    ours = evaluation.evaluate(morea, folder, tmp_path / "scores.json", border_margin=0)
    for name in names:
        fixed = sitk.ReadImage(str(folder / "fixed_masks" / f"{name}.nii.gz"))
        moving = sitk.ReadImage(str(folder / "moving_masks" / f"{name}.nii.gz"))
        metrics = [pymia_metric.DiceCoefficient(),
                   pymia_metric.HausdorffDistance(percentile=100, metric="HDRFDST"),
                   pymia_metric.HausdorffDistance(percentile=95, metric="HDRFDST95")]
        ev = pymia_evaluator.SegmentationEvaluator(metrics, {1: "s"})
        ev.evaluate(moving, fixed, "case")
        theirs = {r.metric: r.value for r in ev.results}
        # Area-weighted mean over both directions, from pymia's surface elements.
        dist = pymia_metric.Distances(sitk.GetArrayFromImage(moving), sitk.GetArrayFromImage(fixed),
                                      fixed.GetSpacing()[::-1])
        weighted = (np.dot(dist.distances_gt_to_pred, dist.surfel_areas_gt)
                    + np.dot(dist.distances_pred_to_gt, dist.surfel_areas_pred))
        theirs["MSD"] = weighted / (dist.surfel_areas_gt.sum() + dist.surfel_areas_pred.sum())
        s = ours["structures"][name]
        assert s["dice"] == pytest.approx(theirs["DICE"], abs=1e-6), name
        assert s["hausdorff_mm"] == pytest.approx(theirs["HDRFDST"], abs=1e-3), name
        assert s["hausdorff95_mm"] == pytest.approx(theirs["HDRFDST95"], abs=1e-3), name
        assert s["mean_surface_distance_mm"] == pytest.approx(theirs["MSD"], abs=1e-4), name
