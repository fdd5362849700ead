# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""What a RegistrationResult gives: saved folders, scores, transforms for
SimpleITK and itk, and the steps around a registration."""
import json
import os
import signal
import subprocess
import sys

import numpy as np
import pytest
import SimpleITK as sitk
from conftest import TINY, dice

import morea


@pytest.fixture(scope="module")
def result(phantom):
    return morea.register(phantom["fixed"], phantom["moving"], structures=phantom["masks"], parameters=TINY,
                          backend="cpu", select="best-guidance,knee", seed=3, progress=False)


def test_save_writes_the_folder_of_morea_register_with_any_solution(result, tmp_path):
    extra = result.choose(weights=(1, 1, 1))
    summary = result.save(tmp_path / "run", solutions=result.solutions + [extra])
    run = tmp_path / "run"
    for name in ("summary.json", "front.csv", "front.json", "generations.csv", "parameters.toml",
                 "rigid_fixed_to_moving.tfm"):
        assert (run / name).is_file(), name
    for label in ("best_guidance", "knee", "weighted"):
        for name in ("fixed_to_moving.h5", "moving_to_fixed.h5", "preprocessed_fixed_to_moving.nii.gz",
                     "mesh_fixed.vtu", "scores.json"):
            assert (run / label / name).is_file(), f"{label}/{name}"
    assert json.loads((run / "summary.json").read_text()) == summary
    assert summary["front_size"] == len(result.front)
    # The scores written are the solution's scores.
    knee = result.solutions[1]
    for name, scores in summary["solutions"]["knee"]["scores"]["structures"].items():
        assert scores["dice"] == pytest.approx(knee.scores["structures"][name]["dice"], abs=1e-12)
    # Saving again with fewer solutions leaves none of the earlier ones behind.
    result.save(run, solutions=[knee])
    assert not (run / "weighted").exists() and not (run / "best_guidance").exists()
    # The transform written is the one the solution gives.
    written = sitk.ReadTransform(str(run / "knee" / "fixed_to_moving.h5"))
    p = (5.0, -12.0, 20.0)
    assert np.allclose(written.TransformPoint(p), knee.fixed_to_moving.TransformPoint(p), atol=1e-6)
    with pytest.raises(ValueError, match="label"):
        result.save(tmp_path / "twice", solutions=[knee, knee])
    # choose() gives one solution; a selection of several is refused, not cut short.
    assert result.choose(selection="spread:1").index == result.solutions[0].index
    if len(result.front) > 1:
        with pytest.raises(ValueError, match="spread:2"):
            result.choose(selection="spread:2")


def test_resampling_through_the_transforms_reproduces_the_reported_dice(phantom, result):
    """The Dice morea.evaluate reports for a returned transform on the
    original images is the Dice of the moving masks resampled through it."""
    best = result.solutions[0]
    reported = morea.evaluate(phantom["fixed"], phantom["moving"], phantom["masks"],
                              fixed_to_moving=best.fixed_to_moving, border_margin=0)
    for name, (fixed_mask, moving_mask) in phantom["masks"].items():
        resampled = dice(fixed_mask, best.resample(moving_mask))
        # Up to voxels on the boundary, which the two resample differently
        # (a small structure such as the rectum moves by 0.011).
        assert resampled == pytest.approx(reported["structures"][name]["dice"], abs=0.02), name


def test_evaluate_and_phantom_agree_with_the_known_truth():
    case = morea.phantom(spacing=4.0, seed=2)
    assert set(case["structures"]) >= {"bladder", "bones", "rectum"}
    fixed, moving = case["fixed"], case["moving"]
    before = morea.evaluate(fixed, moving, case["structures"], case["landmarks"])
    truth = sitk.DisplacementFieldTransform(sitk.Image(case["true_fixed_to_moving"]))
    after = morea.evaluate(fixed, moving, case["structures"], case["landmarks"], fixed_to_moving=truth)
    assert before["structures"]["bladder"]["dice"] < 0.5
    assert after["structures"]["bladder"]["dice"] > 0.95
    assert after["landmarks"]["tre_mean_mm"] < 0.5 < before["landmarks"]["tre_mean_mm"]
    assert after["jacobian_nonpositive_fraction"] == 0.0
    # As numpy: the same images as morea.Image.
    as_numpy = morea.phantom(spacing=4.0, seed=2, output="numpy")
    np.testing.assert_array_equal(as_numpy["fixed"].array, sitk.GetArrayViewFromImage(fixed))
    with pytest.raises(ValueError, match="output"):
        morea.phantom(spacing=4.0, output="vtk")


def test_preprocess_reports_the_grid_and_the_pre_alignment(phantom):
    prepared = morea.preprocess(phantom["fixed"], phantom["moving"], structures=phantom["masks"],
                                parameters={"preprocess_isotropic_spacing": 4.0})
    report = prepared["report"]
    assert report["crop_structure"] == "bladder" and report["spacing"] == 4.0
    assert list(prepared["fixed"].GetSize()) == report["size"] == list(prepared["moving"].GetSize())
    matrix = np.reshape(prepared["pre_alignment"][0], (3, 3))
    np.testing.assert_allclose(matrix @ matrix.T, np.eye(3), atol=1e-6)  # rigid on the bones
    f, m = prepared["structures"]["bones"]
    assert dice(f, m) > 0.75  # pre-aligned


def test_read_rtstruct_of_a_missing_file_is_an_error(phantom, tmp_path):
    with pytest.raises(ValueError, match="nothing.dcm"):
        morea.read_rtstruct(tmp_path / "nothing.dcm", phantom["fixed"])


def test_itk_images_and_transforms(phantom, result):
    itk = pytest.importorskip("itk")
    best = result.solutions[0]
    to_itk = lambda image: itk.image_from_array(sitk.GetArrayFromImage(image))  # noqa: E731
    moving_bones = to_itk(phantom["masks"]["bones"][1])
    for image, source in ((moving_bones, phantom["masks"]["bones"][1]),):
        image.SetSpacing(source.GetSpacing())
        image.SetOrigin(source.GetOrigin())
    warped = best.resample(moving_bones)
    assert type(warped).__module__.startswith("itk")
    expected = best.resample(phantom["masks"]["bones"][1])
    assert dice(itk.array_view_from_image(warped), expected) > 0.99
    transform = best.transform("fixed_to_moving", library="itk")
    for p in ((5.0, -12.0, 20.0), (-30.0, 4.0, -8.0)):
        np.testing.assert_allclose(transform.TransformPoint(p), best.fixed_to_moving.TransformPoint(p), atol=1e-6)
    inverse = best.transform("moving_to_fixed", library="itk")
    p = (5.0, -12.0, 20.0)
    np.testing.assert_allclose(inverse.TransformPoint(p), best.moving_to_fixed.TransformPoint(p), atol=1e-6)


def flipped(image, library):
    """The same physical image with its x axis stored the other way (direction -1 on x)."""
    array = sitk.GetArrayFromImage(image)[:, :, ::-1].copy()
    origin = image.TransformIndexToPhysicalPoint((image.GetSize()[0] - 1, 0, 0))
    direction = (-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    if library == "sitk":
        out = sitk.GetImageFromArray(array)
        out.SetSpacing(image.GetSpacing())
        out.SetOrigin(origin)
        out.SetDirection(direction)
        return out
    import itk

    out = itk.image_from_array(array)
    out.SetSpacing(image.GetSpacing())
    out.SetOrigin(origin)
    out.SetDirection(itk.matrix_from_array(np.reshape(direction, (3, 3))))
    return out


@pytest.mark.parametrize("library", ["sitk", "itk"])
def test_a_flipped_direction_gives_the_dice_of_the_identity_direction(phantom, result, library):
    if library == "itk":
        pytest.importorskip("itk")
    masks = {s: (flipped(f, library), flipped(m, library)) for s, (f, m) in phantom["masks"].items()}
    again = morea.register(flipped(phantom["fixed"], library), flipped(phantom["moving"], library), structures=masks,
                           parameters=TINY, backend="cpu", select="best-guidance,knee", seed=3, progress=False)
    for name in ("bladder", "bones", "rectum"):
        assert again.solutions[0].scores["structures"][name]["dice"] == pytest.approx(
            result.solutions[0].scores["structures"][name]["dice"], abs=1e-6), name


CTRL_C_SCRIPT = """
import sys, SimpleITK as sitk, morea
folder = sys.argv[1]
read = lambda name: sitk.ReadImage(folder + "/" + name)
masks = {s: (read(f"fixed_masks/{s}.nii.gz"), read(f"moving_masks/{s}.nii.gz")) for s in ("bladder", "bones")}
def report(generation, total, front, best):
    print("generation", generation, flush=True)
try:
    morea.register(read("fixed.nii.gz"), read("moving.nii.gz"), structures=masks, backend="cpu", progress=False,
                   parameters={**%r, "ea_num_generations": 400}, checkpoint=sys.argv[2], checkpoint_every=1,
                   callback=report)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    sys.exit(3)
"""


def test_ctrl_c_stops_after_the_current_generation(phantom, tmp_path):
    checkpoint = tmp_path / "checkpoint.bin"
    child = subprocess.Popen([sys.executable, "-c", CTRL_C_SCRIPT % (TINY,), str(phantom["folder"]), str(checkpoint)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ)
    lines = []
    for line in child.stdout:
        lines.append(line.strip())
        if line.startswith("generation 2"):
            child.send_signal(signal.SIGINT)
            break
    rest, err = child.communicate(timeout=120)
    lines += rest.split()
    assert child.returncode == 3, err
    generations = [line for line in lines if line.startswith("generation")]
    assert "interrupted" in rest
    assert len(generations) < 400
    # A whole checkpoint of a finished generation, no partial file.
    assert checkpoint.is_file()
    assert not [p for p in tmp_path.iterdir() if p.name != "checkpoint.bin"]
