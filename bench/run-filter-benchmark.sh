#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Whole registrations through the ITK filter with default settings, and the
# same through `morea register`, on a GPU machine without ITK (results:
# bench/results/filter-benchmark.md).
#   Here:        bench/run-filter-benchmark.sh bundle
#                builds morea, the C++ example (the filter with default
#                settings) and the test programs, and packs them with two
#                problem folders into device-carry/: the abdominal CBCT pair
#                (2 guidance structures) and the pelvis phantom split into 6
#                guidance structures (bench/tools/phantom-six-structures.py),
#                also run with 2 of them guiding (the same grid).
#   On the GPU:  bench/run-filter-benchmark.sh run OUTDIR [ROUNDS]
#                runs the filter and CUDA tests, then per round and problem the
#                example and `morea register` with the paper's configuration
#                (bench/configurations/*_paper.toml), each timed from reading
#                to outputs; prints one line per run and writes OUTDIR/runs.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${MOREA_DATA:-../shared/data/abdomen-cbct-pair}

case "${1:-}" in
  bundle)
    cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build build -j"$(nproc)" --target morea RegisterPelvisPhantom MOREAITKTests MOREACoreTests
    stage=$(mktemp -d)
    trap 'rm -rf "$stage"' EXIT
    # The abdominal pair as a problem folder: fixed CB02, moving CB07.
    a="$stage/abdomen"
    mkdir -p "$a/fixed_masks" "$a/moving_masks"
    cp "$DATA/CB02.mha" "$a/fixed.mha"
    cp "$DATA/CB07.mha" "$a/moving.mha"
    for s in Stomach_duo_CBCT Bowel_sm_CBCT; do
      cp "$DATA/CB02_masks/$s.mha" "$a/fixed_masks/"
      cp "$DATA/CB07_masks/$s.mha" "$a/moving_masks/"
    done
    # The phantom with six guidance structures (SimpleITK from the study's venv).
    python=${MOREA_PYTHON:-build/study-venv/bin/python}
    build/bin/morea phantom -o "$stage/phantom" >/dev/null
    "$python" bench/tools/phantom-six-structures.py "$stage/phantom" "$stage/phantom6"
    cp bench/configurations/abdomen_paper.toml bench/configurations/phantom6_paper.toml "$stage/"
    # The same phantom and grid with 2 of its structures guiding.
    { cat bench/configurations/phantom6_paper.toml; echo 'problem_guidance_selection = "bladder, rectum"'; } \
      >"$stage/phantom2_paper.toml"
    tools/device-bundle.sh --data "$a" --data "$stage/phantom6" --data "$stage/abdomen_paper.toml" \
      --data "$stage/phantom6_paper.toml" --data "$stage/phantom2_paper.toml" \
      build/bin/morea build/bin/RegisterPelvisPhantom build/test/MOREAITKTests build/test/MOREACoreTests
    ;;
  run)
    out=${2:?output folder}
    rounds=${3:-1}
    mkdir -p "$out" /tmp/b
    tar xJf device-carry/bundle.tar.xz -C /tmp/b
    export LD_LIBRARY_PATH=/tmp/b/lib
    B=/tmp/b/bin
    D=/tmp/b/data
    nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader | tee "$out/gpu.txt"
    nproc | sed 's/^/host cores: /' | tee -a "$out/gpu.txt"
    # The GPU tests: the filter uses CUDA by default; CPU and CUDA agree.
    "$B/MOREAITKTests" --gtest_filter='MultiObjectiveMeshRegistrationFilter.*' >"$out/filter-tests.log" 2>&1 || true
    "$B/MOREACoreTests" --gtest_filter='*Cuda*:*BackendSelection*' >"$out/cuda-tests.log" 2>&1 || true
    tail -n 3 "$out/filter-tests.log" "$out/cuda-tests.log"
    echo "problem,program,round,seconds,backend" >"$out/runs.csv"
    for round in $(seq 1 "$rounds"); do
      for problem in abdomen phantom2 phantom6; do
        config="$D/${problem}_paper.toml"
        folder="$D/$problem"
        [ "$problem" = phantom2 ] && folder="$D/phantom6"
        for program in filter cli; do
          run="/tmp/runs/$problem-$program-$round"
          log="$out/$problem-$program-$round.log"
          rm -rf "$run"
          start=$(date +%s.%N)
          if [ "$program" = filter ]; then
            "$B/RegisterPelvisPhantom" "$folder" "$config" "$run" >"$log" 2>&1 || echo "failed: $log"
            backend=$(grep -o 'evaluated on [a-z-]*' "$log" | awk '{print $3}')
          else
            "$B/morea" register --problem "$folder" --parameters "$config" -o "$run" >"$log" 2>&1 ||
              echo "failed: $log"
            backend=$(grep -o '^backend: [a-z-]*' "$log" | awk '{print $2}')
          fi
          end=$(date +%s.%N)
          echo "$problem,$program,$round,$(awk "BEGIN{print $end - $start}"),$backend" | tee -a "$out/runs.csv"
        done
      done
    done
    # Seconds per preprocessed voxel (the same preprocessing for both
    # programs: the CLI's log gives the grid) and the 6- to 2-structure ratio.
    python3 - "$out" <<'PY'
import csv, re, statistics, sys
out = sys.argv[1]
rows = list(csv.DictReader(open(f"{out}/runs.csv")))
voxels = {}
for r in rows:
    if r["program"] == "cli":
        m = re.search(r"preprocessed: (\d+)x(\d+)x(\d+)", open(f"{out}/{r['problem']}-cli-{r['round']}.log").read())
        if m:
            voxels[r["problem"]] = int(m[1]) * int(m[2]) * int(m[3])
lines = ["| problem | program | runs | median s | voxels | ns per voxel | backend |", "|---|---|---|---|---|---|---|"]
per_voxel = {}
for problem in ("abdomen", "phantom2", "phantom6"):
    for program in ("filter", "cli"):
        t = [float(r["seconds"]) for r in rows if r["problem"] == problem and r["program"] == program]
        if not t:
            continue
        med = statistics.median(t)
        v = voxels.get(problem)
        per_voxel[(problem, program)] = med / v if v else None
        backend = {r["backend"] for r in rows if r["problem"] == problem and r["program"] == program}
        lines.append(f"| {problem} | {program} | {len(t)} | {med:.1f} | {v} | "
                     f"{med / v * 1e9:.1f} | {','.join(sorted(backend))} |" if v else f"| {problem} | {program} | {len(t)} | {med:.1f} | ? | ? | {backend} |")
for program in ("filter", "cli"):
    for two in ("abdomen", "phantom2"):
        a, b = per_voxel.get((two, program)), per_voxel.get(("phantom6", program))
        if a and b:
            lines.append(f"\n{program}: time per voxel, phantom6 / {two} = {b / a:.3f}")
text = "\n".join(lines)
open(f"{out}/summary.md", "w").write(text + "\n")
print(text)
PY
    ;;
  *)
    sed -n '2,18p' "$0"
    exit 2
    ;;
esac
