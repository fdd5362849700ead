# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The steps around a registration: preprocessing, scoring, the phantom and
RTSTRUCT contours, each on the library's own code."""
import json

import numpy as np

from . import _morea
from ._images import OUTPUTS, Image, as_image, field_to_itk, field_to_sitk, to_output
from ._problem import configured_registration, geometry


def _structures_out(structures, output):
    return {name: (to_output(f, output), to_output(m, output)) for name, (f, m) in structures.items()}


def preprocess(fixed, moving, structures=None, points=None, landmarks=None, parameters=None, output="sitk"):
    """The problem as a registration sees it: both images on one isotropic
    grid in the fixed frame, cropped around the structure that changes most,
    the moving image pre-aligned (rigid on the bones unless the parameters say
    otherwise) and both windowed to [0, 1]. Arguments as for morea.register.

    Returns a dict: "fixed", "moving" (images in the `output` library: "sitk",
    "itk" or "numpy"), "structures" {name: (fixed mask, moving mask)},
    "landmarks" (the moving ones in the fixed frame) when given,
    "pre_alignment" (matrix row-major, offset: preprocessed fixed point ->
    original moving point) and "report" (crop structure, spacing, size,
    structures dropped and why)."""
    registration, _ = configured_registration(fixed, moving, structures, points, landmarks, parameters)
    result = registration.preprocess()
    out = {"fixed": to_output(result["fixed"], output), "moving": to_output(result["moving"], output),
           "structures": _structures_out(result["structures"], output), "pre_alignment": result["pre_alignment"],
           "report": dict(result["report"])}
    if "landmarks" in result:
        out["landmarks"] = tuple(np.asarray(p) for p in result["landmarks"])
    return out


def _field_on(grid, transform, what):
    """A registration given as a transform or a displacement field, as a
    (array (z, y, x, 3), Geometry) field on `grid`."""
    if transform is None:
        return None, geometry(None)
    if hasattr(transform, "fixed_to_moving") and hasattr(transform, "fields"):
        raise TypeError(f"{what}: give solution.fixed_to_moving (a transform), or use solution.scores")
    module = type(transform).__module__
    if module.startswith("SimpleITK") and hasattr(transform, "TransformPoint"):
        import SimpleITK as sitk

        reference = sitk.Image([int(n) for n in grid.array.shape[::-1]], sitk.sitkUInt8)
        reference.SetSpacing(grid.spacing)
        reference.SetOrigin(grid.origin)
        reference.SetDirection(grid.direction)
        field = sitk.TransformToDisplacementField(transform, sitk.sitkVectorFloat64, reference.GetSize(),
                                                  reference.GetOrigin(), reference.GetSpacing(),
                                                  reference.GetDirection())
        return sitk.GetArrayFromImage(field), geometry(grid)
    if module.startswith("itk") and hasattr(transform, "TransformPoint"):
        import itk

        vector_image = itk.Image[itk.Vector[itk.D, 3], 3]
        source = itk.TransformToDisplacementFieldFilter[vector_image, itk.D].New()
        source.SetTransform(transform)
        source.SetSize([int(n) for n in grid.array.shape[::-1]])
        source.SetOutputSpacing(grid.spacing)
        source.SetOutputOrigin(grid.origin)
        source.SetOutputDirection(itk.matrix_from_array(np.reshape(grid.direction, (3, 3))))
        source.Update()
        return np.array(itk.array_view_from_image(source.GetOutput())), geometry(grid)
    field = as_image(transform, what) if not isinstance(transform, Image) else transform
    return np.ascontiguousarray(field.array, dtype=np.float64), geometry(field)


def evaluate(fixed, moving, structures=None, landmarks=None, fixed_to_moving=None, moving_to_fixed=None,
             border_margin=None):
    """Scores a registration of `moving` onto `fixed` as MOREA scores its own
    (scores.json): per structure Dice, Hausdorff, HD95 and mean surface
    distance (mm) of the fixed mask against the moving mask warped onto the
    fixed grid; landmark errors; the fraction of voxels with a non-positive
    Jacobian determinant; with `moving_to_fixed`, inverse consistency.

    fixed_to_moving: a SimpleITK or itk transform mapping fixed points to
        moving points (what resampling the moving image needs), or a
        displacement field image on the fixed grid; None scores the identity.
    moving_to_fixed: the same the other way (on the moving grid), or None.
    border_margin: mm left out at the image border (default: the parameter
        evaluation_border_margin's default)."""
    registration, fixed_image = configured_registration(fixed, moving, structures, None, landmarks)
    forward, forward_geometry = _field_on(fixed_image, fixed_to_moving, "fixed_to_moving")
    moving_image = as_image(moving, "moving image")
    inverse, inverse_geometry = _field_on(moving_image, moving_to_fixed, "moving_to_fixed")
    margin = -1.0 if border_margin is None else float(border_margin)
    return json.loads(registration.evaluate(forward, forward_geometry, inverse, inverse_geometry, margin))


def phantom(spacing=2.0, seed=1, output="sitk"):
    """The synthetic pelvis with a known deformation (what `morea phantom`
    writes): a dict with "fixed", "moving", "structures" {name: (fixed mask,
    moving mask)}, "landmarks" (fixed, moving; N x 3 mm) and the true
    displacement fields "true_fixed_to_moving" (on the fixed grid) and
    "true_moving_to_fixed" (on the moving grid) as images of the `output`
    library ("sitk", "itk" or "numpy")."""
    if not spacing > 0:
        raise ValueError(f"spacing must be positive, not {spacing}")
    case = _morea.phantom(float(spacing), int(seed))
    out = {"fixed": to_output(case["fixed"], output), "moving": to_output(case["moving"], output),
           "structures": _structures_out(case["structures"], output),
           "landmarks": tuple(np.asarray(p) for p in case["landmarks"])}
    for name in ("true_fixed_to_moving", "true_moving_to_fixed"):
        out[name] = _field_output(case[name], output)
    return out


def _field_output(field, output):
    """A (array, spacing, origin, direction) displacement field as a vector
    image of the `output` library; the tuple itself for "numpy"."""
    if output == "sitk":
        return field_to_sitk(field)
    if output == "itk":
        return field_to_itk(field)
    if output == "numpy":
        return field
    raise ValueError(f"output must be one of {', '.join(OUTPUTS)}, not {output!r}")


def read_rtstruct(path, reference, names=None, output="sitk", points=False):
    """The ROIs of an RTSTRUCT file (or a folder holding one) filled on the
    grid of `reference` (the image they were drawn on): {name: mask}, or
    {name: (mask, contour points N x 3 mm)} with `points`. `names` picks ROIs
    (exact names; an unknown one is an error listing those present)."""
    grid = as_image(reference, "reference")
    size = [int(n) for n in grid.array.shape[::-1]]
    rois = _morea.read_rtstruct(str(path), size, geometry(grid), list(names or []))
    out = {}
    for name, (mask, contour) in rois.items():
        image = to_output(mask, output)
        out[name] = (image, np.asarray(contour)) if points else image
    return out
