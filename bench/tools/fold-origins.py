#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Where a solution's voxel-level folds come from.

Rasterises a solution's mesh map (mesh_fixed.vtu -> mesh_moving.vtu of one
solution folder of `morea register`) on the preprocessed fixed grid, as the
fixed-to-moving field is before its fold repair, and reports the voxels whose
central-difference Jacobian determinant is <= 0: how many tetrahedra their
stencils span, those tetrahedra's own Jacobians (volume ratios), their sizes
against the voxel, and how far apart their gradients are.

    fold-origins.py SOLUTION_FOLDER PREPROCESSED_FIXED_IMAGE [--json OUT]

Needs numpy, SimpleITK and meshio.
"""
import argparse
import json
import sys

import meshio
import numpy as np
import SimpleITK as sitk


def load(folder):
    fixed = meshio.read(f"{folder}/mesh_fixed.vtu")
    moving = meshio.read(f"{folder}/mesh_moving.vtu")
    tets = fixed.cells_dict["tetra"]
    if not np.array_equal(tets, moving.cells_dict["tetra"]):
        sys.exit("the two meshes have different tetrahedra")
    return fixed.points, moving.points, tets


def rasterise(p, q, tets, image):
    """Owner tetrahedron and displacement at every voxel centre (-1 / nan outside)."""
    size = np.array(image.GetSize())
    spacing = np.array(image.GetSpacing())
    origin = np.array(image.GetOrigin())
    direction = np.array(image.GetDirection()).reshape(3, 3)
    to_index = np.linalg.inv(direction @ np.diag(spacing))
    owner = -np.ones(size[::-1], dtype=np.int64)  # z, y, x
    field = np.full(tuple(size[::-1]) + (3,), np.nan)
    pi = (p - origin) @ to_index.T  # vertices in index space
    for t, tet in enumerate(tets):
        lo = np.maximum(np.ceil(pi[tet].min(axis=0) - 1e-9).astype(int), 0)
        hi = np.minimum(np.floor(pi[tet].max(axis=0) + 1e-9).astype(int), size - 1)
        if np.any(hi < lo):
            continue
        grid = np.stack(np.meshgrid(*[np.arange(lo[d], hi[d] + 1) for d in range(3)], indexing="ij"), -1).reshape(-1, 3)
        edges = (pi[tet[1:]] - pi[tet[0]]).T
        b = np.linalg.solve(edges, (grid - pi[tet[0]]).T).T
        bary = np.column_stack([1 - b.sum(axis=1), b])
        inside = np.all(bary >= -1e-9, axis=1)
        g, w = grid[inside], bary[inside]
        free = owner[g[:, 2], g[:, 1], g[:, 0]] < 0
        g, w = g[free], w[free]
        owner[g[:, 2], g[:, 1], g[:, 0]] = t
        field[g[:, 2], g[:, 1], g[:, 0]] = w @ (q[tet] - p[tet])
    return owner, field, spacing, direction


def jacobians(field, spacing, direction):
    """det(I + grad u) per voxel, central differences (one-sided at the edge)."""
    grads = []
    for axis_index, axis in enumerate((2, 1, 0)):  # x, y, z in array order z, y, x
        grads.append(np.gradient(field, axis=axis) / spacing[axis_index])
    du_dindex = np.stack(grads, axis=-1)  # [..., component, index axis]
    grad = du_dindex @ direction.T  # index axes -> physical directions
    return np.linalg.det(np.eye(3) + grad)


def tetra_gradients(p, q, tets):
    """Per tetrahedron: F (moving edges times inverse fixed edges), its
    determinant (volume ratio) and the rest shape's longest edge."""
    ep = np.stack([p[tets[:, k]] - p[tets[:, 0]] for k in (1, 2, 3)], axis=-1)
    eq = np.stack([q[tets[:, k]] - q[tets[:, 0]] for k in (1, 2, 3)], axis=-1)
    F = eq @ np.linalg.inv(ep)
    all_edges = [p[tets[:, a]] - p[tets[:, b]] for a in range(4) for b in range(a + 1, 4)]
    longest = np.max([np.linalg.norm(e, axis=1) for e in all_edges], axis=0)
    shortest = np.min([np.linalg.norm(e, axis=1) for e in all_edges], axis=0)
    return F, np.linalg.det(F), longest, shortest


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("solution")
    parser.add_argument("fixed_image")
    parser.add_argument("--json")
    args = parser.parse_args(argv)
    p, q, tets = load(args.solution)
    image = sitk.ReadImage(args.fixed_image)
    owner, field, spacing, direction = rasterise(p, q, tets, image)
    det = jacobians(np.nan_to_num(field), spacing, direction)
    covered = owner >= 0
    folded = (det <= 0) & covered
    F, volume_ratio, longest, shortest = tetra_gradients(p, q, tets)
    z, y, x = np.nonzero(folded)
    shape = np.array(owner.shape)
    spans, min_ratio, max_ratio, jump = [], [], [], []
    for k, j, i in zip(z, y, x):
        around = {owner[k, j, i]}
        for d in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
            for s in (-1, 1):
                n = np.array([k, j, i]) + s * np.array(d)
                if np.all(n >= 0) and np.all(n < shape) and owner[tuple(n)] >= 0:
                    around.add(owner[tuple(n)])
        around = sorted(around)
        spans.append(len(around))
        min_ratio.append(volume_ratio[around].min())
        max_ratio.append(volume_ratio[around].max())
        Fs = F[around]
        jump.append(max(np.linalg.norm(a - b, 2) for a in Fs for b in Fs))
    spans, min_ratio, max_ratio, jump = map(np.array, (spans, min_ratio, max_ratio, jump))
    in_folds = np.unique(owner[folded])
    pct = lambda a: {f"p{v}": float(np.percentile(a, v)) for v in (5, 25, 50, 75, 95)} if len(a) else {}
    report = {
        "voxels": int(owner.size), "covered": int(covered.sum()), "folded": int(folded.sum()),
        "tetrahedra": int(len(tets)), "tetrahedra_at_folds": int(len(in_folds)),
        "stencil_tetrahedra": {str(n): int((spans == n).sum()) for n in np.unique(spans)},
        "min_volume_ratio_at_folds": pct(min_ratio), "max_volume_ratio_at_folds": pct(max_ratio),
        "gradient_jump_at_folds": pct(jump),
        "volume_ratio_all_tetrahedra": pct(volume_ratio),
        "longest_edge_mm_at_folds": pct(longest[in_folds]), "longest_edge_mm_all": pct(longest),
        "shortest_edge_mm_at_folds": pct(shortest[in_folds]), "shortest_edge_mm_all": pct(shortest),
        "folds_within_one_tetrahedron": int((spans == 1).sum()),
        "voxel_mm": float(spacing.min()),
    }
    text = json.dumps(report, indent=1)
    print(text)
    if args.json:
        with open(args.json, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
