#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Finds the index subspaces W whose cosets the texture sampling kernel's lanes
take in whole chunks of 512 samples (CosetBases in src/core/SampleCosets.cxx).

A tetrahedron's sample k is the scrambled Sobol point of Gray code k ^ (k >> 1);
both the Gray code and the direction numbers are linear over XOR, so samples
whose indices differ by x in an aligned block of 2^9 differ by the same XOR of
direction numbers wherever the block lies. This script measures, for every
offset x, how far apart such samples lie in a tetrahedron of about 1000 voxels,
grows 5-dimensional subspaces greedily from the closest offsets, and keeps the
one whose cosets of 32 samples touch the fewest texture-sector-sized blocks
(4 x 4 x 2 texels) with their trilinear footprints. It prints those counts for
consecutive lanes and for the chosen cosets.

For larger aligned blocks of 2^B samples (--bits B, 10 to 14), W is the set of
offsets that keep the top a_d bits of every Sobol coordinate d (an elementary
box; the bits' total is B - 5): it tries every shape whose a_d lie within 2 of
each other, in a tetrahedron of 1.5 x 2^B voxels, and prints the best three
with the counts for consecutive lanes and for the 2^9 W in each aligned 512.

Usage: tools/cosets/sobol-warp-cosets.py [--bits B]  (needs numpy; seconds to a minute)
"""
import itertools
import sys

import numpy as np

BITS = 9
BLOCK = 1 << BITS


def direction_numbers():
    """Sobol dimensions 1-4 as in src/core/TetrahedronSampling.cxx."""
    v = [[0] * 32 for _ in range(4)]
    for i in range(32):
        v[0][i] = 1 << (31 - i)
    degree, coefficients, initial = [1, 2, 3], [0, 1, 1], [[1], [1, 3], [1, 3, 1]]
    for d in range(3):
        s, m = degree[d], list(initial[d]) + [0] * (32 - degree[d])
        for i in range(s, 32):
            m[i] = m[i - s] ^ (m[i - s] << s)
            for k in range(1, s):
                if (coefficients[d] >> (s - 1 - k)) & 1:
                    m[i] ^= m[i - k] << k
        for i in range(32):
            v[d + 1][i] = (m[i] << (31 - i)) & 0xFFFFFFFF
    return v


V = direction_numbers()
CORNERS = np.array([[0, 0, 0], [18, 0, 0], [6, 16, 0], [7, 6, 20.5]], float)  # 984 voxels


def points(first, shift):
    """Sample positions (voxels) of indices first .. first + BLOCK - 1."""
    out = np.empty((BLOCK, 3))
    for n, k in enumerate(range(first, first + BLOCK)):
        gray, state = k ^ (k >> 1), [0, 0, 0, 0]
        for j in range(32):
            if (gray >> j) & 1:
                for d in range(4):
                    state[d] ^= V[d][j]
        e = -np.log([((state[d] ^ shift[d]) + 0.5) / 2**32 for d in range(4)])
        out[n] = (e / e.sum()) @ CORNERS
    return out


def span(basis):
    s = [0]
    for w in basis:
        s += [q ^ w for q in s]
    return s


def cosets(basis):
    members, seen, rows = span(basis), set(), []
    for k in range(BLOCK):
        if k not in seen:
            row = [k ^ m for m in members]
            seen.update(row)
            rows.append(row)
    return rows


def sectors(rows, p, shape=(4, 4, 2)):
    counts = []
    for row in rows:
        first = np.floor(p[row] - 0.5).astype(int)
        touched = {
            ((q[0] + dx) // shape[0], (q[1] + dy) // shape[1], (q[2] + dz) // shape[2])
            for q in first
            for dx, dy, dz in itertools.product((0, 1), repeat=3)
        }
        counts.append(len(touched))
    return float(np.mean(counts))


def state_of(k):
    """The unshifted Sobol state of index k (Gray-code order)."""
    gray, state = k ^ (k >> 1), [0, 0, 0, 0]
    for j in range(32):
        if (gray >> j) & 1:
            for d in range(4):
                state[d] ^= V[d][j]
    return state


def null_space(rows, bits):
    """A basis of {x < 2^bits : every row & x has even parity} (over GF(2))."""
    pivots, reduced = [], []
    for r in rows:
        for p, q in zip(pivots, reduced):
            if (r >> p) & 1:
                r ^= q
        if r:
            p = r.bit_length() - 1
            reduced = [q ^ r if (q >> p) & 1 else q for q in reduced] + [r]
            pivots.append(p)
    basis = []
    for f in (i for i in range(bits) if i not in pivots):
        x = 1 << f
        for p, q in zip(pivots, reduced):
            if (q >> f) & 1:
                x |= 1 << p
        basis.append(x)
    return basis


def box_basis(shape, bits):
    """W for an elementary box: offsets that keep the top shape[d] bits of
    coordinate d."""
    columns = [state_of(1 << i) for i in range(bits)]
    rows = [sum(((columns[i][d] >> (31 - r)) & 1) << i for i in range(bits)) for d in range(4) for r in range(shape[d])]
    return null_space(rows, bits)


def block_points(bits, first, shift, corners):
    """Sample positions (voxels) of indices first .. first + 2^bits - 1."""
    k = np.arange(first, first + (1 << bits), dtype=np.uint64)
    gray = k ^ (k >> np.uint64(1))
    state = np.zeros((4, len(k)), np.uint64)
    for j in range(32):
        bit = ((gray >> np.uint64(j)) & np.uint64(1)).astype(bool)
        for d in range(4):
            state[d][bit] ^= np.uint64(V[d][j])
    e = np.stack([-np.log(((state[d] ^ np.uint64(shift[d])).astype(float) + 0.5) / 2**32) for d in range(4)], 1)
    return (e / e.sum(1, keepdims=True)) @ corners


def block_cosets(basis, bits):
    members, seen, rows = np.array(span(basis)), np.zeros(1 << bits, bool), []
    for k in range(1 << bits):
        if not seen[k]:
            row = k ^ members
            seen[row] = True
            rows.append(row)
    return rows


def larger_blocks(bits):
    rng = np.random.default_rng(1)
    corners = CORNERS * ((1.5 * (1 << bits) / 984) ** (1 / 3))
    n = 1 << bits
    blocks = [block_points(bits, n * (3 + t), [int(x) for x in rng.integers(0, 2**32, 4)], corners) for t in range(2)]
    consecutive = [np.arange(32 * r, 32 * r + 32) for r in range(n // 32)]
    small = [r + BLOCK * s for s in range(n // BLOCK) for r in block_cosets([216, 392, 464, 332, 432], BITS)]
    print(f"2^{bits}: consecutive lanes {np.mean([sectors(consecutive, p) for p in blocks]):.1f}, "
          f"2^9 cosets {np.mean([sectors(small, p) for p in blocks]):.1f} blocks per row")
    found = []
    for shape in itertools.product(range(bits - 4), repeat=4):
        if sum(shape) != bits - 5 or max(shape) - min(shape) > 2:
            continue
        basis = box_basis(shape, bits)
        if len(basis) == 5:
            found.append((np.mean([sectors(block_cosets(basis, bits), p) for p in blocks]), shape, basis))
    for score, shape, basis in sorted(found)[:3]:
        print(f"  top bits {shape}: W = {basis}: {score:.1f} blocks per row")


def main():
    rng = np.random.default_rng(1)
    blocks = [points(BLOCK * (5 + t), [int(x) for x in rng.integers(0, 2**32, 4)]) for t in range(4)]
    distance = np.zeros(BLOCK)
    every = np.arange(BLOCK)
    for x in range(1, BLOCK):
        distance[x] = np.mean([np.linalg.norm(p - p[every ^ x], axis=1).mean() for p in blocks])
    order = [int(x) for x in np.argsort(distance[1:]) + 1]
    best = None
    for start in order[:30]:
        basis = [start]
        while len(basis) < 5:
            members = span(basis)
            x = min((x for x in order if x not in members), key=lambda x: max(distance[q ^ x] for q in members))
            basis.append(x)
        score = np.mean([sectors(cosets(basis), p) for p in blocks])
        if best is None or score < best[0]:
            best = (score, basis)
    consecutive = [list(range(32 * r, 32 * r + 32)) for r in range(BLOCK // 32)]
    print(f"consecutive lanes: {np.mean([sectors(consecutive, p) for p in blocks]):.1f} blocks per row")
    print(f"cosets of W = {best[1]}: {best[0]:.1f} blocks per row")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--bits":
        larger_blocks(int(sys.argv[2]))
    else:
        main()
