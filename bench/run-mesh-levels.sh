#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Multi-resolution meshes against one mesh: the paper's configuration with
# one mesh level and with three (600 -> ~1400 -> ~3200 points), on the
# abdominal CBCT pair (stomach and bowel Dice and HD95 of the chosen
# solutions) and on the bladder-emptying phantom (TRE per landmark kind via
# bench/run-rigid-structures.sh). Results: bench/results/mesh-levels.md.
#   Here:        bench/run-mesh-levels.sh bundle
#   On the GPU:  bench/run-mesh-levels.sh run OUTDIR [CONFIGS]
# CONFIGS: words PROBLEM:SCHEDULE, PROBLEM abdomen or phantom, SCHEDULE
# below (default: both problems with 1 and 3). MOREA_LEVELS_SET: more
# KEY=VALUE overrides for every run (abdomen only), e.g. morea_repair_method=none.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${MOREA_DATA:-../shared/data/abdomen-cbct-pair}
# Mesh level schedules by name: 1 (one mesh), 3 (600 points for 200
# generations, ~1400 for 200, ~3200 for 100), 2a (600 for 400, ~1400 for
# 100), 2b (600 for 450, ~3200 for 50), 2c (600 for 475, ~3200 for 25), 2d
# (600 for 485, ~3200 for 15); a trailing g (3g, 2g, 2bg) makes the refined
# levels' FOS elements groups of points (morea_fos_type = coarse-groups); 2g:
# 600 for 250, ~3200 for 250.
schedule() {
  case "$1" in
    *g) echo "$(schedule "${1%g}") morea_fos_type=coarse-groups"; return ;;
  esac
  case "$1" in
    1) ;;
    3) echo morea_max_num_mesh_levels=3 morea_num_generations_per_level=200 morea_mesh_refinement_factor=2.3 ;;
    2a) echo morea_max_num_mesh_levels=2 morea_num_generations_per_level=400 morea_mesh_refinement_factor=2.3 ;;
    2b) echo morea_max_num_mesh_levels=2 morea_num_generations_per_level=450 morea_mesh_refinement_factor=5.3 ;;
    2c) echo morea_max_num_mesh_levels=2 morea_num_generations_per_level=475 morea_mesh_refinement_factor=5.3 ;;
    2d) echo morea_max_num_mesh_levels=2 morea_num_generations_per_level=485 morea_mesh_refinement_factor=5.3 ;;
    2) echo morea_max_num_mesh_levels=2 morea_num_generations_per_level=250 morea_mesh_refinement_factor=5.3 ;;
    *) echo "unknown schedule $1" >&2; exit 2 ;;
  esac
}

case "${1:-}" in
  bundle)
    cmake --build build -j"$(nproc)" --target morea
    stage=$(mktemp -d)
    trap 'rm -rf "$stage"' EXIT
    a="$stage/abdomen"
    mkdir -p "$a/fixed_masks" "$a/moving_masks"
    cp "$DATA/CB02.mha" "$a/fixed.mha"
    cp "$DATA/CB07.mha" "$a/moving.mha"
    for s in Stomach_duo_CBCT Bowel_sm_CBCT; do
      cp "$DATA/CB02_masks/$s.mha" "$a/fixed_masks/"
      cp "$DATA/CB07_masks/$s.mha" "$a/moving_masks/"
    done
    MOREA_BUNDLE=${MOREA_BUNDLE:-device-carry/bundle.tar.xz} ${MOREA_BUNDLER:-tools/device-bundle.sh} --data "$a" \
      --data bench/configurations/abdomen_paper.toml \
      --data bench/run-rigid-structures.sh build/bin/morea
    ;;
  run)
    out=${2:?output folder}
    configs=${3:-abdomen:1 abdomen:3 phantom:1 phantom:3}
    mkdir -p "$out" /tmp/b
    tar xJf "${MOREA_BUNDLE:-device-carry/bundle.tar.xz}" -C /tmp/b
    export LD_LIBRARY_PATH=/tmp/b/lib
    B=/tmp/b/bin
    D=/tmp/b/data
    nvidia-smi --query-gpu=name,memory.total --format=csv,noheader | tee "$out/gpu.txt"
    for config in $configs; do
      problem=${config%:*}
      levels=${config#*:}
      case "$problem" in
        abdomen)
          sets=()
          for o in $(schedule "$levels") ${MOREA_LEVELS_SET:-}; do sets+=(--set "$o"); done
          start=$(date +%s.%N)
          "$B/morea" register --problem "$D/abdomen" --parameters "$D/abdomen_paper.toml" "${sets[@]}" -o "/tmp/runs/$config" \
            --select best-guidance,knee >"$out/abdomen-$levels.log" 2>&1 || echo "failed: abdomen-$levels"
          grep -E "^generation (450|451|452|460|500)/" "$out/abdomen-$levels.log" || true
          echo "abdomen levels $levels: $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s"
          grep -E "^(mesh|best_guidance|knee|  [A-Z])" "$out/abdomen-$levels.log" || true
          ;;
        phantom)
          read -r -a overrides <<<"$(schedule "$levels")"
          MOREA_RIGID_RUNS="all:default" bash "$D/run-rigid-structures.sh" "$B/morea" "/tmp/runs/$config" \
            bladder-emptying "" seed=0 "${overrides[@]}" >"$out/phantom-$levels.log" 2>&1 || echo "failed: phantom-$levels"
          cp "/tmp/runs/$config/rigid-structures.csv" "$out/phantom-$levels.csv" 2>/dev/null || true
          echo "phantom levels $levels:"
          cat "$out/phantom-$levels.csv" 2>/dev/null || tail -5 "$out/phantom-$levels.log"
          grep -E "^mesh" "/tmp/runs/$config/all-rigid-default.log" 2>/dev/null || true
          ;;
      esac
    done
    ;;
  *)
    sed -n '2,9p' "$0"
    exit 2
    ;;
esac
