#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Names the functions in a profile written by main-thread-profiler.c.

  profile-report.py PROFILE [--binary PATH]... [--under TEXT] [--callers-of TEXT] [--skip FRACTION] [--top N]
                    [--during INTERVALS]

PROFILE holds the sampled call stacks' return addresses and the process's
memory map. Each address is resolved against a local, unstripped copy of the
binary it fell in (--binary, matched by file name; the build the bundle was
stripped from), or else named by its library. Prints the share of samples
per function as the innermost frame (self) and anywhere on the stack
(inclusive); with --under, only samples whose stack holds a function whose
name contains TEXT, with the functions called directly below it. With
--during, only samples taken within the intervals a file lists (one
"START END" line each, CLOCK_MONOTONIC nanoseconds, as device-gaps.py writes
the device's idle gaps); with --per-interval TEXT as well, interval by
interval what the samples inside it did below the frame holding TEXT.
"""
import argparse
import bisect
import collections
import os
import re
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


def is_library(frame):
    """A frame named by its library alone (no symbols for it)."""
    return (".so" in frame and "(" not in frame) or frame.startswith(("[", "libcudart_static"))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("profile")
    parser.add_argument("--binary", action="append", default=[])
    parser.add_argument("--under")
    parser.add_argument("--callers-of", help="the callers of the samples whose innermost frame contains this")
    parser.add_argument("--skip", type=float, default=0.0,
                        help="leave out this fraction of the (--under) samples, the first ones (warming up)")
    parser.add_argument("--lines", help="source lines of the outermost frame in a function whose name holds this")
    parser.add_argument("--depth", type=int, default=0,
                        help="with --lines: the line this many inlined calls inside that frame's own")
    parser.add_argument("--top", type=int, default=40)
    parser.add_argument("--during", help="a file of START END lines (ns): only samples taken within them")
    parser.add_argument("--per-interval", metavar="TEXT",
                        help="with --during: per interval, the paths its samples took below the outermost frame "
                             "holding TEXT (e.g. RunGeneration)")
    parser.add_argument("--depth-below", type=int, default=4, help="with --per-interval: frames per path")
    args = parser.parse_args()

    stacks, times, maps = [], [], []
    time = None
    with open(args.profile) as f:
        header = f.readline().strip()
        for line in f:
            if line.startswith("t "):
                time = int(line.split()[1])
            elif line.startswith("s"):
                stacks.append([int(a, 16) for a in line.split()[1:]])
                times.append(time)
                time = None
            elif line.startswith("m "):
                p = line[2:].split()
                if len(p) >= 6 and "x" in p[1]:
                    lo, hi = (int(v, 16) for v in p[0].split("-"))
                    maps.append((lo, hi, int(p[2], 16), p[5]))
    maps.sort()
    starts = [m[0] for m in maps]
    binaries = {os.path.basename(b): load_symbols(b) for b in args.binary}
    cache = {}

    def locate(address):
        """(binary's file name, its virtual address, function name) of an address."""
        if address in cache:
            return cache[address]
        i = bisect.bisect_right(starts, address) - 1
        result = (None, None, "?")
        if i >= 0 and address < maps[i][1]:
            lo, _, offset, path = maps[i]
            base = os.path.basename(path)
            result = (base, None, base)
            if base in binaries:
                syms, names, segments = binaries[base]
                fileoffset = address - lo + offset
                for seg_offset, vaddr, size in segments:
                    if seg_offset <= fileoffset < seg_offset + size:
                        v = fileoffset - seg_offset + vaddr
                        k = bisect.bisect_right(syms, v) - 1
                        if k >= 0:
                            result = (base, v, names[k])
                        break
        cache[address] = result
        return result

    def name(address):
        return locate(address)[2]

    if args.during:
        spans = sorted(tuple(int(v) for v in line.split()[:2]) for line in open(args.during) if line.strip())
        begins = [b for b, _ in spans]

        def within(t):
            i = bisect.bisect_right(begins, t) - 1 if t is not None else -1
            return i >= 0 and t < spans[i][1]

        kept = [(st, t) for st, t in zip(stacks, times) if within(t)]
        stacks, times = [k[0] for k in kept], [k[1] for k in kept]
    samples, addresses = [], []
    for stack in stacks:
        # Frames 0 and 1 are the signal handler and the kernel's return
        # trampoline; frame 2 the interrupted instruction; the rest return
        # addresses (one byte back lands in the call).
        frame_addresses = stack[2:3] + [a - 1 for a in stack[3:]]
        samples.append([name(a) for a in frame_addresses])
        addresses.append(frame_addresses)
    if args.per_interval:
        # Interval by interval (--during), in time order: its length and the
        # paths below the outermost frame holding TEXT that its samples took
        # (function names without arguments or scopes), the commonest first.
        def short(f):
            lambda_in = re.search(r"_Function_handler<[^,]*, (.*)::\{lambda", f)
            if lambda_in:  # a lambda run through std::function: where it was written
                return short(lambda_in.group(1)) + ":lambda"
            f = f.replace("(anonymous namespace)", "")
            while re.search(r"<[^<>]*>", f):
                f = re.sub(r"<[^<>]*>", "", f)
            return re.sub(r"\(.*", "", f).split("::")[-1][:40]

        per = collections.defaultdict(collections.Counter)
        for st, t in zip(samples, times):
            outer = [i for i, f in enumerate(st) if args.per_interval in f]
            if outer:
                o = max(outer)
                path = "/".join(short(st[j]) for j in range(o - 1, max(o - 1 - args.depth_below, -1), -1))
                per[bisect.bisect_right(begins, t) - 1][path or "(itself)"] += 1
        for k in sorted(per)[: args.top]:
            b, e = spans[k]
            paths = "; ".join(f"{n} x {p}" for p, n in per[k].most_common(4))
            print(f"{(b - spans[0][0]) * 1e-6:10.2f} ms: gap {(e - b) * 1e-6:6.2f} ms: {paths}")
        return
    if args.under:
        kept = [i for i, s in enumerate(samples) if any(args.under in f for f in s)]
        samples = [samples[i] for i in kept]
        addresses = [addresses[i] for i in kept]
    addresses = addresses[int(args.skip * len(addresses)):]
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
                # Libraries' own frames (libc, libcuda, the vDSO) say little
                # about who called them: the first named function does.
                rest = [f for f in s if args.callers_of not in f and not is_library(f)]
                callers[rest[0] if rest else "?"] += 1
        show(f"first caller outside '{args.callers_of}' and libraries of the innermost frames in it", callers)
    if args.lines:
        # Source lines (the binary needs line tables: the bundle builds with
        # -g1) of the outermost frame in a function whose name holds TEXT:
        # where its own time and its calls' time went, line by line.
        wanted = collections.defaultdict(list)
        for s, a in zip(samples, addresses):
            hits = [i for i, f in enumerate(s) if args.lines in f]
            if hits:
                base, v, _ = locate(a[max(hits)])
                if v is not None:
                    wanted[base].append(v)
        outer, inner = collections.Counter(), collections.Counter()
        for base, vs in wanted.items():
            path = next(b for b in args.binary if os.path.basename(b) == base)
            unique = sorted(set(vs))
            # addr2line -i prints one (function, file:line) pair per inline
            # level, innermost first; an address 0 after each one ends its
            # chain with a pair of "??".
            query = "".join(f"{hex(v)}\n0x0\n" for v in unique)
            out = subprocess.run(["addr2line", "-i", "-C", "-f", "-e", path], input=query,
                                 capture_output=True, text=True).stdout.splitlines()
            chains, chain, j = {}, [], 0
            for k in range(0, len(out) - 1, 2):
                if out[k] == "??" and out[k + 1].startswith("??"):
                    chains[unique[j]] = chain
                    chain, j = [], j + 1
                else:
                    chain.append(os.path.basename(out[k + 1].split(" (")[0]))
            for v in vs:
                chain = chains.get(v) or ["?"]
                outer[chain[max(0, len(chain) - 1 - args.depth)]] += 1
                inner[chain[0]] += 1
        show(f"lines of the outermost '{args.lines}' frame, {args.depth} inlined calls in", outer)
        show(f"innermost inlined lines there", inner)


if __name__ == "__main__":
    main()
