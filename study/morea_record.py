# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The record of one MOREA run of the study (run.json) from `morea register`'s
summary.json, and the check that a run's preprocessing is the study's problem:
standard library only, so that bench/run-study-morea.sh writes the same records
on a GPU machine that has no SimpleITK.

    python3 -m study.morea_record record REGISTER_DIR OUT.json --seed N --config NAME
            --parameters FILE --seconds S [--total-seconds T] [--host TEXT]
    python3 -m study.morea_record check REGISTER_DIR PROBLEM_DIR
            (exit 1, with the reason, when the grids or the landmarks differ)
    python3 -m study.morea_record md5 ROOT JOB.json   (the raw inputs are the study's)
"""
from __future__ import annotations

import argparse
import gzip
import hashlib
import json
import struct
import sys
import zlib
from array import array
from pathlib import Path

CHOSEN = "best_guidance"


def record(summary: dict, seed: int, parameters: str, config: str, seconds: float,
           total_seconds: float | None = None, host: str | None = None,
           extra_args: list[str] | None = None, solution: str = CHOSEN) -> dict:
    chosen = summary["solutions"][solution]
    rec = {
        "method": "morea", "seed": seed, "config": config, "parameters": str(parameters),
        "extra_args": list(extra_args or []), "chosen": solution,
        "chosen_objectives": {k: chosen[k] for k in ("magnitude", "intensity", "guidance", "id")},
        "voxel_fold_repair": chosen.get("voxel_fold_repair"),
        "front_size": summary.get("front_size"), "generations": summary.get("generations"),
        "backend": summary.get("backend"), "backend_note": summary.get("backend_note"),
        "threads": summary.get("threads"),
        "seconds": {"registration": seconds,
                    "total": seconds if total_seconds is None else total_seconds,
                    **{f"morea_{k}": v for k, v in summary.get("seconds", {}).items()}},
    }
    if host:
        rec["host"] = host
    return rec


# -- images without ITK: the MetaImage files `morea register` writes and the NIfTI
# files of `morea preprocess` (float32) ------------------------------------------

def read_mha(path: Path) -> tuple[dict, array]:
    raw = Path(path).read_bytes()
    header, pos = {}, 0
    while True:
        end = raw.index(b"\n", pos)
        line = raw[pos:end].decode("ascii").strip()
        pos = end + 1
        key, _, value = line.partition("=")
        header[key.strip()] = value.strip()
        if key.strip() == "ElementDataFile":
            break
    if header.get("ElementType") != "MET_FLOAT" or header.get("ElementDataFile") != "LOCAL":
        raise ValueError(f"{path}: only local MET_FLOAT data are read here")
    data = raw[pos:]
    if header.get("CompressedData", "False") == "True":
        data = zlib.decompress(data)
    values = array("f")
    values.frombytes(data)
    grid = {"size": [int(x) for x in header["DimSize"].split()],
            "spacing": [float(x) for x in header["ElementSpacing"].split()],
            "origin": [float(x) for x in header["Offset"].split()]}
    return grid, values


def read_nifti_gz(path: Path) -> tuple[dict, array]:
    raw = gzip.open(path).read()
    if struct.unpack("<i", raw[:4])[0] != 348:
        raise ValueError(f"{path}: not a little-endian NIfTI-1 file")
    dims = struct.unpack("<8h", raw[40:56])
    datatype = struct.unpack("<h", raw[70:72])[0]
    if datatype != 16:
        raise ValueError(f"{path}: only float32 NIfTI is read here")
    pixdim = struct.unpack("<8f", raw[76:108])
    offset = int(struct.unpack("<f", raw[108:112])[0])
    qoffset = struct.unpack("<3f", raw[268:280])
    values = array("f")
    n = dims[1] * dims[2] * dims[3]
    values.frombytes(raw[offset:offset + 4 * n])
    # NIfTI stores RAS: the LPS origin is (-x, -y, z) for an identity direction.
    grid = {"size": list(dims[1:4]), "spacing": list(pixdim[1:4]),
            "origin": [-qoffset[0], -qoffset[1], qoffset[2]]}
    return grid, values


def _landmarks(path: Path) -> list[list[float]]:
    lines = [ln.split() for ln in Path(path).read_text().splitlines() if ln.strip()]
    return [[float(v) for v in ln] for ln in lines[2:]]


def check(register_dir: Path, problem: Path, tolerance: float = 1e-4) -> list[str]:
    """Differences between a run's preprocessed inputs and the study's problem
    folder: grid, moving image voxels (the pre-alignment) and landmarks."""
    problems = []
    pre = register_dir / "preprocessed"
    for role in ("fixed", "moving"):
        g1, v1 = read_mha(pre / f"{role}.mha")
        g2, v2 = read_nifti_gz(problem / f"{role}.nii.gz")
        if g1["size"] != g2["size"]:
            problems.append(f"{role}: size {g1['size']} != the problem's {g2['size']}")
            continue
        for key in ("spacing", "origin"):
            if max(abs(a - b) for a, b in zip(g1[key], g2[key])) > 1e-3:
                problems.append(f"{role}: {key} {g1[key]} != the problem's {g2[key]}")
        worst = max((abs(a - b) for a, b in zip(v1, v2)), default=0.0)
        if worst > 1e-5:
            problems.append(f"{role}: voxels differ from the problem's by up to {worst:g}")
    for side in ("fixed", "moving"):
        a, b = pre / f"{side}_landmarks.txt", problem / f"{side}_landmarks.txt"
        if a.exists() != b.exists():
            problems.append(f"{side} landmarks: present in only one of run and problem")
        elif a.exists():
            la, lb = _landmarks(a), _landmarks(b)
            if len(la) != len(lb) or any(abs(x - y) > tolerance for p, q in zip(la, lb)
                                         for x, y in zip(p, q)):
                problems.append(f"{side} landmarks differ from the problem's")
    return problems


def md5_check(root: Path, expected: dict) -> list[str]:
    bad = []
    for rel, digest in expected.items():
        p = root / rel
        if not p.exists():
            bad.append(f"{rel}: missing")
            continue
        if hashlib.md5(p.read_bytes()).hexdigest() != digest:
            bad.append(f"{rel}: differs from the study's")
    return bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m study.morea_record", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("record")
    r.add_argument("register", type=Path)
    r.add_argument("out", type=Path)
    r.add_argument("--seed", type=int, required=True)
    r.add_argument("--config", required=True)
    r.add_argument("--parameters", required=True)
    r.add_argument("--seconds", type=float, required=True)
    r.add_argument("--total-seconds", type=float)
    r.add_argument("--host")
    r.add_argument("--extra-args", default="", help="the variant's extra arguments, one string")
    r.add_argument("--solution", default=CHOSEN, help="the selected solution scored (default: the study's choice)")
    c = sub.add_parser("check")
    c.add_argument("register", type=Path)
    c.add_argument("problem", type=Path)
    m = sub.add_parser("md5")
    m.add_argument("root", type=Path)
    m.add_argument("job", type=Path)
    a = ap.parse_args(argv)
    if a.command == "record":
        summary = json.loads((a.register / "summary.json").read_text())
        rec = record(summary, a.seed, a.parameters, a.config, a.seconds, a.total_seconds,
                     a.host, a.extra_args.split() if a.extra_args else [], a.solution)
        a.out.write_text(json.dumps(rec, indent=1, sort_keys=True))
        return 0
    if a.command == "check":
        problems = check(a.register, a.problem)
        for p in problems:
            print(f"{a.register}: {p}", file=sys.stderr)
        return 1 if problems else 0
    bad = md5_check(a.root, json.loads(a.job.read_text()).get("raw_md5", {}))
    for b in bad:
        print(f"{a.root}/{b}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
