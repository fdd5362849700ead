# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Shared helpers of the comparison study: the morea binary, subprocesses with
timing, displacement-field IO and inversion, composite masks.

Field conventions (those of `morea evaluate`, README "Conventions"):
  * fixed_to_moving.nii.gz lives on the fixed grid; a fixed point x maps to the
    moving point x + u(x) (the transform used to resample the moving image onto
    the fixed grid: elastix's and ANTs' "forward" output transform);
  * moving_to_fixed.nii.gz lives on the moving grid and maps a moving point y to
    the fixed point y + v(y).
Vectors are in physical LPS millimetres, as ITK (and so elastix and ANTs) store them.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parent.parent
PARAMS_DIR = Path(__file__).resolve().parent / "params"


def find_morea(explicit: str | None = None) -> str:
    """The morea binary: --morea, $MOREA, the build trees, then PATH."""
    candidates = [explicit, os.environ.get("MOREA")]
    candidates += [str(REPO_ROOT / "build" / "bin" / "morea")]
    for c in candidates:
        if c and Path(c).is_file() and os.access(c, os.X_OK):
            return str(Path(c).resolve())
    found = shutil.which("morea")
    if found:
        return found
    raise SystemExit("morea binary not found: pass --morea PATH or set $MOREA")


def run_command(cmd: list[str], log: Path, env: dict | None = None,
                cwd: Path | None = None) -> float:
    """Runs `cmd`, appending its output to `log`; returns the wall time in
    seconds. Raises RuntimeError (with the log's tail) on a non-zero exit."""
    log.parent.mkdir(parents=True, exist_ok=True)
    full_env = dict(os.environ)
    if env:
        full_env.update(env)
    start = time.perf_counter()
    with open(log, "a") as out:
        out.write("$ " + " ".join(str(c) for c in cmd) + "\n")
        out.flush()
        proc = subprocess.run([str(c) for c in cmd], stdout=out, stderr=subprocess.STDOUT,
                              env=full_env, cwd=cwd)
    seconds = time.perf_counter() - start
    if proc.returncode != 0:
        tail = log.read_text(errors="replace")[-3000:]
        raise RuntimeError(f"command failed ({proc.returncode}): {' '.join(map(str, cmd))}\n{tail}")
    return seconds


def write_json(path: Path, data) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True))
    tmp.replace(path)


def read_json(path: Path):
    return json.loads(Path(path).read_text())


def md5(path: Path) -> str:
    import hashlib
    h = hashlib.md5()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def fill_placeholders(text: str, values: dict) -> str:
    """Replaces $name tokens (longest names first); fails on any left over."""
    for name in sorted(values, key=len, reverse=True):
        text = text.replace("$" + name, str(values[name]))
    import re
    left = [m for m in re.findall(r"\$[A-Za-z_]+", text)]
    if left:
        raise ValueError(f"unfilled placeholders: {sorted(set(left))}")
    return text


# ---------------------------------------------------------------------------
# Problem folder
# ---------------------------------------------------------------------------

def problem_image(problem: Path, role: str) -> Path:
    for ext in (".nii.gz", ".mha", ".nrrd", ".nii"):
        p = problem / f"{role}{ext}"
        if p.exists():
            return p
    raise FileNotFoundError(f"{problem}: no {role} image")


def structure_names(problem: Path) -> list[str]:
    """Structures with a mask on both images of a problem folder."""
    def names(role):
        d = problem / f"{role}_masks"
        if not d.is_dir():
            return set()
        return {p.name.split(".")[0] for p in d.iterdir() if p.is_file()}
    return sorted(names("fixed") & names("moving"))


def mask_path(problem: Path, role: str, name: str) -> Path:
    d = problem / f"{role}_masks"
    for p in sorted(d.iterdir()):
        if p.name.split(".")[0] == name:
            return p
    raise FileNotFoundError(f"{d}: no mask {name}")


def write_composite_masks(problem: Path, out_dir: Path) -> tuple[Path, Path]:
    """The paper's composite mask images: every structure mask of a scan in one
    image, each structure with its own homogeneous value (1, 2, ...). Structures
    are painted from the largest (on the fixed image) to the smallest so that a
    structure inside another (e.g. an organ inside the body) stays visible.
    Returns (fixed composite, moving composite)."""
    import SimpleITK as sitk
    out_dir.mkdir(parents=True, exist_ok=True)
    names = structure_names(problem)
    volumes = {n: float(sitk.GetArrayViewFromImage(
        sitk.ReadImage(str(mask_path(problem, "fixed", n)))).astype(bool).sum()) for n in names}
    order = sorted(names, key=lambda n: (-volumes[n], n))
    result = []
    for role in ("fixed", "moving"):
        ref = sitk.ReadImage(str(problem_image(problem, role)))
        comp = np.zeros(sitk.GetArrayViewFromImage(ref).shape, dtype=np.float32)
        for value, n in enumerate(order, start=1):
            m = sitk.ReadImage(str(mask_path(problem, role, n)))
            comp[sitk.GetArrayViewFromImage(m) > 0] = float(value)
        img = sitk.GetImageFromArray(comp)
        img.CopyInformation(ref)
        path = out_dir / f"{role}_composite.nii.gz"
        sitk.WriteImage(img, str(path))
        result.append(path)
    (out_dir / "composite_values.json").write_text(json.dumps(
        {n: v for v, n in enumerate(order, start=1)}, indent=1))
    return result[0], result[1]


# ---------------------------------------------------------------------------
# Displacement fields
# ---------------------------------------------------------------------------

def read_field(path: Path):
    """(array [z, y, x, 3] float64 of LPS mm vectors, SimpleITK reference image)."""
    import SimpleITK as sitk
    img = sitk.ReadImage(str(path))
    if img.GetNumberOfComponentsPerPixel() != 3:
        raise ValueError(f"{path}: not a 3-component displacement field")
    arr = sitk.GetArrayFromImage(img).astype(np.float64)
    return arr, img


def write_field(path: Path, array: np.ndarray, reference) -> None:
    """Writes a [z, y, x, 3] LPS displacement array on `reference`'s grid as a
    vector image of doubles (written under a temporary name, then renamed)."""
    import SimpleITK as sitk
    img = sitk.GetImageFromArray(np.ascontiguousarray(array, dtype=np.float64), isVector=True)
    img.SetOrigin(reference.GetOrigin())
    img.SetSpacing(reference.GetSpacing())
    img.SetDirection(reference.GetDirection())
    path = Path(path)
    tmp = path.with_name("tmp_" + path.name)
    sitk.WriteImage(img, str(tmp))
    tmp.replace(path)


def same_grid(a, b, tol: float = 1e-4) -> bool:
    return (a.GetSize() == b.GetSize()
            and np.allclose(a.GetOrigin(), b.GetOrigin(), atol=tol)
            and np.allclose(a.GetSpacing(), b.GetSpacing(), atol=tol)
            and np.allclose(a.GetDirection(), b.GetDirection(), atol=tol))


def _grid_points(reference) -> np.ndarray:
    """Physical coordinates [z, y, x, 3] (x, y, z order in the last axis)."""
    size = reference.GetSize()
    idx = np.stack(np.meshgrid(np.arange(size[2]), np.arange(size[1]), np.arange(size[0]),
                               indexing="ij"), axis=-1)[..., ::-1].astype(np.float64)
    direction = np.array(reference.GetDirection()).reshape(3, 3)
    spacing = np.array(reference.GetSpacing())
    origin = np.array(reference.GetOrigin())
    return origin + (idx * spacing) @ direction.T


def sample_field(field: np.ndarray, field_ref, points: np.ndarray) -> np.ndarray:
    """Trilinear samples of a displacement field at physical points (outside the
    grid: the nearest border value)."""
    from scipy.ndimage import map_coordinates
    direction = np.array(field_ref.GetDirection()).reshape(3, 3)
    spacing = np.array(field_ref.GetSpacing())
    origin = np.array(field_ref.GetOrigin())
    cidx = ((points - origin) @ direction) / spacing          # continuous (x, y, z) index
    coords = [cidx[..., 2], cidx[..., 1], cidx[..., 0]]       # array order z, y, x
    out = np.empty(points.shape, dtype=np.float64)
    for c in range(3):
        out[..., c] = map_coordinates(field[..., c], coords, order=1, mode="nearest")
    return out


def invert_field(field: np.ndarray, field_ref, target_ref, iterations: int = 30,
                 tolerance: float = 1e-3) -> tuple[np.ndarray, dict]:
    """Numerical inverse of x -> x + u(x) on `target_ref`'s grid by fixed-point
    iteration v(y) = -u(y + v(y)). Returns (v, {'iterations', 'max_residual_mm'})."""
    y = _grid_points(target_ref)
    v = np.zeros_like(y)
    residual = np.inf
    for it in range(1, iterations + 1):
        nv = -sample_field(field, field_ref, y + v)
        residual = float(np.abs(nv - v).max())
        v = nv
        if residual < tolerance:
            break
    return v, {"iterations": it, "max_change_mm": residual}


def python_executable() -> str:
    return sys.executable
