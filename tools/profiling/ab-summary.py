#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Per program of a `run-device-benchmark.sh ab` run: mean seconds per
generation and per phase over generations FIRST..LAST of its generations.csv.
Usage: tools/profiling/ab-summary.py ABDIR FIRST LAST"""
import csv
import os
import sys

root, first, last = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
columns = ["seconds", "seconds_sampling", "seconds_fold_checks", "seconds_evaluation", "seconds_acceptance",
           "seconds_modelling", "seconds_device_kernels", "seconds_device_span"]
print("program".ljust(22) + "".join(c.replace("seconds_", "")[:12].rjust(13) for c in columns))
for name in sorted(os.listdir(root)):
    path = os.path.join(root, name, "generations.csv")
    if not os.path.exists(path):
        continue
    rows = [r for r in csv.DictReader(open(path)) if first <= int(r["generation"]) <= last]
    if not rows:
        continue
    means = [sum(float(r.get(c) or 0) for r in rows) / len(rows) for c in columns]
    print(name.ljust(22) + "".join(f"{m:13.4f}" for m in means) + f"   ({len(rows)} generations)")
