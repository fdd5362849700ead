# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Images and point sets in and out: SimpleITK, itk and numpy.

Inside, an image is a C-ordered (z, y, x) numpy array with its geometry
(spacing, origin, row-major direction), as SimpleITK and itk lay them out, so
float32 and uint8 inputs reach the registration without a copy.
"""
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Image:
    """A 3D numpy array (z, y, x) with its physical geometry (x, y, z order)."""

    array: np.ndarray
    spacing: tuple = (1.0, 1.0, 1.0)
    origin: tuple = (0.0, 0.0, 0.0)
    direction: tuple = field(default=(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0))

    def __post_init__(self):
        self.array = np.asarray(self.array)
        if self.array.ndim != 3:
            raise ValueError(f"a 3D image is needed, got an array of {self.array.ndim} dimensions")
        self.spacing = tuple(float(v) for v in self.spacing)
        self.origin = tuple(float(v) for v in self.origin)
        self.direction = tuple(float(v) for v in np.asarray(self.direction, dtype=float).ravel())
        if len(self.spacing) != 3 or len(self.origin) != 3 or len(self.direction) != 9:
            raise ValueError("spacing and origin need 3 values and direction 9 (row-major 3x3)")


def _is_sitk(image):
    return type(image).__module__.startswith("SimpleITK")


def _is_itk(image):
    return type(image).__module__.startswith("itk")


def as_image(image, what):
    """An Image from a SimpleITK image, an itk image, an Image, or a plain
    3D numpy array (spacing 1 mm, origin 0, identity direction)."""
    if isinstance(image, Image):
        return image
    if _is_sitk(image):
        import SimpleITK as sitk

        if image.GetDimension() != 3 or image.GetNumberOfComponentsPerPixel() != 1:
            raise ValueError(f"{what}: a 3D scalar image is needed")
        return Image(sitk.GetArrayViewFromImage(image), image.GetSpacing(), image.GetOrigin(), image.GetDirection())
    if _is_itk(image):
        import itk

        if image.GetImageDimension() != 3:
            raise ValueError(f"{what}: a 3D image is needed")
        direction = np.asarray(itk.array_from_matrix(image.GetDirection()), dtype=float)
        return Image(itk.array_view_from_image(image), tuple(image.GetSpacing()), tuple(image.GetOrigin()),
                     direction.ravel())
    if isinstance(image, np.ndarray):
        return Image(image)
    raise TypeError(f"{what}: a SimpleITK image, an itk image, a morea.Image or a 3D numpy array is needed, "
                    f"got {type(image).__name__}")


def as_intensities(image, what):
    """The image as float32 (integer pixel types are converted)."""
    img = as_image(image, what)
    return Image(np.ascontiguousarray(img.array, dtype=np.float32), img.spacing, img.origin, img.direction)


def as_mask(image, what):
    """The image as a uint8 mask: 1 where it is non-zero."""
    img = as_image(image, what)
    array = img.array
    if array.dtype != np.uint8 or array.max(initial=0) > 1:
        array = (array != 0).astype(np.uint8)
    return Image(np.ascontiguousarray(array), img.spacing, img.origin, img.direction)


def as_points(points, what):
    """An N x 3 float array of physical points (mm) from an array, a list of
    triples, or an itk.PointSet."""
    if points is None:
        return None
    if _is_itk(points) and hasattr(points, "GetPoints"):
        container = points.GetPoints()
        points = [tuple(container.GetElement(i)) for i in range(container.Size())]
    array = np.asarray(points, dtype=float)
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{what}: an N x 3 array of points in mm is needed, got shape {array.shape}")
    if len(array) == 0:
        raise ValueError(f"{what}: the point set is empty")
    return np.ascontiguousarray(array)


def field_to_sitk(field):
    """A (array, spacing, origin, direction) field as a SimpleITK vector image."""
    import SimpleITK as sitk

    array, spacing, origin, direction = field
    image = sitk.GetImageFromArray(np.array(array, dtype=np.float64), isVector=True)
    image.SetSpacing(spacing)
    image.SetOrigin(origin)
    image.SetDirection(direction)
    return image


def to_sitk(image):
    """An (array, spacing, origin, direction) tuple or Image as a SimpleITK image
    (a copy: SimpleITK owns its buffers)."""
    import SimpleITK as sitk

    if not isinstance(image, Image):
        image = Image(*image)
    out = sitk.GetImageFromArray(np.asarray(image.array))
    out.SetSpacing(image.spacing)
    out.SetOrigin(image.origin)
    out.SetDirection(image.direction)
    return out


def to_itk(image):
    """An (array, spacing, origin, direction) tuple or Image as an itk image."""
    import itk

    if not isinstance(image, Image):
        image = Image(*image)
    out = itk.image_from_array(np.ascontiguousarray(image.array))
    out.SetSpacing(image.spacing)
    out.SetOrigin(image.origin)
    out.SetDirection(itk.matrix_from_array(np.reshape(image.direction, (3, 3))))
    return out


OUTPUTS = ("sitk", "itk", "numpy")


def to_output(image, output):
    """An image tuple in the library `output` names: "sitk" (SimpleITK),
    "itk", or "numpy" (a morea.Image: the array with its geometry)."""
    if image is None:
        return None
    if output == "sitk":
        return to_sitk(image)
    if output == "itk":
        return to_itk(image)
    if output == "numpy":
        return image if isinstance(image, Image) else Image(*image)
    raise ValueError(f"output must be one of {', '.join(OUTPUTS)}, not {output!r}")


def field_to_itk(field):
    """A (array, spacing, origin, direction) field as an itk image of
    itk.Vector[itk.D, 3], what itk.DisplacementFieldTransform takes."""
    import itk

    array, spacing, origin, direction = field
    out = itk.Image[itk.Vector[itk.D, 3], 3].New()
    out.SetRegions([int(n) for n in np.shape(array)[2::-1]])
    out.Allocate()
    itk.array_view_from_image(out)[...] = array
    out.SetSpacing(spacing)
    out.SetOrigin(origin)
    out.SetDirection(itk.matrix_from_array(np.reshape(np.asarray(direction, dtype=float), (3, 3))))
    return out
