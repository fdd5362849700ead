# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""A registration problem from Python's images, masks and points, handed to
the filter behind morea._morea.Registration."""
import os

import numpy as np

from ._images import as_intensities, as_mask, as_points
from ._morea import Geometry, Registration


def parameter_text(value):
    """A parameter's value as its TOML file would spell it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ", ".join(str(v) for v in value)
    return str(value)


def geometry(image):
    """The Geometry of a morea.Image (the default one for None)."""
    if image is None:
        return Geometry()
    return Geometry(image.spacing, image.origin, image.direction)


def configured_registration(fixed, moving, structures=None, points=None, landmarks=None, parameters=None,
                            initial_transform=None):
    """A Registration with its inputs set; returns it and the fixed image (a morea.Image)."""
    registration = Registration()
    fixed_image = as_intensities(fixed, "fixed image")
    moving_image = as_intensities(moving, "moving image")
    registration.set_images(fixed_image.array, geometry(fixed_image), moving_image.array, geometry(moving_image))
    for name, pair in (structures or {}).items():
        fixed_mask, moving_mask = pair
        f = as_mask(fixed_mask, f"fixed mask of {name!r}") if fixed_mask is not None else None
        m = as_mask(moving_mask, f"moving mask of {name!r}") if moving_mask is not None else None
        registration.add_structure_masks(name, None if f is None else f.array, geometry(f),
                                         None if m is None else m.array, geometry(m))
    for name, pair in (points or {}).items():
        fixed_points, moving_points = pair
        registration.add_structure_points(name, as_points(fixed_points, f"fixed points of {name!r}"),
                                          as_points(moving_points, f"moving points of {name!r}"))
    if landmarks is not None:
        registration.set_landmarks(as_points(landmarks[0], "fixed landmarks"),
                                   as_points(landmarks[1], "moving landmarks"))
    if isinstance(parameters, (str, os.PathLike)):
        registration.set_parameter_file(os.fspath(parameters))
    elif parameters is not None:
        for key, value in dict(parameters).items():
            registration.set_parameter(key, parameter_text(value))
    if initial_transform is not None:
        set_initial_transform(registration, initial_transform)
    return registration, fixed_image


def set_initial_transform(registration, transform):
    """A SimpleITK or itk linear transform as the matrix and offset of x -> M x + offset."""
    def apply(p):
        return np.asarray(transform.TransformPoint([float(v) for v in p]), dtype=float)

    offset = apply(np.zeros(3))
    matrix = np.column_stack([apply(e) - offset for e in np.eye(3)])
    probe = np.array([3.0, -7.0, 11.0])
    if np.linalg.norm(apply(probe) - (matrix @ probe + offset)) > 1e-6:
        raise ValueError("initial_transform: a linear transform (translation, rigid, similarity, affine) is needed")
    registration.set_initial_transform(matrix.ravel().tolist(), offset.tolist())
