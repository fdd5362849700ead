# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The competitors' outputs reach `morea evaluate` in its conventions:
fixed_to_moving on the fixed grid maps x to x + u(x); moving_to_fixed on the
moving grid is its inverse. Checked with a known translation, first through
each tool's own transform files, then with real (short) registrations."""
from __future__ import annotations

import json

import numpy as np
import pytest

from study import common, evaluation
from conftest import SHIFT_MM, have_elastix


def _constant_field_check(path, expected, role_ref):
    arr, img = common.read_field(path)
    assert common.same_grid(img, role_ref)
    assert np.allclose(arr.reshape(-1, 3).mean(axis=0), expected, atol=1e-4)
    assert np.abs(arr - np.array(expected)).max() < 1e-3


def _refs(problem):
    import SimpleITK as sitk
    return (sitk.ReadImage(str(problem / "fixed.nii.gz")),
            sitk.ReadImage(str(problem / "moving.nii.gz")))


def test_known_translation_scores_perfectly(morea, translated_problem, tmp_path):
    """Our own constant field of SHIFT_MM aligns the balls (Dice 1, HD 0)."""
    fixed_ref, moving_ref = _refs(translated_problem)
    shape = fixed_ref.GetSize()[::-1] + (3,)
    common.write_field(tmp_path / "f.nii.gz", np.broadcast_to(SHIFT_MM, shape), fixed_ref)
    common.write_field(tmp_path / "g.nii.gz", np.broadcast_to(np.negative(SHIFT_MM), shape), moving_ref)
    base = evaluation.evaluate(morea, translated_problem, tmp_path / "base.json", border_margin=0)
    s = evaluation.evaluate(morea, translated_problem, tmp_path / "s.json", tmp_path / "f.nii.gz",
                            tmp_path / "g.nii.gz", border_margin=0)
    assert base["structures"]["ball"]["dice"] < 0.6
    assert s["structures"]["ball"]["dice"] == pytest.approx(1.0, abs=1e-9)
    assert s["structures"]["ball"]["hausdorff_mm"] == pytest.approx(0.0, abs=1e-9)
    assert s["inverse_consistency"]["max_mm"] < 1e-6
    # The opposite sign is wrong, and scores worse than no registration.
    common.write_field(tmp_path / "w.nii.gz", np.broadcast_to(np.negative(SHIFT_MM), shape), fixed_ref)
    w = evaluation.evaluate(morea, translated_problem, tmp_path / "w.json", tmp_path / "w.nii.gz",
                            border_margin=0)
    assert w["structures"]["ball"]["dice"] < base["structures"]["ball"]["dice"]


def test_invert_field_of_smooth_deformation():
    import SimpleITK as sitk
    ref = sitk.Image(24, 22, 20, sitk.sitkFloat32)
    ref.SetSpacing((2.0, 2.0, 2.0))
    pts = common._grid_points(ref)
    u = np.stack([3.0 * np.sin(pts[..., 1] / 9.0), 2.0 * np.cos(pts[..., 2] / 7.0),
                  1.5 * np.sin(pts[..., 0] / 8.0)], axis=-1)
    v, info = common.invert_field(u, ref, ref)
    # x + v(x) + u(x + v(x)) = x away from the border (where sampling clamps)
    resid = v + common.sample_field(u, ref, pts + v)
    inner = resid[4:-4, 4:-4, 4:-4]
    assert np.abs(inner).max() < 0.05
    assert info["max_change_mm"] < 1e-3


@pytest.mark.skipif(not have_elastix(), reason="elastix/transformix not installed")
def test_elastix_translation_transform_is_fixed_to_moving(translated_problem, tmp_path):
    """A hand-written elastix TranslationTransform of SHIFT_MM comes out of the
    runner's export as fixed_to_moving = SHIFT_MM and moving_to_fixed = -SHIFT_MM."""
    from study import elastix_runner
    fixed_ref, moving_ref = _refs(translated_problem)
    size = " ".join(str(s) for s in fixed_ref.GetSize())
    tp = tmp_path / "TransformParameters.0.txt"
    tp.write_text(f"""(Transform "TranslationTransform")
(NumberOfParameters 3)
(TransformParameters {SHIFT_MM[0]} {SHIFT_MM[1]} {SHIFT_MM[2]})
(InitialTransformParametersFileName "NoInitialTransform")
(HowToCombineTransforms "Compose")
(FixedImageDimension 3)
(MovingImageDimension 3)
(FixedInternalImagePixelType "float")
(MovingInternalImagePixelType "float")
(Size {size})
(Index 0 0 0)
(Spacing {' '.join(map(str, fixed_ref.GetSpacing()))})
(Origin {' '.join(map(str, fixed_ref.GetOrigin()))})
(Direction 1 0 0 0 1 0 0 0 1)
(UseDirectionCosines "true")
(ResampleInterpolator "FinalBSplineInterpolator")
(FinalBSplineInterpolationOrder 3)
(Resampler "DefaultResampler")
(DefaultPixelValue 0)
(ResultImageFormat "nii.gz")
(ResultImagePixelType "float")
""")
    out = tmp_path / "out"
    out.mkdir()
    elastix_runner.export_fields(tp, translated_problem, out, tmp_path, threads=1)
    _constant_field_check(out / "fixed_to_moving.nii.gz", SHIFT_MM, fixed_ref)
    _constant_field_check(out / "moving_to_fixed.nii.gz", np.negative(SHIFT_MM), moving_ref)


def test_ants_translation_transform_is_fixed_to_moving(translated_problem, tmp_path):
    """An ANTs/ITK translation (which maps fixed points to moving points, as
    antsRegistration's forward transforms do) composed by the runner's
    antsApplyTransforms call gives fixed_to_moving = SHIFT_MM; its inverse on the
    moving grid gives -SHIFT_MM."""
    ants = pytest.importorskip("ants")
    from study import ants_runner
    fixed_ref, moving_ref = _refs(translated_problem)
    tx = ants.create_ants_transform(transform_type="AffineTransform", dimension=3,
                                    translation=list(SHIFT_MM))
    mat = tmp_path / "translation.mat"
    ants.write_transform(tx, str(mat))
    _, get_lib_fn = ants_runner._ants(1)
    log = tmp_path / "compose.log"
    ants_runner.compose_field(get_lib_fn, translated_problem / "fixed.nii.gz", [str(mat)],
                              tmp_path / "f.nii.gz", log)
    ants_runner.compose_field(get_lib_fn, translated_problem / "moving.nii.gz", [f"[{mat},1]"],
                              tmp_path / "g.nii.gz", log)
    _constant_field_check(tmp_path / "f.nii.gz", SHIFT_MM, fixed_ref)
    _constant_field_check(tmp_path / "g.nii.gz", np.negative(SHIFT_MM), moving_ref)


def _recovered_shift(run_dir, problem):
    """Mean fixed_to_moving displacement inside the fixed ball."""
    import SimpleITK as sitk
    arr, _ = common.read_field(run_dir / "fixed_to_moving.nii.gz")
    ball = sitk.GetArrayFromImage(sitk.ReadImage(str(problem / "fixed_masks" / "ball.nii.gz"))) > 0
    return arr[ball].mean(axis=0)


@pytest.mark.skipif(not have_elastix(), reason="elastix/transformix not installed")
def test_elastix_registration_recovers_translation(morea, translated_problem, tmp_path):
    from study import elastix_runner
    elastix_runner.run(translated_problem, tmp_path, weight=0.01, seed=1, iterations=60,
                       grid_spacing=16.0, spatial_samples=2000, threads=2,
                       parameter_estimation="DisplacementDistribution")
    shift = _recovered_shift(tmp_path, translated_problem)
    assert np.allclose(shift, SHIFT_MM, atol=1.0), shift
    s = evaluation.evaluate(morea, translated_problem, tmp_path / "s.json",
                            tmp_path / "fixed_to_moving.nii.gz", tmp_path / "moving_to_fixed.nii.gz",
                            border_margin=0)
    assert s["structures"]["ball"]["dice"] > 0.9


def test_ants_registration_recovers_translation(morea, translated_problem, tmp_path):
    pytest.importorskip("ants")
    from study import ants_runner
    ants_runner.run(translated_problem, tmp_path, total_regularization=0.0, seed=1,
                    iterations=(40, 20, 10, 0), cc_radius=2, threads=2)
    shift = _recovered_shift(tmp_path, translated_problem)
    assert np.allclose(shift, SHIFT_MM, atol=1.0), shift
    s = evaluation.evaluate(morea, translated_problem, tmp_path / "s.json",
                            tmp_path / "fixed_to_moving.nii.gz", tmp_path / "moving_to_fixed.nii.gz",
                            border_margin=0)
    assert s["structures"]["ball"]["dice"] > 0.9
    assert s["inverse_consistency"]["mean_mm"] < 0.5
    rec = json.loads((tmp_path / "run.json").read_text())
    assert rec["cc_radius"] == 2 and rec["gradient_step"] == 1.0
    assert rec["update_regularization"] == 4.0
