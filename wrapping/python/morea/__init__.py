"""MOREA: multi-objective deformable registration of 3D images with large
deformations, on the GPU when one is present.

    import SimpleITK as sitk, morea
    result = morea.register(fixed, moving, structures={"bladder": (fixed_mask, moving_mask)},
                            parameters={"ea_num_generations": 100}, seed=1)
    result.front                        # objective values of every solution found
    best = result.solutions[0]          # the best-guidance solution
    warped = best.resample(moving)      # the moving image on the fixed grid
    sitk.WriteTransform(best.fixed_to_moving, "fixed_to_moving.h5")

Images are SimpleITK images, itk images, morea.Image or 3D numpy arrays.
"""
import os
import sys

import numpy as np

from ._images import Image, as_image, as_intensities, as_mask, as_points, field_to_sitk
from ._morea import Registration as _Registration

__all__ = ["register", "Image", "RegistrationResult", "Solution"]

FRONT_DTYPE = np.dtype([("id", np.uint64), ("magnitude", float), ("intensity", float), ("guidance", float)])


def _parameter_text(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ", ".join(str(v) for v in value)
    return str(value)


class Solution:
    """One solution of the front: its objectives and its transforms."""

    def __init__(self, result, index, label):
        self._result = result
        self.index = index
        self.label = label
        row = result.front[index]
        self.id = int(row["id"])
        self.objectives = {name: float(row[name]) for name in ("magnitude", "intensity", "guidance")}
        self._fields = None

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

    def _pre_alignment(self, inverse):
        import SimpleITK as sitk

        matrix, offset = self._result._registration.pre_alignment()
        affine = sitk.AffineTransform(3)
        affine.SetMatrix(matrix)
        affine.SetTranslation(offset)
        return affine.GetInverse() if inverse else affine

    @property
    def fixed_to_moving(self):
        """SimpleITK transform, original fixed points -> original moving points
        (the pre-alignment after the field): what sitk.Resample needs to map the
        moving image onto the fixed grid."""
        import SimpleITK as sitk

        field = sitk.DisplacementFieldTransform(field_to_sitk(self.fields()[0]))
        return sitk.CompositeTransform([self._pre_alignment(False), field])

    @property
    def moving_to_fixed(self):
        """SimpleITK transform, original moving points -> original fixed points."""
        import SimpleITK as sitk

        field = sitk.DisplacementFieldTransform(field_to_sitk(self.fields()[1]))
        return sitk.CompositeTransform([field, self._pre_alignment(True)])

    def resample(self, image, reference=None, interpolator=None, default_value=0.0):
        """`image` (on the moving image's grid or any grid in its space) resampled
        onto the fixed image's grid (or `reference`'s) through this solution.
        Masks (integer images) are resampled by nearest neighbour, others
        linearly; returns a SimpleITK image."""
        import SimpleITK as sitk

        if not isinstance(image, sitk.Image):
            img = as_image(image, "image to resample")
            image = sitk.GetImageFromArray(np.asarray(img.array))
            image.SetSpacing(img.spacing)
            image.SetOrigin(img.origin)
            image.SetDirection(img.direction)
        if reference is None:
            reference = self._result._fixed_reference()
        if interpolator is None:
            integer = image.GetPixelID() in (sitk.sitkUInt8, sitk.sitkInt8, sitk.sitkUInt16, sitk.sitkInt16,
                                             sitk.sitkUInt32, sitk.sitkInt32)
            interpolator = sitk.sitkNearestNeighbor if integer else sitk.sitkLinear
        return sitk.Resample(image, reference, self.fixed_to_moving, interpolator, default_value,
                             image.GetPixelID())


class RegistrationResult:
    """What morea.register returns: the front and the chosen solutions."""

    def __init__(self, registration, fixed):
        self._registration = registration
        self._fixed = fixed
        ids, objectives = registration.front()
        objectives = np.asarray(objectives, dtype=float).reshape(-1, 3)
        self.front = np.zeros(len(ids), dtype=FRONT_DTYPE)
        self.front["id"] = ids
        for m, name in enumerate(("magnitude", "intensity", "guidance")):
            self.front[name] = objectives[:, m]
        self.solutions = [Solution(self, index, label) for label, index in registration.selected()]
        self.backend = registration.backend_used
        self.backend_note = registration.backend_note
        self.resumed_at_generation = registration.resumed_at_generation

    def __repr__(self):
        return (f"RegistrationResult(front of {len(self.front)}, chosen {[s.label for s in self.solutions]}, "
                f"backend {self.backend!r})")

    def choose(self, weights=None, nearest=None, selection=None):
        """Any solution of the front: by weights of the normalised objectives
        (magnitude, intensity, guidance), by the objective values it should be
        nearest to, or by a selection string ("knee", "best-guidance", ...)."""
        if sum(x is not None for x in (weights, nearest, selection)) != 1:
            raise ValueError("choose: give exactly one of weights, nearest or selection")
        if weights is not None:
            selection = "weighted:" + ":".join(str(float(w)) for w in weights)
        elif nearest is not None:
            selection = "nearest:" + ":".join(str(float(v)) for v in nearest)
        label, index = self._registration.choose(selection)[0]
        return Solution(self, index, label)

    def _fixed_reference(self):
        import SimpleITK as sitk

        f = self._fixed
        reference = sitk.Image([int(n) for n in f.array.shape[::-1]], sitk.sitkUInt8)
        reference.SetSpacing(f.spacing)
        reference.SetOrigin(f.origin)
        reference.SetDirection(f.direction)
        return reference


def _progress_bar(enabled):
    """A per-generation callback drawing a bar (tqdm when installed)."""
    if not enabled:
        return None
    state = {}
    try:
        from tqdm import tqdm
    except ImportError:
        tqdm = None

    def update(generation, total, front, best_guidance):
        if tqdm is not None:
            bar = state.get("bar")
            if bar is None:
                bar = state["bar"] = tqdm(total=total, unit="generation")
            bar.n = generation
            bar.set_postfix(front=front, guidance=f"{best_guidance:.4g}", refresh=False)
            bar.refresh()
            if generation >= total:
                bar.close()
        elif generation % 10 == 0 or generation == total:
            print(f"generation {generation}/{total}: front of {front}, best guidance {best_guidance:.4g}",
                  file=sys.stderr, flush=True)

    return update


def register(fixed, moving, structures=None, points=None, landmarks=None, parameters=None, backend="auto",
             select="best-guidance,knee", seed=None, checkpoint=None, checkpoint_every=10, resume=False,
             initial_transform=None, progress=True, callback=None):
    """Registers `moving` onto `fixed` with MOREA; returns a RegistrationResult.

    structures: {name: (fixed_mask, moving_mask)}, masks on each image's grid
        (either may be None when `points` gives that side).
    points: {name: (fixed_points, moving_points)}, N x 3 contour points in mm.
    landmarks: (fixed_points, moving_points), corresponding, for evaluation.
    parameters: a TOML parameter file's path, or a dict of its keys.
    backend: "auto" (the GPU when present, else the CPU), "cuda", "cuda-exact", "cpu".
    select: the solutions to rasterise at once (best-guidance, knee,
        weighted:a:b:c, nearest:m:i:g, all; comma-separated); any other later
        with result.choose().
    initial_transform: a SimpleITK linear transform (fixed -> moving points) used
        instead of the rigid pre-alignment.
    callback: called as callback(generation, total, front_size, best_guidance)
        after each generation; raising from it stops the run.
    Ctrl-C stops after the current generation and raises KeyboardInterrupt.
    """
    registration = _Registration()
    fixed_image = as_intensities(fixed, "fixed image")
    moving_image = as_intensities(moving, "moving image")
    registration.set_images(fixed_image.array, _geometry(fixed_image), moving_image.array, _geometry(moving_image))
    for name, pair in (structures or {}).items():
        fixed_mask, moving_mask = pair
        f = as_mask(fixed_mask, f"fixed mask of {name!r}") if fixed_mask is not None else None
        m = as_mask(moving_mask, f"moving mask of {name!r}") if moving_mask is not None else None
        registration.add_structure_masks(name, None if f is None else f.array, _geometry(f),
                                         None if m is None else m.array, _geometry(m))
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
            registration.set_parameter(key, _parameter_text(value))
    if seed is not None:
        registration.set_parameter("seed", str(int(seed)))
    registration.set_backend(backend)
    registration.set_selection(select)
    if checkpoint is not None:
        registration.set_checkpoint(os.fspath(checkpoint), int(checkpoint_every), bool(resume))
    if initial_transform is not None:
        _set_initial_transform(registration, initial_transform)
    bar = _progress_bar(progress)

    def on_generation(generation, total, front, best_guidance):
        if bar is not None:
            bar(generation, total, front, best_guidance)
        if callback is not None:
            callback(generation, total, front, best_guidance)

    registration.run(on_generation if (bar or callback) else None)
    return RegistrationResult(registration, fixed_image)


def _geometry(image):
    from ._morea import Geometry

    if image is None:
        return Geometry()
    return Geometry(image.spacing, image.origin, image.direction)


def _set_initial_transform(registration, transform):
    """A SimpleITK linear transform as the matrix and offset of x -> M x + offset."""
    origin = np.zeros(3)
    offset = np.asarray(transform.TransformPoint(tuple(origin)))
    matrix = np.column_stack([np.asarray(transform.TransformPoint(tuple(e))) - offset for e in np.eye(3)])
    probe = np.array([3.0, -7.0, 11.0])
    if np.linalg.norm(np.asarray(transform.TransformPoint(tuple(probe))) - (matrix @ probe + offset)) > 1e-6:
        raise ValueError("initial_transform: a linear transform (translation, rigid, similarity, affine) is needed")
    registration.set_initial_transform(matrix.ravel().tolist(), offset.tolist())
