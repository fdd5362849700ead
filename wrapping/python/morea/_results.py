# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""What morea.register returns: the front, its solutions and their transforms."""
import json
import os

import numpy as np

from ._images import as_image, field_to_itk, field_to_sitk, to_sitk

FRONT_DTYPE = np.dtype([("id", np.uint64), ("magnitude", float), ("intensity", float), ("guidance", float)])
OBJECTIVES = ("magnitude", "intensity", "guidance")
DIRECTIONS = ("fixed_to_moving", "moving_to_fixed")


class Solution:
    """One solution of the front: its objectives, transforms and scores."""

    def __init__(self, result, index, label):
        self._result = result
        self.index = index
        self.label = label
        row = result.front[index]
        self.id = int(row["id"])
        self.objectives = {name: float(row[name]) for name in OBJECTIVES}
        self._fields = None
        self._scores = None

    def __repr__(self):
        o = self.objectives
        return (f"Solution({self.label!r}, id {self.id}: magnitude {o['magnitude']:.4g}, "
                f"intensity {o['intensity']:.4g}, guidance {o['guidance']:.4g})")

    def fields(self):
        """The displacement fields in the preprocessed frame, fixed -> moving
        and moving -> fixed, each (array (z, y, x, 3), spacing, origin,
        direction); rasterised on first use."""
        if self._fields is None:
            self._fields = self._result._registration.fields(self.index)
        return self._fields

    @property
    def scores(self):
        """Scores on the preprocessed problem, as scores.json holds them: per
        structure Dice, Hausdorff (max, 95th percentile) and mean surface
        distance in mm; landmark errors; the fraction of folded voxels;
        inverse consistency."""
        if self._scores is None:
            self._scores = json.loads(self._result._registration.scores(self.index))
        return self._scores

    def transform(self, direction="fixed_to_moving", library="sitk"):
        """The transform between the original images, `direction`
        "fixed_to_moving" (what resampling the moving image onto the fixed
        grid needs) or "moving_to_fixed", as a SimpleITK ("sitk") or itk
        ("itk") composite transform: the displacement field, then the
        pre-alignment (or its inverse first, the other way)."""
        if direction not in DIRECTIONS:
            raise ValueError(f"direction must be one of {', '.join(DIRECTIONS)}, not {direction!r}")
        inverse = direction == "moving_to_fixed"
        field = self.fields()[1 if inverse else 0]
        matrix, offset = self._result._registration.pre_alignment()
        if library == "sitk":
            import SimpleITK as sitk

            affine = sitk.AffineTransform(3)
            affine.SetMatrix(matrix)
            affine.SetTranslation(offset)
            deformation = sitk.DisplacementFieldTransform(field_to_sitk(field))
            if inverse:
                return sitk.CompositeTransform([deformation, affine.GetInverse()])
            return sitk.CompositeTransform([affine, deformation])
        if library == "itk":
            import itk

            affine = itk.AffineTransform[itk.D, 3].New()
            affine.SetMatrix(itk.matrix_from_array(np.reshape(matrix, (3, 3))))
            affine.SetTranslation(offset)
            deformation = itk.DisplacementFieldTransform[itk.D, 3].New()
            deformation.SetDisplacementField(field_to_itk(field))
            composite = itk.CompositeTransform[itk.D, 3].New()
            # Like SimpleITK's list, ITK applies the transform added last first.
            if inverse:
                composite.AddTransform(deformation)
                composite.AddTransform(affine.GetInverseTransform())
            else:
                composite.AddTransform(affine)
                composite.AddTransform(deformation)
            return composite
        raise ValueError(f"library must be 'sitk' or 'itk', not {library!r}")

    @property
    def fixed_to_moving(self):
        """SimpleITK transform, original fixed points -> original moving points
        (the pre-alignment after the field): what sitk.Resample needs to map the
        moving image onto the fixed grid."""
        return self.transform("fixed_to_moving")

    @property
    def moving_to_fixed(self):
        """SimpleITK transform, original moving points -> original fixed points."""
        return self.transform("moving_to_fixed")

    def resample(self, image, reference=None, interpolator=None, default_value=0.0):
        """`image` (on the moving image's grid or any grid in its space)
        resampled onto the fixed image's grid (or `reference`'s) through this
        solution. Masks (integer images) are resampled by nearest neighbour,
        others linearly. An itk image comes back as an itk image (resampled
        by itk), anything else as a SimpleITK image."""
        if type(image).__module__.startswith("itk"):
            return self._resample_itk(image, reference, interpolator, default_value)
        import SimpleITK as sitk

        if not isinstance(image, sitk.Image):
            image = to_sitk(as_image(image, "image to resample"))
        if reference is None:
            reference = self._result._fixed_reference()
        elif not isinstance(reference, sitk.Image):
            reference = to_sitk(as_image(reference, "reference"))
        if interpolator is None:
            integer = image.GetPixelID() in (sitk.sitkUInt8, sitk.sitkInt8, sitk.sitkUInt16, sitk.sitkInt16,
                                             sitk.sitkUInt32, sitk.sitkInt32)
            interpolator = sitk.sitkNearestNeighbor if integer else sitk.sitkLinear
        return sitk.Resample(image, reference, self.fixed_to_moving, interpolator, default_value,
                             image.GetPixelID())

    def _resample_itk(self, image, reference, interpolator, default_value):
        import itk

        grid = as_image(reference, "reference") if reference is not None else self._result._fixed
        integer = np.issubdtype(itk.array_view_from_image(image).dtype, np.integer)
        if interpolator is None:
            interpolator = (itk.NearestNeighborInterpolateImageFunction if integer
                            else itk.LinearInterpolateImageFunction)[type(image), itk.D].New()
        return itk.resample_image_filter(
            image, transform=self.transform("fixed_to_moving", "itk"), interpolator=interpolator,
            size=[int(n) for n in grid.array.shape[::-1]], output_spacing=grid.spacing,
            output_origin=grid.origin,
            output_direction=itk.matrix_from_array(np.reshape(grid.direction, (3, 3))),
            default_pixel_value=int(default_value) if integer else float(default_value))


class RegistrationResult:
    """What morea.register returns: the front and the chosen solutions."""

    def __init__(self, registration, fixed):
        self._registration = registration
        self._fixed = fixed
        ids, objectives = registration.front()
        objectives = np.asarray(objectives, dtype=float).reshape(-1, 3)
        self.front = np.zeros(len(ids), dtype=FRONT_DTYPE)
        self.front["id"] = ids
        for m, name in enumerate(OBJECTIVES):
            self.front[name] = objectives[:, m]
        self.solutions = [Solution(self, index, label) for label, index in registration.selected()]
        self.backend = registration.backend_used
        self.backend_note = registration.backend_note
        self.resumed_at_generation = registration.resumed_at_generation

    def __repr__(self):
        return (f"RegistrationResult(front of {len(self.front)}, chosen {[s.label for s in self.solutions]}, "
                f"backend {self.backend!r})")

    def front_table(self):
        """The front as a pandas DataFrame (pandas needed), one row per solution."""
        import pandas as pd

        return pd.DataFrame(self.front)

    def choose(self, weights=None, nearest=None, selection=None):
        """Any solution of the front: by weights of the normalised objectives
        (magnitude, intensity, guidance), by the objective values it should be
        nearest to, or by a selection string that names one solution ("knee",
        "best-guidance", ...; "spread:N" and "all" name several: give them to
        register's `select`)."""
        if sum(x is not None for x in (weights, nearest, selection)) != 1:
            raise ValueError("choose: give exactly one of weights, nearest or selection")
        if weights is not None:
            selection = "weighted:" + ":".join(str(float(w)) for w in weights)
        elif nearest is not None:
            selection = "nearest:" + ":".join(str(float(v)) for v in nearest)
        chosen = self._registration.choose(selection)
        if len(chosen) != 1:
            raise ValueError(f"choose: '{selection}' names {len(chosen)} solutions, not one; "
                             "pass it as register(select=...) for several")
        label, index = chosen[0]
        return Solution(self, index, label)

    def save(self, folder, solutions=None):
        """Writes the folder `morea register` writes (parameters, front,
        per-generation log, and per solution its fields, transforms, meshes,
        scores and renders; summary.json last) with `solutions` (default: the
        chosen ones; any from choose() too); returns the summary as a dict.
        The folder is locked while written; an earlier result in it is replaced."""
        chosen = self.solutions if solutions is None else list(solutions)
        labels = [s.label for s in chosen]
        if len(set(labels)) != len(labels):
            raise ValueError(f"save: two solutions with one label among {labels}")
        return json.loads(self._registration.save(os.fspath(folder), [(s.label, s.index) for s in chosen]))

    def _fixed_reference(self):
        import SimpleITK as sitk

        f = self._fixed
        reference = sitk.Image([int(n) for n in f.array.shape[::-1]], sitk.sitkUInt8)
        reference.SetSpacing(f.spacing)
        reference.SetOrigin(f.origin)
        reference.SetDirection(f.direction)
        return reference
