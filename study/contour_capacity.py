# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""What limits the contour match: the mesh, or the search?

For a solution of `morea register` (its two meshes, `mesh_moving.vtu` and
`mesh_fixed.vtu`), keeps the source (moving-side) mesh as the optimiser left
it and fits the target (fixed-side) mesh's points directly to the fixed
structures' surfaces, fold-free: a least-squares fit of the map's contour
match, by damped Gauss-Newton steps per point. Then scores both target meshes
alike, on other surface samples than the fit saw: the moving surface of each
structure carried through the piecewise-affine map, its distance to the fixed
surface (mean and 95th percentile, mm). What the fit reaches bounds what the
search could reach with this mesh; the gap to the optimiser's own target mesh
is left to the search.

    python -m study.contour_capacity --problem PREPROCESSED --solution RUN/best_guidance [--json OUT.json]

PREPROCESSED is the problem folder the run registered (`morea preprocess`
with the run's parameters writes it): fixed_masks/ and moving_masks/.
"""
import argparse
import base64
import json
import struct
import xml.etree.ElementTree as ElementTree
import zlib
from pathlib import Path

import numpy as np
import SimpleITK as sitk
from scipy import ndimage

CONTOUR_ORIGINS = (3, 4)  # contour and surface vertices (VtuWriter's "origin")
CORNER, FACE = 0, 1


def read_vtu(path):
    """Points, tetrahedra and point arrays of a VTU that VtuWriter wrote
    (binary, zlib-compressed, UInt32 headers)."""
    arrays = {}
    for element in ElementTree.parse(path).iter("DataArray"):
        text = element.text.strip()
        header = base64.b64decode(text[:24])  # blocks, block size, last size, first compressed size
        blocks = struct.unpack("<I", header[:4])[0]
        header_length = 4 * (3 + blocks)
        encoded_header = 4 * ((header_length + 2) // 3)
        sizes = struct.unpack("<%dI" % (3 + blocks), base64.b64decode(text[:encoded_header]))[3:]
        payload = base64.b64decode(text[encoded_header:])
        raw, offset = b"", 0
        for size in sizes:
            raw += zlib.decompress(payload[offset:offset + size])
            offset += size
        dtype = {"Float64": "<f8", "Int64": "<i8", "UInt8": "u1"}[element.get("type")]
        values = np.frombuffer(raw, dtype=dtype)
        components = int(element.get("NumberOfComponents", "1"))
        arrays[element.get("Name")] = values.reshape(-1, components) if components > 1 else values
    tetrahedra = arrays["connectivity"].reshape(-1, 4)
    return arrays["Points"].copy(), tetrahedra, arrays


class SignedDistance:
    """Signed distance (mm, negative inside) to a mask's surface, trilinear."""

    def __init__(self, mask_path):
        image = sitk.ReadImage(str(mask_path))
        mask = sitk.GetArrayFromImage(image).transpose(2, 1, 0) > 0  # x, y, z
        spacing = np.array(image.GetSpacing())
        outside = ndimage.distance_transform_edt(~mask, sampling=spacing)
        inside = ndimage.distance_transform_edt(mask, sampling=spacing)
        self.values = np.where(mask, -inside + 0.5 * spacing.min(), outside - 0.5 * spacing.min())
        self.origin = np.array(image.GetOrigin())
        self.to_index = np.linalg.inv(np.array(image.GetDirection()).reshape(3, 3) * spacing)
        self.mask = mask
        self.image = image

    def __call__(self, points):
        index = (points - self.origin) @ self.to_index.T
        return ndimage.map_coordinates(self.values, index.T, order=1, mode="nearest")

    def gradient(self, points, h=0.5):
        return np.stack([(self(points + h * e) - self(points - h * e)) / (2 * h) for e in np.eye(3)], axis=1)

    def surface_points(self, limit, seed=1):
        """Centres of the mask's voxels that touch the background, physical
        space; where the crop cuts the structure is no surface."""
        eroded = ndimage.binary_erosion(self.mask, border_value=1)
        index = np.argwhere(self.mask & ~eroded).astype(float)
        if len(index) > limit:
            index = index[np.random.default_rng(seed).choice(len(index), limit, replace=False)]
        return np.array([self.image.TransformContinuousIndexToPhysicalPoint(tuple(i)) for i in index])


def signed_volumes(points, tetrahedra):
    p = points[tetrahedra]
    return np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])) / 6.0


def locate(points, source, tetrahedra, chunk=256):
    """The source tetrahedron of each point (-1: in none) and its barycentric weights."""
    corners = source[tetrahedra]
    inverse = np.linalg.inv(np.stack([corners[:, k] - corners[:, 0] for k in (1, 2, 3)], axis=2))
    where = np.full(len(points), -1)
    weights = np.zeros((len(points), 4))
    for start in range(0, len(points), chunk):
        p = points[start:start + chunk]
        local = np.einsum("tij,ptj->pti", inverse, p[:, None, :] - corners[None, :, 0])
        w = np.concatenate([1.0 - local.sum(axis=2, keepdims=True), local], axis=2)
        inside = (w >= -1e-9).all(axis=2)
        hit = inside.any(axis=1)
        t = inside.argmax(axis=1)
        where[start:start + chunk] = np.where(hit, t, -1)
        weights[start:start + chunk] = w[np.arange(len(p)), t]
    return where, weights


def carry(points, source, target, tetrahedra):
    """Maps points lying in the source mesh through the piecewise-affine map
    onto the target mesh: the mapped points and which of `points` lay in a
    tetrahedron (the others are left out)."""
    where, weights = locate(points, source, tetrahedra)
    found = where >= 0
    return np.einsum("pk,pkj->pj", weights[found], target[tetrahedra[where[found]]]), found


def fit_target(source, target, tetrahedra, origin, samples, fixed, iterations=100, damping=0.5):
    """Moves the target mesh's free points so that the map carries each
    structure's moving surface samples p to where the fixed signed distance
    equals the moving one: per point a damped Gauss-Newton step on
    sum (d_fixed(T(p)) - d_moving(p))^2 over the samples in its tetrahedra
    (`samples`: structure -> (points, d_moving at them)). Corners and face
    points stay. A step is halved (up to three times) while it would flip a
    tetrahedron or leave it under 5 % of its volume, else the point keeps its
    place this round: the mesh stays fold-free."""
    fitted = target.copy()
    sign = np.sign(signed_volumes(target, tetrahedra))
    reference = np.abs(signed_volumes(target, tetrahedra))
    free = ~np.isin(origin, (CORNER, FACE))
    incident = [[] for _ in range(len(target))]
    for t, tet in enumerate(tetrahedra):
        for a in tet:
            incident[a].append(t)
    located = {}
    for s, (points, goals) in samples.items():
        where, weights = locate(points, source, tetrahedra)
        found = where >= 0
        located[s] = (tetrahedra[where[found]], weights[found], goals[found])
    for _ in range(iterations):
        gradient = np.zeros_like(fitted)
        curvature = np.zeros(len(fitted))
        for s, (corners, weights, goals) in located.items():
            mapped = np.einsum("pk,pkj->pj", weights, fitted[corners])
            residual = fixed[s](mapped) - goals
            normal = fixed[s].gradient(mapped)
            for k in range(4):
                np.add.at(gradient, corners[:, k], (residual * weights[:, k])[:, None] * normal)
                np.add.at(curvature, corners[:, k], weights[:, k] ** 2 * (normal * normal).sum(axis=1))
        moving = np.where(free & (curvature > 1e-9))[0]
        steps = -damping * gradient[moving] / curvature[moving, None]
        for i, step in zip(moving, steps):  # one point at a time, halved until no tetrahedron folds
            old = fitted[i].copy()
            t = incident[i]
            for fraction in (1.0, 0.5, 0.25, 0.125):
                fitted[i] = old + fraction * step
                if np.all(signed_volumes(fitted, tetrahedra[t]) * sign[t] > 0.05 * reference[t]):
                    break
            else:
                fitted[i] = old
    return fitted


def contour_match(source, target, tetrahedra, surfaces, moving, fixed):
    """Per structure: |d_fixed(T(p)) - d_moving(p)| over its moving surface
    points p (as the guidance objective compares them), mean and 95th percentile."""
    scores = {}
    for s, points in surfaces.items():
        carried, found = carry(points, source, target, tetrahedra)
        d = np.abs(fixed[s](carried) - moving[s](points[found]))
        scores[s] = {"mean_mm": float(d.mean()), "p95_mm": float(np.percentile(d, 95)), "points": int(len(d))}
    return scores


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problem", required=True, type=Path)
    parser.add_argument("--solution", required=True, type=Path, help="a solution folder of `morea register`")
    parser.add_argument("--mesh-structures", default="",
                        help="the structures of the mesh's indices, in order (default: the guidance selection -1)")
    parser.add_argument("--structures", default="", help="comma-separated; default: those the mesh follows")
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--surface-points", type=int, default=4000, help="per structure, for scoring")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)

    source, tetrahedra, moving_arrays = read_vtu(args.solution / "mesh_moving.vtu")
    target, _, _ = read_vtu(args.solution / "mesh_fixed.vtu")
    origin = moving_arrays["origin"].astype(int)
    structure = moving_arrays["structure"].astype(int)
    # The mesh's structure indices follow the guidance selection (all masks
    # but "body", in name order), then rigid structures that do not guide.
    if args.mesh_structures:
        names = args.mesh_structures.split(",")
    else:
        names = sorted(p.name[:-len(".nii.gz")] for p in (args.problem / "fixed_masks").glob("*.nii.gz"))
        names = [n for n in names if n.lower() != "body"]
    wanted = args.structures.split(",") if args.structures else names
    index = {name: names.index(name) for name in wanted if name in names}
    fixed = {index[n]: SignedDistance(args.problem / "fixed_masks" / f"{n}.nii.gz") for n in index}
    moving = {index[n]: SignedDistance(args.problem / "moving_masks" / f"{n}.nii.gz") for n in index}
    # The fit sees one sample of each moving surface, the scores another.
    surfaces = {s: moving[s].surface_points(args.surface_points, seed=2) for s in moving}
    training = {s: moving[s].surface_points(args.surface_points, seed=1) for s in moving}
    samples = {s: (points, moving[s](points)) for s, points in training.items()}

    optimiser = contour_match(source, target, tetrahedra, surfaces, moving, fixed)
    fitted_target = fit_target(source, target, tetrahedra, origin, samples, fixed, args.iterations)
    fitted = contour_match(source, fitted_target, tetrahedra, surfaces, moving, fixed)
    # A contour vertex matches when d_fixed(t) = d_moving(s), as the guidance objective has it.
    goals = {s: moving[s](source) for s in moving}
    contour = np.isin(origin, CONTOUR_ORIGINS) & (structure >= 0)
    vertex = {}
    for n, s in index.items():
        points = np.where(contour & (structure == s))[0]
        goal = goals[s][points]
        vertex[n] = {"optimiser_mm": float(np.abs(fixed[s](target[points]) - goal).mean()),
                     "fitted_mm": float(np.abs(fixed[s](fitted_target[points]) - goal).mean()),
                     "vertices": int(len(points))}
    folded = int(np.sum(np.sign(signed_volumes(fitted_target, tetrahedra)) != np.sign(signed_volumes(target, tetrahedra))))
    result = {"solution": str(args.solution), "folded_tetrahedra_after_fit": folded, "structures": {
        n: {"optimiser": optimiser[s], "fitted": fitted[s], "contour_vertices": vertex[n]} for n, s in index.items()}}
    print("structure       carried moving surface -> fixed surface (mm)      contour vertices (mm)")
    print("                optimiser mean / p95     fitted mean / p95        optimiser   fitted")
    for n, r in result["structures"].items():
        print(f"{n:14s}  {r['optimiser']['mean_mm']:7.2f} / {r['optimiser']['p95_mm']:6.2f}       "
              f"{r['fitted']['mean_mm']:7.2f} / {r['fitted']['p95_mm']:6.2f}          "
              f"{r['contour_vertices']['optimiser_mm']:6.2f}   {r['contour_vertices']['fitted_mm']:6.2f}")
    print(f"folded tetrahedra after the fit: {folded}")
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
