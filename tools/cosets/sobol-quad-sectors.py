#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""How many texture sectors each quad of 4 lanes touches when a warp's lanes
take one coset of W (CosetBases in src/core/SampleCosets.cxx), and how many
with the best choice of the two basis vectors of W that span a quad.

Sectors are modelled for the slice-pair intensity texels (4 bytes; a 32-byte
sector of 8 x 1 or 4 x 2 texels of one layer); a sample reads the 2 x 2
texels around it in layer floor(z + 1/2). Points come from
tools/cosets/sobol-warp-cosets.py (the same tetrahedra and shifts).

Usage: tools/cosets/sobol-quad-sectors.py  (needs numpy; about a minute)
"""
import importlib.util
import itertools
import os

import numpy as np

_here = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location("cosets", os.path.join(_here, "sobol-warp-cosets.py"))
cosets = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cosets)

BASES = [[216, 392, 464, 332, 432], [516, 264, 784, 576, 128], [516, 264, 912, 1696, 576],
         [3204, 3976, 3344, 2080, 576], [6408, 3344, 2080, 576, 5760], [6408, 12816, 14112, 15680, 10624]]


def sectors_per_group(rows, p, group, shape):
    """Mean distinct sectors per group of `group` consecutive lanes."""
    total, groups = 0, 0
    for row in rows:
        q = p[row]
        x = np.floor(q[:, 0] - 0.5).astype(int)
        y = np.floor(q[:, 1] - 0.5).astype(int)
        layer = np.floor(q[:, 2] + 0.5).astype(int)
        for g in range(0, 32, group):
            touched = {((x[i] + dx) // shape[0], (y[i] + dy) // shape[1], layer[i])
                       for i in range(g, g + group) for dx in (0, 1) for dy in (0, 1)}
            total += len(touched)
            groups += 1
    return total / groups


def lane_rows_of(basis, bits):
    """The cosets of span(basis) in lane order: span() lists element i as the
    XOR of the basis vectors of i's set bits, lane i's offset."""
    return cosets.block_cosets(basis, bits)


def with_quad(pair, basis):
    """A basis of span(basis) whose first two vectors are `pair`."""
    out = list(pair)
    for v in cosets.span(basis)[1:]:
        if v not in cosets.span(out):
            out.append(v)
        if len(out) == 5:
            break
    return out


def main():
    rng = np.random.default_rng(1)
    for level, basis in enumerate(BASES):
        bits = 9 + level
        corners = cosets.CORNERS * ((1.5 * (1 << bits) / 984) ** (1 / 3))
        n = 1 << bits
        blocks = [cosets.block_points(bits, n * (3 + t), [int(x) for x in rng.integers(0, 2**32, 4)], corners)
                  for t in range(2)]
        pairs = {frozenset((a, b, a ^ b)) for a, b in itertools.combinations(cosets.span(basis)[1:], 2)}
        for shape in [(8, 1), (4, 2)]:
            now = np.mean([sectors_per_group(lane_rows_of(basis, bits), p, 4, shape) for p in blocks])
            best = min((sectors_per_group(lane_rows_of(with_quad(sorted(q)[:2], basis), bits), blocks[0], 4, shape),
                        sorted(q)[:2]) for q in pairs)
            best_both = np.mean([sectors_per_group(lane_rows_of(with_quad(best[1], basis), bits), p, 4, shape)
                                 for p in blocks])
            print(f"2^{bits}, sectors of {shape[0]} x {shape[1]} texels: {now:.2f} per quad now, "
                  f"{best_both:.2f} with quads spanned by {best[1]}", flush=True)


if __name__ == "__main__":
    main()
