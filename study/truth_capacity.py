# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Can a mesh carry the true map at all?

For a problem whose true moving-to-fixed map is known (`morea phantom`), puts
the mesh's base points on the moving image, their fixed-image partners where
the true map takes them, and scores that piecewise-affine map like a
registration: landmark TRE (per kind when the landmark sets are given) and
the tetrahedra it folds. What it reaches bounds what any solution on this mesh
can reach; `morea mesh --objectives-of` gives the same map's objectives.

    morea mesh --problem PREPROCESSED --parameters RUN.toml --set seed=S -o MESH
    python -m study.truth_capacity --mesh MESH --truth PHANTOM/true_moving_to_fixed.nii.gz \\
        --landmarks STUDY/landmarks [--json OUT.json]

--landmarks holds one folder per landmark kind with fixed_landmarks.txt and
moving_landmarks.txt (the study's landmarks/), or is a problem folder with the
two files.
"""
import argparse
import json
from pathlib import Path

import numpy as np

from .contour_capacity import carry, read_vtu, signed_volumes


def read_points(path):
    """An elastix point file's points (mm)."""
    lines = Path(path).read_text().split("\n")
    count = int(lines[1])
    return np.array([[float(v) for v in line.split()] for line in lines[2:2 + count]]).reshape(-1, 3)


def field_map(path):
    """The map x -> x + u(x) of a displacement field file (linear interpolation)."""
    import SimpleITK as sitk
    transform = sitk.DisplacementFieldTransform(sitk.ReadImage(str(path), sitk.sitkVectorFloat64))
    return lambda points: np.array([transform.TransformPoint(tuple(map(float, p))) for p in points])


def carried_tre(source, target, tetrahedra, fixed_landmarks, moving_landmarks):
    """TRE of the piecewise-affine map target -> source at the fixed landmarks
    inside the target mesh: (errors in mm, how many lay inside)."""
    mapped, inside = carry(fixed_landmarks, target, source, tetrahedra)
    return np.linalg.norm(mapped - moving_landmarks[inside], axis=1), int(inside.sum())


def capacity(source, tetrahedra, true_map, landmark_sets):
    """The truth carried by the mesh: per landmark set, TRE of the carried map
    and of the truth itself (its field's sampling), and the folded tetrahedra."""
    target = true_map(source)
    folded = int(np.sum(np.sign(signed_volumes(target, tetrahedra)) != np.sign(signed_volumes(source, tetrahedra))))
    out = {"folded_tetrahedra": folded, "tetrahedra": int(len(tetrahedra)), "landmarks": {}}
    for name, (fixed_path, moving_path) in landmark_sets.items():
        fixed, moving = read_points(fixed_path), read_points(moving_path)
        errors, inside = carried_tre(source, target, tetrahedra, fixed, moving)
        # The field itself, the other way round: how exactly it holds the truth.
        truth_error = np.linalg.norm(true_map(moving) - fixed, axis=1)
        out["landmarks"][name] = {
            "count": inside, "of": int(len(fixed)),
            "tre_mean_mm": float(errors.mean()) if inside else None,
            "tre_max_mm": float(errors.max()) if inside else None,
            "true_motion_mean_mm": float(np.linalg.norm(moving - fixed, axis=1).mean()),
            "field_error_max_mm": float(truth_error.max())}
    return out


def landmark_sets(folder):
    folder = Path(folder)
    if (folder / "fixed_landmarks.txt").exists():
        return {"all": (folder / "fixed_landmarks.txt", folder / "moving_landmarks.txt")}
    return {d.name: (d / "fixed_landmarks.txt", d / "moving_landmarks.txt")
            for d in sorted(folder.iterdir()) if (d / "fixed_landmarks.txt").exists()}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mesh", required=True, type=Path, help="a folder of `morea mesh` (mesh_moving.vtu)")
    parser.add_argument("--truth", required=True, type=Path, help="the true moving-to-fixed displacement field")
    parser.add_argument("--landmarks", required=True, type=Path)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    source, tetrahedra, _ = read_vtu(args.mesh / "mesh_moving.vtu")
    result = capacity(source, tetrahedra, field_map(args.truth), landmark_sets(args.landmarks))
    print(f"the truth on this mesh folds {result['folded_tetrahedra']} of {result['tetrahedra']} tetrahedra")
    print("landmarks   inside   true motion mm   carried TRE mean / max mm   field's own error max mm")
    for name, r in result["landmarks"].items():
        tre = "-" if r["tre_mean_mm"] is None else f"{r['tre_mean_mm']:.2f} / {r['tre_max_mm']:.2f}"
        print(f"{name:10s}  {r['count']:3d}/{r['of']:<3d}  {r['true_motion_mean_mm']:14.2f}   {tre:>25s}   "
              f"{r['field_error_max_mm']:.2f}")
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
