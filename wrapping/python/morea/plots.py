# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Figures of a registration (matplotlib, needed only here)."""
import numpy as np

from ._images import as_image


def save_overview(path, fixed, fixed_masks, warped_masks, result, solution, window=(-300.0, 400.0),
                  focus="bladder"):
    """Saves a PNG: the fixed image's axial slice through `focus` (or the
    first structure) with each structure's fixed contour (solid) and warped
    moving contour (dashed), beside the front (guidance against intensity,
    coloured by magnitude) with `solution` marked. Images may be SimpleITK,
    itk or numpy; masks are {name: mask} on the fixed grid."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    image = as_image(fixed, "fixed image").array
    masks = {n: as_image(m, f"fixed mask of {n!r}").array for n, m in fixed_masks.items()}
    warped = {n: as_image(m, f"warped mask of {n!r}").array for n, m in warped_masks.items()}
    focus = focus if focus in masks else next(iter(masks))
    z = int(np.argmax((masks[focus] > 0).sum(axis=(1, 2))))
    figure, (left, right) = plt.subplots(1, 2, figsize=(13, 6))
    left.imshow(image[z], cmap="gray", vmin=window[0], vmax=window[1])
    for i, name in enumerate(masks):
        color = f"C{i}"
        for mask, style in ((masks[name], "solid"), (warped.get(name), "dashed")):
            if mask is not None and np.any(mask[z] > 0):
                left.contour(mask[z] > 0, [0.5], colors=color, linestyles=style, linewidths=1.2)
        left.plot([], [], color=color, label=f"{name}: fixed (solid), warped moving (dashed)")
    left.legend(loc="lower left", fontsize=8)
    left.set_title(f"fixed image, axial slice {z}")
    left.axis("off")
    front = result.front
    points = right.scatter(front["guidance"], front["intensity"], c=front["magnitude"], cmap="viridis", s=18)
    right.scatter([front["guidance"][solution.index]], [front["intensity"][solution.index]], s=120,
                  facecolors="none", edgecolors="red", label=f"{solution.label} (shown)")
    right.set_xlabel("guidance (contour mismatch)")
    right.set_ylabel("intensity (image mismatch)")
    right.set_title(f"the front: {len(front)} registrations")
    right.legend()
    figure.colorbar(points, ax=right, label="magnitude (deformation energy)")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
