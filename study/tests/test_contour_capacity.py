# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The contour-capacity study's parts: it reads the meshes morea writes,
carries points through the piecewise-affine map, and fits contour points onto
a surface without folding a tetrahedron."""
from __future__ import annotations

import itertools
import json
import subprocess

import numpy as np

from study import contour_capacity as cc


class Sphere:
    """Signed distance to a sphere, with its gradient."""

    def __init__(self, centre, radius):
        self.centre, self.radius = np.asarray(centre, float), radius

    def __call__(self, points):
        return np.linalg.norm(points - self.centre, axis=1) - self.radius

    def gradient(self, points):
        d = points - self.centre
        return d / np.linalg.norm(d, axis=1, keepdims=True)


def box_mesh(n=4, size=20.0):
    """A cube of n^3 cells, six positive tetrahedra each (Kuhn split)."""
    axis = np.linspace(0.0, size, n + 1)
    points = np.array([(x, y, z) for z in axis for y in axis for x in axis])
    index = lambda i, j, k: i + (n + 1) * (j + (n + 1) * k)  # noqa: E731
    tetrahedra = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                c = [index(i + (v & 1), j + (v >> 1 & 1), k + (v >> 2 & 1)) for v in range(8)]
                for a, b in itertools.permutations((1, 2, 4), 2):  # monotone paths from corner 0 to 7
                    tet = [c[0], c[a], c[a | b], c[7]]
                    if cc.signed_volumes(points, np.array([tet]))[0] < 0:
                        tet[1], tet[2] = tet[2], tet[1]
                    tetrahedra.append(tet)
    return points, np.array(tetrahedra)


def test_reads_the_meshes_morea_writes(morea, tmp_path):
    subprocess.run([morea, "phantom", "--spacing", "6", "-o", tmp_path / "phantom"], check=True,
                   stdout=subprocess.DEVNULL)
    subprocess.run([morea, "mesh", "--problem", tmp_path / "phantom", "-o", tmp_path / "mesh",
                    "--set", "morea_mesh_num_points=60"], check=True, stdout=subprocess.DEVNULL)
    summary = json.loads((tmp_path / "mesh" / "mesh.json").read_text())
    points, tetrahedra, arrays = cc.read_vtu(tmp_path / "mesh" / "mesh_moving.vtu")
    assert points.shape == (summary["points"], 3)
    assert tetrahedra.shape == (summary["tetrahedra"], 4)
    assert np.all(cc.signed_volumes(points, tetrahedra) > 0)
    assert set(np.unique(arrays["origin"])) <= set(range(9))  # TetrahedralMesh.h's PointOrigin
    assert arrays["structure"].max() >= 0  # contour points of the structures


def test_carrying_follows_the_affine_pieces():
    points, tetrahedra = box_mesh()
    rng = np.random.default_rng(3)
    inside = rng.uniform(0.5, 19.5, size=(200, 3))
    carried, found = cc.carry(inside, points, points, tetrahedra)
    assert found.all() and np.allclose(carried, inside)
    affine = np.array([[1.1, 0.1, 0.0], [0.0, 0.9, 0.2], [0.05, 0.0, 1.0]])
    moved = points @ affine.T + 3.0
    assert np.allclose(cc.carry(inside, points, moved, tetrahedra)[0], inside @ affine.T + 3.0)
    carried, found = cc.carry(np.array([[30.0, 5.0, 5.0], [5.0, 5.0, 5.0]]), points, points, tetrahedra)
    assert found.tolist() == [False, True] and np.allclose(carried, [[5.0, 5.0, 5.0]])


def test_fit_carries_a_surface_onto_another_without_folds():
    # The source mesh holds a sphere of radius 6; the target should carry it
    # onto one of radius 8 about a shifted centre.
    points, tetrahedra = box_mesh(n=6, size=30.0)
    source_sphere = Sphere((15.3, 14.6, 15.2), 6.0)
    target_sphere = Sphere((16.1, 14.6, 15.2), 8.0)
    on_box = np.any((points == 0.0) | (points == 30.0), axis=1)
    origin = np.where(on_box, cc.FACE, 2)
    rng = np.random.default_rng(5)
    directions = rng.normal(size=(3000, 3))
    surface = source_sphere.centre + 6.0 * directions / np.linalg.norm(directions, axis=1, keepdims=True)
    training, scoring = surface[:1500], surface[1500:]
    mismatch = lambda target: np.abs(target_sphere(cc.carry(scoring, points, target, tetrahedra)[0])).mean()  # noqa: E731
    before = mismatch(points)
    fitted = cc.fit_target(points, points.copy(), tetrahedra, origin, {0: (training, np.zeros(len(training)))},
                           {0: target_sphere}, iterations=60)
    assert mismatch(fitted) < 0.3 * before
    assert np.all(cc.signed_volumes(fitted, tetrahedra) > 0)
    assert np.array_equal(fitted[on_box], points[on_box])
