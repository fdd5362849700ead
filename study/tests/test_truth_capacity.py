# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The truth-capacity check: a map the mesh can follow (affine) is carried
exactly, one it cannot (a fold between its points) shows its folds and error."""
from __future__ import annotations

import numpy as np

from study import truth_capacity as tc
from study.tests.test_contour_capacity import box_mesh


def _points(path, points):
    path.write_text("point\n%d\n" % len(points) + "".join("%.17g %.17g %.17g\n" % tuple(p) for p in points))


def _sets(tmp_path, fixed, moving):
    _points(tmp_path / "fixed_landmarks.txt", fixed)
    _points(tmp_path / "moving_landmarks.txt", moving)
    return tc.landmark_sets(tmp_path)


def test_an_affine_truth_is_carried_exactly(tmp_path):
    source, tetrahedra = box_mesh(n=4, size=20.0)
    a = np.array([[1.1, 0.1, 0.0], [0.0, 0.9, 0.05], [0.02, 0.0, 1.05]])
    to_fixed = lambda p: p @ a.T + np.array([0.5, -0.3, 0.2])        # noqa: E731  moving -> fixed
    rng = np.random.default_rng(3)
    moving = rng.uniform(4.0, 16.0, (20, 3))
    result = tc.capacity(source, tetrahedra, to_fixed, _sets(tmp_path, to_fixed(moving), moving))
    r = result["landmarks"]["all"]
    assert result["folded_tetrahedra"] == 0 and r["count"] == 20
    assert r["tre_mean_mm"] < 1e-9 and r["field_error_max_mm"] < 1e-9
    assert r["true_motion_mean_mm"] > 0.5


def test_a_map_the_mesh_cannot_follow_folds_and_misses(tmp_path):
    source, tetrahedra = box_mesh(n=4, size=20.0)

    def swirl(p):   # a twist about the box's vertical axis: half a turn there, less away from it
        c = p - 10.0
        angle = np.pi * np.exp(-(np.hypot(c[:, 0], c[:, 1]) / 6.0) ** 2)
        x = c[:, 0] * np.cos(angle) - c[:, 1] * np.sin(angle)
        y = c[:, 0] * np.sin(angle) + c[:, 1] * np.cos(angle)
        return np.stack([x, y, c[:, 2]], axis=1) + 10.0

    moving = np.array([[12.0, 10.0, 10.0], [10.0, 13.0, 11.0], [8.0, 9.0, 10.0]])
    result = tc.capacity(source, tetrahedra, swirl, _sets(tmp_path, swirl(moving), moving))
    assert result["folded_tetrahedra"] > 0
    assert result["landmarks"]["all"]["tre_mean_mm"] > 0.3
