#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Where the device stands idle, from a timeline written by device-timeline.c.

  device-gaps.py TIMELINE [--from-seconds S] [--min-ms M] [--write-gaps FILE]

Merges every kernel, copy and set on any stream into the device's busy time
and lists the idle gaps between them: their total, their sizes, the work that
ends them, and how long before a gap's end the host queued that work (a
call queued late shows the device waiting for the host). --write-gaps writes
the gaps of at least --min-ms as START END lines (CLOCK_MONOTONIC ns) for
profile-report.py --during, which then shows what the main thread did while
the device waited. --from-seconds leaves out the timeline's first seconds
(set-up, loading a checkpoint).
"""
import argparse
import collections
import re
import shutil
import subprocess


def short_names(mangled):
    """Readable kernel names: demangled without arguments and namespaces."""
    names = {m: m for m in mangled}
    if shutil.which("c++filt"):
        out = subprocess.run(["c++filt"], input="\n".join(mangled), capture_output=True, text=True).stdout.splitlines()
        if len(out) == len(mangled):
            names = dict(zip(mangled, out))
    def unmangled(m):
        """The kernel's own name from an Itanium-mangled one, without c++filt:
        after a file's anonymous namespace (..._cu_HASH) come the name's
        length and the name; the hash may end in digits too, so each split of
        the digits is tried."""
        match = re.search(r"_cu_[0-9a-f]{8}(\d+)", m)
        if match:
            digits = match.group(1)
            for cut in range(len(digits)):
                n = int(digits[cut:])
                name = m[match.end(1): match.end(1) + n]
                if n > 0 and len(name) == n and name.isidentifier():
                    return name
        return m

    result = {}
    for m, n in names.items():
        if n == m:
            n = unmangled(m)
        n = n.replace("(anonymous namespace)", "")
        while re.search(r"<[^<>]*>", n):  # template arguments, innermost first
            n = re.sub(r"<[^<>]*>", "", n)
        n = re.sub(r"\(.*", "", n)  # arguments
        result[m] = n.split("::")[-1].split()[-1] if n.strip() else m
    return result


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("timeline")
    parser.add_argument("--from-seconds", type=float, default=0.0)
    parser.add_argument("--min-ms", type=float, default=0.2)
    parser.add_argument("--write-gaps")
    parser.add_argument("--top", type=int, default=25)
    args = parser.parse_args()

    work, calls = [], {}
    with open(args.timeline) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "k" and len(p) >= 6:
                work.append((int(p[1]), int(p[2]), int(p[3]), int(p[4]), p[5]))
            elif p[0] == "c" and len(p) >= 7:
                kind = {"1": "upload", "2": "download", "8": "device copy"}.get(p[5], "copy " + p[5])
                work.append((int(p[1]), int(p[2]), int(p[3]), int(p[4]), f"{kind} {int(p[6]) >> 10} KiB"))
            elif p[0] == "z" and len(p) >= 5:
                work.append((int(p[1]), int(p[2]), int(p[3]), int(p[4]), "memset"))
            elif p[0] == "a" and len(p) >= 6:
                calls[int(p[4])] = (int(p[1]), int(p[2]), int(p[3]), p[5])
    if not work:
        print("no device work in the timeline")
        return
    work.sort()
    first = work[0][0] + int(args.from_seconds * 1e9)
    work = [w for w in work if w[0] >= first]
    names = short_names(sorted({w[4] for w in work if not w[4].startswith(("upload", "download", "device copy",
                                                                                "copy ", "memset"))}))

    def label(w):
        text = names.get(w[4], w[4])
        return re.sub(r" \d+ KiB", "", text)

    busy_until = work[0][1]
    gaps = []  # (length, start, end, the work that ends it)
    busy = collections.Counter()
    for w in work:
        busy[label(w)] += w[1] - w[0]
        if w[0] > busy_until:
            gaps.append((w[0] - busy_until, busy_until, w[0], w))
        busy_until = max(busy_until, w[1])
    span = (busy_until - work[0][0]) * 1e-9
    idle = sum(g[0] for g in gaps) * 1e-9
    print(f"span {span:.3f} s from the first work after {args.from_seconds} s; idle {idle:.3f} s "
          f"({100 * idle / span:.1f} %) in {len(gaps)} gaps")
    print("busy time per kind of work (streams overlap, so this sums to more than the span):")
    for n, v in busy.most_common(args.top):
        print(f"  {v * 1e-9:8.4f} s  {n}")
    edges = [0.02, 0.1, 0.2, 0.5, 1, 2, 5, 1e9]
    counts, sums = collections.Counter(), collections.Counter()
    for g in gaps:
        ms = g[0] * 1e-6
        edge = next(e for e in edges if ms < e)
        counts[edge] += 1
        sums[edge] += ms
    print("gaps by length:")
    lower = 0
    for e in edges:
        print(f"  {lower:g}-{e:g} ms: {counts[e]:6d} gaps, {sums[e] * 1e-3:.4f} s")
        lower = e
    ending, ending_count = collections.Counter(), collections.Counter()
    for g in gaps:
        if g[0] >= args.min_ms * 1e6:
            ending[label(g[3])] += g[0]
            ending_count[label(g[3])] += 1
    print(f"gaps of at least {args.min_ms} ms by the work that ends them:")
    for n, v in ending.most_common(args.top):
        print(f"  {v * 1e-9:8.4f} s in {ending_count[n]:5d} gaps: {n}")
    # The call that queued the gap-ending work: queued after the gap began,
    # the device waited for the host; queued before, for something else
    # (an event, another stream).
    late, early = collections.Counter(), collections.Counter()
    for g in gaps:
        if g[0] < args.min_ms * 1e6 or g[3][3] not in calls:
            continue
        start, end, thread, name = calls[g[3][3]]
        (late if end > g[1] else early)[name] += g[0]
    print(f"gaps of at least {args.min_ms} ms whose ending work was queued after the gap began (the host was late):")
    for n, v in late.most_common(args.top):
        print(f"  {v * 1e-9:8.4f} s  {n}")
    print("... and queued before it began (the work waited for something else):")
    for n, v in early.most_common(args.top):
        print(f"  {v * 1e-9:8.4f} s  {n}")
    if args.write_gaps:
        with open(args.write_gaps, "w") as out:
            for g in gaps:
                if g[0] >= args.min_ms * 1e6:
                    out.write(f"{g[1]} {g[2]}\n")


if __name__ == "__main__":
    main()
