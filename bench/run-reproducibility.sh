#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Does a GPU run repeat itself when other registrations share the GPU?
# SPEC 5: the same seed and backend give the same front. Runs the abdominal
# pair (the paper's configuration) with one seed alone, then COPIES runs of
# the same seed side by side, and compares each copy with the lone run:
# generations.csv's columns that do not measure time, generation by
# generation, and front.json's solutions. Uses the bundle of
# bench/run-mesh-levels.sh.
#   Here:        bench/run-mesh-levels.sh bundle
#   On the GPU:  bench/run-reproducibility.sh run OUTDIR [SEED] [COPIES]
# MOREA_REPRO_SET: KEY=VALUE overrides for every run (e.g. ea_num_generations=100
# for a short check); MOREA_REPRO_ARGS: more options of `morea register`
# (e.g. --refusal-bound off).
set -euo pipefail
cd "$(dirname "$0")/.."

case "${1:-}" in
  run)
    out=${2:?output folder}
    seed=${3:-1}
    copies=${4:-3}
    mkdir -p "$out" /tmp/b
    tar xJf "${MOREA_BUNDLE:-device-carry/bundle.tar.xz}" -C /tmp/b
    export LD_LIBRARY_PATH=/tmp/b/lib
    D=/tmp/b/data
    sets=(--set "seed=$seed")
    for o in ${MOREA_REPRO_SET:-}; do sets+=(--set "$o"); done
    read -r -a extra <<<"${MOREA_REPRO_ARGS:-}"
    register() { # NAME
      rm -rf "/tmp/repro/$1"
      /tmp/b/bin/morea register --problem "$D/abdomen" --parameters "$D/abdomen_paper.toml" "${sets[@]}" \
        "${extra[@]}" -o "/tmp/repro/$1" --select best-guidance >"$out/$1.log" 2>&1 || echo "failed: $1 (see $1.log)"
    }
    nvidia-smi --query-gpu=name --format=csv,noheader | tee "$out/gpu.txt"
    register alone
    names=()
    for k in $(seq 1 "$copies"); do
      names+=("side-$k")
      register "side-$k" &
    done
    wait
    python3 - /tmp/repro "${names[@]}" <<'EOF' | tee "$out/reproducibility.txt"
import csv, json, sys
from pathlib import Path

root, copies = Path(sys.argv[1]), sys.argv[2:]
# The columns a run's path decides; the rest measure time.
KEEP = ("generation", "hypervolume", "best_guidance", "archive_size", "feasible", "candidates", "folded",
        "accepted", "repaired", "forced_improvements", "mean_multiplier", "tetrahedron_evaluations")

def rows(name):
    with open(root / name / "generations.csv") as f:
        return [{k: r[k] for k in KEEP} for r in csv.DictReader(f)]

def front(name):
    solutions = json.loads((root / name / "front.json").read_text())["solutions"]
    return [(s["magnitude"], s["intensity"], s["guidance"]) for s in solutions]

alone = rows("alone")
print(f"alone: {len(alone)} generations, front of {len(front('alone'))}")
same = 0
for name in copies:
    other = rows(name)
    first = next((i for i, (a, b) in enumerate(zip(alone, other)) if a != b), None)
    if first is None:
        identical = len(other) == len(alone) and front(name) == front("alone")
        same += identical
        print(f"{name}: " + ("identical (every generation and the front)" if identical
                             else "the same generations, another front or length"))
        continue
    a, b = alone[first], other[first]
    differing = [k for k in KEEP if a[k] != b[k]]
    print(f"{name}: differs from generation {a['generation']} on: " +
          ", ".join(f"{k} {a[k]} (alone) / {b[k]}" for k in differing))
print(f"{same} of {len(copies)} copies side by side repeat the lone run")
EOF
    ;;
  *)
    sed -n '2,15p' "$0"
    exit 2
    ;;
esac
