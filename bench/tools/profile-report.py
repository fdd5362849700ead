#!/usr/bin/env python3
"""Names the functions in a profile written by main-thread-profiler.c.

  profile-report.py PROFILE [--binary PATH]... [--under TEXT] [--callers-of TEXT] [--skip FRACTION] [--top N]

PROFILE holds the sampled call stacks' return addresses and the process's
memory map. Each address is resolved against a local, unstripped copy of the
binary it fell in (--binary, matched by file name; the build the bundle was
stripped from), or else named by its library. Prints the share of samples
per function as the innermost frame (self) and anywhere on the stack
(inclusive); with --under, only samples whose stack holds a function whose
name contains TEXT, with the functions called directly below it.
"""
import argparse
import bisect
import collections
import os
import subprocess


def load_symbols(path):
    """Sorted (address, name) of a binary's functions, and its LOAD segments."""
    out = subprocess.run(["nm", "-C", "-n", "--defined-only", path], capture_output=True, text=True).stdout
    starts, names = [], []
    for line in out.splitlines():
        parts = line.split(" ", 2)
        if len(parts) == 3 and parts[1] in "tTwW":
            starts.append(int(parts[0], 16))
            names.append(parts[2])
    segments = []
    for line in subprocess.run(["readelf", "-lW", path], capture_output=True, text=True).stdout.splitlines():
        f = line.split()
        if f and f[0] == "LOAD":
            segments.append((int(f[1], 16), int(f[2], 16), int(f[4], 16)))  # offset, vaddr, filesz
    return starts, names, segments


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("profile")
    parser.add_argument("--binary", action="append", default=[])
    parser.add_argument("--under")
    parser.add_argument("--callers-of", help="the callers of the samples whose innermost frame contains this")
    parser.add_argument("--skip", type=float, default=0.0,
                        help="leave out this fraction of the (--under) samples, the first ones (warming up)")
    parser.add_argument("--top", type=int, default=40)
    args = parser.parse_args()

    stacks, maps = [], []
    with open(args.profile) as f:
        header = f.readline().strip()
        for line in f:
            if line.startswith("s"):
                stacks.append([int(a, 16) for a in line.split()[1:]])
            elif line.startswith("m "):
                p = line[2:].split()
                if len(p) >= 6 and "x" in p[1]:
                    lo, hi = (int(v, 16) for v in p[0].split("-"))
                    maps.append((lo, hi, int(p[2], 16), p[5]))
    maps.sort()
    starts = [m[0] for m in maps]
    binaries = {os.path.basename(b): load_symbols(b) for b in args.binary}
    cache = {}

    def name(address):
        if address in cache:
            return cache[address]
        i = bisect.bisect_right(starts, address) - 1
        result = "?"
        if i >= 0 and address < maps[i][1]:
            lo, _, offset, path = maps[i]
            base = os.path.basename(path)
            result = base
            if base in binaries:
                syms, names, segments = binaries[base]
                fileoffset = address - lo + offset
                for seg_offset, vaddr, size in segments:
                    if seg_offset <= fileoffset < seg_offset + size:
                        v = fileoffset - seg_offset + vaddr
                        k = bisect.bisect_right(syms, v) - 1
                        if k >= 0:
                            result = names[k]
                        break
        cache[address] = result
        return result

    samples = []
    for stack in stacks:
        # Frames 0 and 1 are the signal handler and the kernel's return
        # trampoline; frame 2 the interrupted instruction; the rest return
        # addresses (one byte back lands in the call).
        frames = [name(a) for a in stack[2:3]] + [name(a - 1) for a in stack[3:]]
        samples.append(frames)
    if args.under:
        samples = [s for s in samples if any(args.under in f for f in s)]
    samples = samples[int(args.skip * len(samples)):]
    total = len(samples)
    print(f"{header}; {total} samples shown")
    if not total:
        return

    def show(title, counter):
        print(f"\n{title}")
        for fn, n in counter.most_common(args.top):
            print(f"{100.0 * n / total:6.2f}%  {n:7d}  {fn[:200]}")

    show("self (innermost frame)", collections.Counter(s[0] for s in samples if s))
    show("inclusive (anywhere on the stack)", collections.Counter(f for s in samples for f in set(s)))
    if args.under:
        below = collections.Counter()
        for s in samples:
            # The outermost frame that matches, and the function it called.
            k = max(i for i, f in enumerate(s) if args.under in f)
            below[s[k - 1] if k > 0 else "(itself)"] += 1
        show(f"called directly below '{args.under}'", below)
    if args.callers_of:
        callers = collections.Counter()
        for s in samples:
            if s and args.callers_of in s[0]:
                rest = [f for f in s if args.callers_of not in f]
                callers[rest[0] if rest else "?"] += 1
        show(f"first caller outside '{args.callers_of}' of the innermost frames in it", callers)


if __name__ == "__main__":
    main()
