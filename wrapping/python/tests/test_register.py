# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""morea.register on the pelvis phantom (written by `morea phantom`, MOREA_BIN)."""
import csv
import os
import pathlib
import subprocess

import numpy as np
import pytest
import SimpleITK as sitk
from conftest import STRUCTURES, TINY, dice

import morea


def test_simpleitk_images_give_the_front_of_morea_register(phantom, tmp_path):
    generations = []
    result = morea.register(phantom["fixed"], phantom["moving"], structures=phantom["masks"], parameters=TINY,
                            backend="cpu", select="best-guidance,knee", seed=4, progress=False,
                            callback=lambda g, total, front, best: generations.append(g))
    assert generations == [1, 2, 3, 4, 5]
    assert result.backend == "cpu"
    assert len(result.front) > 1
    assert np.all(np.diff(result.front["guidance"]) >= 0)
    assert [s.label for s in result.solutions] == ["best_guidance", "knee"]
    assert result.solutions[0].index == int(np.argmin(result.front["guidance"]))

    # The same parameters, seed and backend through the command line: the same front.
    toml = tmp_path / "parameters.toml"
    toml.write_text("".join(f"{k} = {v}\n" for k, v in {**TINY, "seed": 4}.items()))
    cli = tmp_path / "cli"
    command = [os.environ["MOREA_BIN"], "register", "--parameters", str(toml), "--backend", "cpu", "-o", str(cli),
               "--fixed", str(phantom["folder"] / "fixed.nii.gz"), "--moving", str(phantom["folder"] / "moving.nii.gz")]
    for s in STRUCTURES:
        command += ["--fixed-structure", f"{s}={phantom['folder'] / 'fixed_masks' / (s + '.nii.gz')}",
                    "--moving-structure", f"{s}={phantom['folder'] / 'moving_masks' / (s + '.nii.gz')}"]
    subprocess.run(command, check=True, capture_output=True)
    with open(cli / "front.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["id"]) for r in rows] == [int(i) for i in result.front["id"]]
    for name in ("magnitude", "intensity", "guidance"):
        np.testing.assert_allclose([float(r[name]) for r in rows], result.front[name], rtol=1e-8)

    # The transforms map the original images: the moving bones land on the fixed bones.
    best = result.solutions[0]
    fixed_bones, moving_bones = phantom["masks"]["bones"]
    warped = best.resample(moving_bones)
    assert warped.GetSize() == phantom["fixed"].GetSize()
    identity = sitk.Resample(moving_bones, phantom["fixed"], sitk.Transform(), sitk.sitkNearestNeighbor)
    assert dice(fixed_bones, warped) > dice(fixed_bones, identity) + 0.2
    path = str(tmp_path / "fixed_to_moving.h5")
    sitk.WriteTransform(best.fixed_to_moving, path)
    again = sitk.Resample(moving_bones, phantom["fixed"], sitk.ReadTransform(path), sitk.sitkNearestNeighbor)
    assert dice(warped, again) == 1.0
    # The inverse maps back: a fixed point through both returns within a voxel.
    p = (10.0, -20.0, 5.0)
    back = best.moving_to_fixed.TransformPoint(best.fixed_to_moving.TransformPoint(p))
    assert np.linalg.norm(np.subtract(back, p)) < 3.0


def test_numpy_arrays_integer_pixels_and_a_rotated_frame(phantom):
    # The same anatomy in int16 arrays, seen through a direction that swaps x and y.
    def rotated(image, cast=None):
        if cast is not None:
            image = sitk.Cast(image, cast)
        array = sitk.GetArrayFromImage(image)
        return morea.Image(array, image.GetSpacing(), image.GetOrigin(), (0, 1, 0, 1, 0, 0, 0, 0, -1))
    result = morea.register(rotated(phantom["fixed"], sitk.sitkInt16), rotated(phantom["moving"], sitk.sitkInt16),
                            structures={s: (rotated(f), rotated(m)) for s, (f, m) in phantom["masks"].items()},
                            parameters=TINY, backend="cpu", select="knee", seed=2, progress=False)
    assert len(result.front) > 1
    fixed_to_moving, moving_to_fixed = result.solutions[0].fields()
    array, spacing, origin, direction = fixed_to_moving
    assert array.ndim == 4 and array.shape[3] == 3
    d = np.reshape(direction, (3, 3))
    np.testing.assert_allclose(d @ d.T, np.eye(3), atol=1e-9)
    # In the rotated frame too the moving bones land on the fixed bones.
    def as_sitk(image):
        out = sitk.GetImageFromArray(image.array)
        out.SetSpacing(image.spacing)
        out.SetOrigin(image.origin)
        out.SetDirection(image.direction)
        return out
    fixed_bones, moving_bones = (as_sitk(rotated(m)) for m in phantom["masks"]["bones"])
    warped = result.solutions[0].resample(moving_bones)
    identity = sitk.Resample(moving_bones, fixed_bones, sitk.Transform(), sitk.sitkNearestNeighbor)
    assert dice(fixed_bones, warped) > dice(fixed_bones, identity) + 0.2
    # Any solution on demand.
    chosen = result.choose(weights=(1, 1, 1))
    assert 0 <= chosen.index < len(result.front)
    assert chosen.fields()[0][0].shape == array.shape


def test_errors_are_python_exceptions(phantom):
    fixed, moving = phantom["fixed"], phantom["moving"]
    with pytest.raises(ValueError, match="unknown backend"):
        morea.register(fixed, moving, backend="gpu", progress=False)
    with pytest.raises(ValueError, match="no_such_key"):
        morea.register(fixed, moving, parameters={"no_such_key": 1}, progress=False)
    with pytest.raises(ValueError, match="3D"):
        morea.register(np.zeros((4, 4)), moving, progress=False)
    with pytest.raises(RuntimeError, match="rectum"):
        morea.register(fixed, moving, structures={"rectum": (phantom["masks"]["rectum"][0], None)},
                       parameters={**TINY, "preprocess_rigid_structure": "none"}, backend="cpu", progress=False)
    with pytest.raises(ValueError, match="empty"):
        morea.register(fixed, moving, points={"rectum": (np.zeros((0, 3)), None)}, progress=False)
    with pytest.raises(ValueError, match=r"checkpoint interval '10h': expected a number of generations \(10\), a dur"):
        morea.register(fixed, moving, checkpoint="never-written.bin", checkpoint_every="10h", progress=False)
    # A mask on another grid than its image, and a guidance structure that is not given.
    small = sitk.Image([5, 5, 5], sitk.sitkUInt8)
    with pytest.raises(RuntimeError, match="^structure 'bladder': the fixed mask is not on the image grid"):
        morea.register(fixed, moving, structures={"bladder": (small, phantom["masks"]["bladder"][1])},
                       parameters=TINY, backend="cpu", progress=False)
    with pytest.raises(RuntimeError, match="liver"):
        morea.register(fixed, moving, structures=phantom["masks"], backend="cpu", progress=False,
                       parameters={**TINY, "problem_guidance_selection": "liver"})


def test_a_callback_that_raises_stops_the_run_after_its_generation(phantom):
    seen = []

    def stop(generation, total, front, best):
        seen.append(generation)
        if generation == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        morea.register(phantom["fixed"], phantom["moving"], structures=phantom["masks"], parameters=TINY,
                       backend="cpu", seed=1, progress=False, callback=stop)
    assert seen == [1, 2]
