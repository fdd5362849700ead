#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Removes a solution's voxel-level folds by projection: the NumPy experiment
behind the product's repair (morea_core::RemoveVoxelFolds, which asks for a
lift to twice the threshold and works only near folds), kept to repeat the
experiment's rows in bench/results/generation-budget.md.

Rasterises the solution's mesh map on the preprocessed grid as
fold-origins.py does, then, each round, every voxel whose Jacobian
determinant (central differences, one-sided at the grid's faces) is below
--target asks for the smallest change of the displacements in its stencil
that lifts the determinant to --target, linearised through its cofactors;
the requests are summed and --step of the sum is applied. Reports the rounds,
the folds left and how far voxels moved.

  fold-projection.py SOLUTION_FOLDER PREPROCESSED_IMAGE [--inverse]
"""
import argparse
import importlib.util
import os
import time

import numpy as np
import SimpleITK as sitk

_spec = importlib.util.spec_from_file_location(
    "fold_origins", os.path.join(os.path.dirname(os.path.abspath(__file__)), "fold-origins.py"))
fold_origins = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fold_origins)

AXES = (2, 1, 0)  # index axis x, y, z -> array axis


def stencil_weights(shape, h):
    """Per index axis: the weights of u(v - e), u(v), u(v + e) in dJ[:, j]."""
    weights = []
    for axis in AXES:
        n = shape[axis]
        minus, self_, plus = np.full(n, -0.5 / h), np.zeros(n), np.full(n, 0.5 / h)
        minus[0], self_[0], plus[0] = 0.0, -1.0 / h, 1.0 / h
        minus[-1], self_[-1], plus[-1] = -1.0 / h, 1.0 / h, 0.0
        view = [1, 1, 1]
        view[axis] = n
        weights.append(tuple(w.reshape(view)[..., None] for w in (minus, self_, plus)))
    return weights


def determinants_and_cofactors(u, h):
    J = np.empty(u.shape[:3] + (3, 3))
    for j, axis in enumerate(AXES):
        J[..., :, j] = np.gradient(u, axis=axis) / h
    J += np.eye(3)
    r0, r1, r2 = J[..., 0, :], J[..., 1, :], J[..., 2, :]
    C = np.stack([np.cross(r1, r2), np.cross(r2, r0), np.cross(r0, r1)], axis=-2)
    return np.einsum("...j,...j->...", r0, C[..., 0, :]), C


def project(u0, h, target, step, rounds):
    u = u0.copy()
    weights = stencil_weights(u.shape[:3], h)
    # Per index axis, the squared weights summed: how much a unit cofactor
    # moves the determinant's stencil.
    weight_norms = [sum(w[..., 0] ** 2 for w in axis_weights) for axis_weights in weights]
    for round_ in range(rounds):
        det, C = determinants_and_cofactors(u, h)
        if not (det <= 0).any():
            return u, round_
        shortfall = np.where(det < target, target - det, 0.0)
        norm2 = sum((C[..., :, j] ** 2).sum(-1) * weight_norms[j] for j in range(3))
        share = np.where(shortfall > 0, shortfall / np.maximum(norm2, 1e-12), 0.0)[..., None]
        change = np.zeros_like(u)
        for j, axis in enumerate(AXES):
            minus, self_, plus = weights[j]
            request = share * C[..., :, j]
            change += np.roll(request * plus, 1, axis=axis) + request * self_ + np.roll(request * minus, -1, axis=axis)
        u += step * change
    return u, rounds


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("solution", help="a solution folder with mesh_fixed.vtu and mesh_moving.vtu")
    parser.add_argument("image", help="the preprocessed image whose grid the field lives on")
    parser.add_argument("--inverse", action="store_true", help="the moving-to-fixed map (give the moving image)")
    parser.add_argument("--target", type=float, default=0.005)
    parser.add_argument("--step", type=float, default=0.9)
    parser.add_argument("--rounds", type=int, default=3000)
    args = parser.parse_args(argv)
    p, q, tets = fold_origins.load(args.solution)
    if args.inverse:
        p, q = q, p
    image = sitk.ReadImage(args.image)
    _, field, spacing, direction = fold_origins.rasterise(p, q, tets, image)
    if not np.allclose(direction, np.eye(3)) or len(set(spacing)) != 1:
        raise SystemExit("fold-projection: needs an isotropic grid without rotation (a preprocessed image)")
    u0 = np.nan_to_num(field).astype(np.float64)
    start = time.time()
    u, rounds = project(u0, spacing[0], args.target, args.step, args.rounds)
    moved = np.linalg.norm(u - u0, axis=-1)
    folded = int((fold_origins.jacobians(u, spacing, direction) <= 0).sum())
    print(f"folded before {int((fold_origins.jacobians(u0, spacing, direction) <= 0).sum())}, after {folded} "
          f"({rounds} rounds, {time.time() - start:.0f} s); moved > 0.01 mm {(moved > 0.01).sum()}, "
          f"> 1 mm {(moved > 1).sum()}, > 5 mm {(moved > 5).sum()}, largest {moved.max():.1f} mm")


if __name__ == "__main__":
    main()
