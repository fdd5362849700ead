#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Sampled points per second by kernel, from a device timeline.

`morea benchmark` reports samples per second over its sampling kernels'
event spans (set-up included). This reads the CUPTI timeline of the same
run (tools/profiling/device-timeline.c, MOREA_TIMELINE) and its JSON, and prints
where the device's sampling time went kernel by kernel, and the rate over
  - the sampling kernel alone (SampleTextureChunks),
  - all sampling kernels' own durations, summed and as a union (kernels of
    the skipped candidates' sampling run beside the batches' on a stream
    of their own),
next to the JSON's figure. Only kernels of the generations count: those
that start within `seconds_generations` of the last kernel's end.

  sampling-kernel-rates.py TIMELINE.txt[.xz] BENCHMARK.json [--backend cuda-texture]
                           [--fetch-rate PER_SECOND]
"""
import argparse
import collections
import json
import lzma
import re

SAMPLING = re.compile(r"PrepareTextureTasks|DeviceRadixSort|ScheduleCandidateItems|GatherScheduleCounts|DeviceScan|"
                      r"ScatterChunkTasks|SampleTextureChunks|SumChunks|SampleListedChunks")
MAIN = re.compile(r"SampleTextureChunks")


def short_name(name):
    """The part of a kernel's (mangled) name that SAMPLING matched."""
    return SAMPLING.search(name).group(0)


def union_seconds(spans):
    total, start, end = 0, None, None
    for a, b in sorted(spans):
        if start is None or a > end:
            if start is not None:
                total += end - start
            start, end = a, b
        else:
            end = max(end, b)
    if start is not None:
        total += end - start
    return total / 1e9


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("timeline")
    parser.add_argument("benchmark")
    parser.add_argument("--backend", default="cuda-texture")
    parser.add_argument("--fetch-rate", type=float, default=0.0,
                        help="trilinear fetches per second (default: the JSON's probe, if it ran)")
    args = parser.parse_args()
    report = json.load(open(args.benchmark))
    run = report["runs"][args.backend]
    fetch = args.fetch_rate or report.get("trilinear_fetches_per_second", 0.0)
    opener = lzma.open if args.timeline.endswith(".xz") else open
    kernels = []
    with opener(args.timeline, "rt") as lines:
        for line in lines:
            fields = line.split()
            if fields and fields[0] == "k":
                kernels.append((int(fields[1]), int(fields[2]), " ".join(fields[5:])))
    if not kernels:
        raise SystemExit("no kernels in " + args.timeline)
    end = max(k[1] for k in kernels)
    begin = end - run["seconds_generations"] * 1e9
    kernels = [k for k in kernels if k[0] >= begin]
    seconds, launches = collections.defaultdict(float), collections.Counter()
    for a, b, name in kernels:
        if SAMPLING.search(name):
            seconds[short_name(name)] += (b - a) / 1e9
            launches[short_name(name)] += 1
    samples = run["samples"]
    print("%d generations, %.4g samples" % (run["generations"], samples))
    for name, s in sorted(seconds.items(), key=lambda item: -item[1]):
        print("  %-24s %8.4f s in %5d launches" % (name, s, launches[name]))
    sampling = [(a, b) for a, b, name in kernels if SAMPLING.search(name)]
    main_kernel = sum((b - a) for a, b, name in kernels if MAIN.search(name)) / 1e9
    # The skipped candidates' samples drawn later are SampleListedChunks'.
    later = run.get("samples_sampled_later")
    rows = [("the sampling kernel alone", main_kernel, samples - later if later is not None else samples),
            ("sampling kernels, summed", sum(b - a for a, b in sampling) / 1e9, samples),
            ("sampling kernels, union", union_seconds(sampling), samples),
            ("the benchmark's event spans", run["seconds_in_kernels"], samples)]
    if later is None:
        print("  (no samples_sampled_later in the JSON: the first row counts all samples)")
    else:
        print("  %.4g of the samples drawn later (SampleListedChunks)" % later)
    for label, s, counted in rows:
        rate = counted / s if s > 0 else 0.0
        share = " = %.1f %% of %.4g fetches/s" % (100.0 * rate / fetch, fetch) if fetch else ""
        print("  %-30s %8.4f s  %.4g samples/s%s" % (label, s, rate, share))


if __name__ == "__main__":
    main()
