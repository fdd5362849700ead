#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# The CUDA benchmark on a GPU machine without ITK (see README.md, "CUDA backend").
#   Here:          bench/run-device-benchmark.sh bundle [PROGRAM...]
#                  builds morea and the core tests (CUDA for sm_90), packs them (and
#                  PROGRAMs, e.g. an older build's morea renamed, for A/B runs) with
#                  their libraries and the abdominal CBCT pair into device-carry/.
#   On the GPU:    bench/run-device-benchmark.sh run OUTDIR [morea benchmark options]
#                  runs the CPU/CUDA agreement tests, then `morea benchmark` with
#                  the paper's configuration; logs and JSON go to OUTDIR.
#                  bench/run-device-benchmark.sh register|ab ...: `morea register` of
#                  the same configuration, resumable, or several programs compared
#                  over the same late generations (see below).
#   Late generations in detail: `morea benchmark ... --from-checkpoint RUNDIR/checkpoint.bin`
#                  times the generations after a register checkpoint; tools/profiling/device-phases.py
#                  JSON prints where the device's time went (device_phase_seconds).
#                  bench/run-device-benchmark.sh late OUTDIR SECONDS BACKEND [GENERATIONS]
#                  does both on the GPU machine.
#   Kernels of several builds: bench/run-device-benchmark.sh early OUTDIR GENERATIONS ROUNDS
#                  BACKEND PROGRAM... times early generations from scratch, programs in turns.
#   Where the host's time goes: bench/run-device-benchmark.sh profile OUTDIR SECONDS BACKEND GENERATIONS
#                  [morea benchmark options] samples the main thread's call stacks over late
#                  generations (tools/profiling/main-thread-profiler.c); here,
#                  tools/profiling/profile-report.py OUTDIR/main-thread.prof --binary build/bin/morea
#                  names the functions (with the build the bundle was made from).
#   While the device waits: bench/run-device-benchmark.sh timeline OUTDIR SECONDS BACKEND GENERATIONS
#                  [morea benchmark options] records the device's timeline (CUPTI) and the main
#                  thread's stacks on one clock; tools/profiling/device-gaps.py lists the idle gaps and
#                  profile-report.py --during shows what the main thread did in them.
#   Whole runs: bench/run-device-benchmark.sh whole OUTDIR SECONDS BACKEND LABEL PROGRAM [OPTIONS]
#                  registers from scratch with PROGRAM (e.g. /tmp/b/bin/morea-old) and OPTIONS.
#   Late generations of several builds: bench/run-device-benchmark.sh late-ab OUTDIR SECONDS BACKEND
#                  GENERATIONS ROUNDS PROGRAM... times GENERATIONS from one common checkpoint
#                  per program, in turns; one summary line and the device phases each.
#                  Options of one build compare the same way: a PROGRAM may be a script
#                  that runs `exec /tmp/b/bin/morea "$@" --draw-ahead 0` (benchmark options).
#   The whole command: bench/run-device-benchmark.sh command OUTDIR ROUNDS BACKEND PROGRAM...
#                  runs a plain `morea register` (reading to outputs) per PROGRAM in turns.
#   Refusal bound: bench/run-device-benchmark.sh bound OUTDIR SECONDS BACKEND GENERATIONS [ROUNDS [PROGRAM...]]
#                  times late generations with --refusal-bound on and off in turns.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${MOREA_DATA:-../shared/data/abdomen-cbct-pair}

# The bundled pair (unpacked on the GPU machine) and the paper's
# configuration, as morea options.
D=/tmp/b/data/abdomen
PROBLEM=(--fixed "$D/CB02.mha" --moving "$D/CB07.mha"
  --fixed-structure Stomach_duo_CBCT="$D/CB02_labels.mha:Stomach_duo_CBCT"
  --moving-structure Stomach_duo_CBCT="$D/CB07_masks/Stomach_duo_CBCT.mha"
  --fixed-structure Bowel_sm_CBCT="$D/CB02_labels.mha:Bowel_sm_CBCT"
  --moving-structure Bowel_sm_CBCT="$D/CB07_masks/Bowel_sm_CBCT.mha"
  --parameters bench/configurations/abdomen_paper.toml)

# register PROGRAM RUNDIR SECONDS BACKEND [OPTIONS]: `morea register` of the paper's
# configuration on the bundled pair, resuming RUNDIR's checkpoint, stopped
# (SIGKILL) after SECONDS; the log is appended to RUNDIR/register.log.
register() {
  mkdir -p "$2"
  timeout --signal=KILL "$3" "$1" register "${PROBLEM[@]}" --backend "$4" "${@:5}" \
    --checkpoint-every 10 --resume -o "$2" >> "$2/register.log" 2>&1
}
# The bundle unpacked into /tmp/b (once per machine) and its libraries found.
unpack_bundle() {
  mkdir -p /tmp/b
  [ -x /tmp/b/bin/morea ] || tar xJf device-carry/bundle.tar.xz -C /tmp/b
  export LD_LIBRARY_PATH=/tmp/b/lib
}

# late_from_checkpoint OUTBASE SECONDS BACKEND GENERATIONS [OPTIONS]: `morea benchmark`
# of GENERATIONS late generations from the checkpoint /tmp/ab/profile (registered for
# SECONDS once per machine), under the LD_PRELOAD and MOREA_* variables the caller
# sets (it starts no other program under them); OUTBASE.json and OUTBASE.log.
late_from_checkpoint() {
  local outbase=$1 seconds=${2:?seconds of the start} backend=${3:?backend} generations=${4:?generations}
  shift 4
  [ -f /tmp/ab/profile/checkpoint.bin ] ||
    LD_PRELOAD= MOREA_PROFILE= MOREA_TIMELINE= register /tmp/b/bin/morea /tmp/ab/profile "$seconds" cuda-texture || true
  /tmp/b/bin/morea benchmark "${PROBLEM[@]}" --backends "$backend" --generations "$generations" \
    --cpu-generations "$generations" --threads 16 --probe 0 --from-checkpoint /tmp/ab/profile/checkpoint.bin \
    -o "$outbase.json" "$@" > "$outbase.log" 2>&1
}
# summary JSON BACKEND NAME: one line of a `morea benchmark` run.
summary() {
  python3 - "$1" "$2" "$3" <<'EOF'
import json, sys
run = json.load(open(sys.argv[1]))["runs"][sys.argv[2]]
# The first generation after a checkpoint is loaded pays for allocations
# and page faults (about 0.3 s on an H100 host): the rest is what a run's
# late generations cost.
later = [g["seconds"] for g in run["per_generation"][1:]]
print(f"{sys.argv[3]}: from generation {run['first_generation']}, {run['samples_per_second_kernel']:.4e} samples/s "
      f"in kernels, {run['seconds_per_generation']:.4f} s per generation "
      f"({sum(later) / max(1, len(later)):.4f} after the first), {run['seconds_in_kernels']:.3f} s in "
      f"kernels ({run.get('seconds_in_setup_kernels', 0):.3f} set-up), samples {run['samples']:.4g}, "
      f"spared {run.get('bound_skipped_samples', 0):.4g}")
EOF
}
case "${1:-}" in
  bundle)
    # Line tables (-g1) let profile-report.py name source lines; the bundle
    # carries stripped copies, so they cost nothing on the device.
    cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O3 -DNDEBUG -g1" >/dev/null
    cmake --build build -j"$(nproc)" --target morea MOREACoreTests
    stage=$(mktemp -d)
    trap 'rm -rf "$stage"' EXIT
    mkdir -p "$stage/abdomen/CB07_masks"
    cp "$DATA"/CB02.mha "$DATA"/CB07.mha "$DATA"/CB02_labels.mha "$DATA"/CB02_labels.txt "$stage/abdomen/"
    cp "$DATA"/CB07_masks/Stomach_duo_CBCT.mha "$DATA"/CB07_masks/Bowel_sm_CBCT.mha "$stage/abdomen/CB07_masks/"
    cc -O2 -shared -fPIC -o "$stage/main-thread-profiler.so" tools/profiling/main-thread-profiler.c
    libs=(--lib "$stage/main-thread-profiler.so")
    # The timeline tracer, where CUPTI is installed (it travels along).
    cuda=$(dirname "$(dirname "$(readlink -f "$(command -v nvcc)")")")
    cupti=$(ls "$cuda"/lib/libcupti.so.* "$cuda"/lib64/libcupti.so.* "$cuda"/extras/CUPTI/lib64/libcupti.so.* 2>/dev/null | head -1 || true)
    if [ -n "$cupti" ]; then
      cc -O2 -shared -fPIC -o "$stage/device-timeline.so" tools/profiling/device-timeline.c -I "$cuda/include" \
        -I "$cuda/extras/CUPTI/include" "$cupti"
      libs+=(--lib "$stage/device-timeline.so" --lib "$cupti")
    fi
    tools/device-bundle.sh --data "$stage/abdomen" "${libs[@]}" \
      build/bin/morea build/test/MOREACoreTests "${@:2}"
    ;;
  run)
    out=${2:?output folder}
    shift 2
    mkdir -p "$out" /tmp/b
    tar xJf device-carry/bundle.tar.xz -C /tmp/b
    export LD_LIBRARY_PATH=/tmp/b/lib
    nvidia-smi --query-gpu=name,memory.total,driver_version,clocks.max.sm --format=csv | tee "$out/gpu.txt"
    /tmp/b/bin/MOREACoreTests --gtest_filter='*Cuda*:*BackendSelection*' 2>&1 | tee "$out/agreement-tests.log" | tail -4 || true
    /tmp/b/bin/morea benchmark "${PROBLEM[@]}" -o "$out/benchmark.json" "$@" 2>&1 | tee "$out/benchmark.log"
    ;;
  register)
    # The paper's configuration end to end with `morea register`, resumable:
    # each call continues from RUNDIR/checkpoint.bin until SECONDS have passed
    # (one device command is limited to 10 minutes), so repeated calls finish
    # the 500 generations. RUNDIR must survive between calls (a git-ignored
    # folder of the working tree, e.g. build-device/run500).
    out=${2:?output folder}
    run=${3:?run folder}
    seconds=${4:-540}
    backend=${5:-cuda}
    shift $(( $# < 5 ? $# : 5 ))
    mkdir -p "$out" "$run"
    unpack_bundle
    status=0
    register /tmp/b/bin/morea "$run" "$seconds" "$backend" "$@" || status=$?
    tail -c 4000 "$run/register.log" | tee "$out/register-tail.log"
    cp "$run"/generations.csv "$run"/summary.json "$run"/front.csv "$out/" 2>/dev/null || true
    echo "register exit status $status (137: stopped after $seconds s; call again to resume)"
    ;;
  whole)
    # One run of the paper's configuration from scratch by PROGRAM (the
    # bundle's morea or an older build it carries) with OPTIONS, stopped
    # after SECONDS; its per-generation record and front go to OUTDIR/LABEL.
    # Several in one device command compare builds within one lease.
    out=${2:?output folder}
    seconds=${3:?seconds}
    backend=${4:?backend}
    label=${5:?label}
    program=${6:?program}
    shift 6
    mkdir -p "$out/$label"
    unpack_bundle
    rm -rf "/tmp/whole/$label"
    status=0
    register "$program" "/tmp/whole/$label" "$seconds" "$backend" "$@" || status=$?
    tail -c 2000 "/tmp/whole/$label/register.log" > "$out/$label/register-tail.log"
    cp "/tmp/whole/$label"/generations.csv "/tmp/whole/$label"/summary.json "/tmp/whole/$label"/front.csv \
      "$out/$label/" 2>/dev/null || true
    python3 - "$out/$label/generations.csv" "$label" "$status" <<'EOF2'
import csv, os, sys
rows = list(csv.DictReader(open(sys.argv[1]))) if os.path.exists(sys.argv[1]) else []
total = sum(float(r["seconds"]) for r in rows)
print(f"{sys.argv[2]}: exit {sys.argv[3]}, {len(rows)} generations, {total:.1f} s summed over them")
EOF2
    ;;
  ab)
    # Variants of morea over the same late generations: the bundle's morea
    # registers for SECONDS, then every PROGRAM (e.g. device-carry/variants/*)
    # resumes its own copy of that checkpoint to the end. Per program, its
    # generations.csv, front.csv and log tail go to OUTDIR/NAME: the fronts of
    # variants that compute the same must be equal byte for byte.
    out=${2:?output folder}
    seconds=${3:?seconds of the common start}
    backend=${4:?backend}
    shift 4
    mkdir -p "$out" /tmp/ab
    unpack_bundle
    # The common start lives outside /tmp/ab, where each program has a
    # folder of its name.
    start=/tmp/ab-common-start
    rm -rf "$start"
    register /tmp/b/bin/morea "$start" "$seconds" "$backend" || true
    tail -n 3 "$start/register.log" > "$out/start-tail.log"
    for program in "$@"; do
      name=$(basename "$program")
      rm -rf "/tmp/ab/$name"
      cp -r "$start" "/tmp/ab/$name"
      mkdir -p "$out/$name"
      register "$program" "/tmp/ab/$name" 600 "$backend" || true
      tail -n 12 "/tmp/ab/$name/register.log" > "$out/$name/register-tail.log"
      cp "/tmp/ab/$name"/generations.csv "/tmp/ab/$name"/front.csv "$out/$name/" 2>/dev/null || true
      echo "$name: $(md5sum < "/tmp/ab/$name/front.csv" 2>/dev/null)"
    done
    ;;
  late)
    # Where late generations' time goes: the bundle's morea registers for
    # SECONDS (85 reach generation ~330 on an H100), then `morea benchmark`
    # times GENERATIONS more from that checkpoint; OUTDIR/late.json and the
    # summary of its device phases (tools/profiling/device-phases.py).
    out=${2:?output folder}
    seconds=${3:?seconds of the start}
    backend=${4:?backend}
    generations=${5:-40}
    mkdir -p "$out" /tmp/ab
    unpack_bundle
    rm -rf /tmp/ab/late
    register /tmp/b/bin/morea /tmp/ab/late "$seconds" "$backend" || true
    /tmp/b/bin/morea benchmark "${PROBLEM[@]}" --backends "$backend" \
      --from-checkpoint /tmp/ab/late/checkpoint.bin --generations "$generations" --probe 0 \
      -o "$out/late.json" > "$out/late.log" 2>&1
    python3 tools/profiling/device-phases.py "$out/late.json" "$backend" | tee "$out/late-summary.txt"
    ;;
  early)
    # Early generations of several programs, in turns (ROUNDS times each):
    # `morea benchmark` of GENERATIONS from scratch; per program and round
    # OUTDIR/NAME-ROUND.json, and one line each of kernel samples per second
    # and seconds per generation.
    out=${2:?output folder}
    generations=${3:?generations}
    rounds=${4:?rounds}
    backend=${5:?backend}
    shift 5
    mkdir -p "$out"
    unpack_bundle
    for round in $(seq "$rounds"); do
      for program in "$@"; do
        name=$(basename "$program")
        "$program" benchmark "${PROBLEM[@]}" --backends "$backend" --generations "$generations" --probe 0 \
          -o "$out/$name-$round.json" > "$out/$name-$round.log" 2>&1 || { tail -3 "$out/$name-$round.log"; continue; }
        summary "$out/$name-$round.json" "$backend" "$name"
      done
    done
    ;;
  profile)
    # The main thread's call stacks, sampled 1000 times a second over
    # GENERATIONS late generations from a checkpoint of SECONDS.
    out=${2:?output folder}
    mkdir -p "$out" /tmp/ab
    unpack_bundle
    MOREA_PROFILE="$out/main-thread.prof" MOREA_PROFILE_HZ=1000 LD_PRELOAD=/tmp/b/lib/main-thread-profiler.so \
      late_from_checkpoint "$out/profiled" "${@:3}"
    summary "$out/profiled.json" "$4" profiled
    ;;
  timeline)
    # What the main thread does while the device stands idle: GENERATIONS
    # late generations from a checkpoint of SECONDS, with the device's
    # timeline (tools/profiling/device-timeline.c) and the main thread's stacks
    # (main-thread-profiler.c) on one clock. OUTDIR gets the gaps' summary
    # (device-gaps.py), the gaps and the profile; here,
    # tools/profiling/profile-report.py OUTDIR/main-thread.prof --binary build/bin/morea --during OUTDIR/gaps.txt
    out=${2:?output folder}
    mkdir -p "$out" /tmp/ab
    unpack_bundle
    MOREA_TIMELINE=/tmp/ab/timeline.txt MOREA_PROFILE="$out/main-thread.prof" MOREA_PROFILE_HZ=2000 \
      LD_PRELOAD="/tmp/b/lib/device-timeline.so /tmp/b/lib/main-thread-profiler.so" \
      late_from_checkpoint "$out/timeline" "${@:3}"
    summary "$out/timeline.json" "$4" timeline
    # The first seconds load the checkpoint and evaluate its population.
    python3 tools/profiling/device-gaps.py /tmp/ab/timeline.txt --from-seconds "${MOREA_TIMELINE_SKIP:-1}" \
      --write-gaps "$out/gaps.txt" | tee "$out/gaps-summary.txt"
    xz -T0 -c /tmp/ab/timeline.txt > "$out/timeline.txt.xz"
    ;;
  late-ab)
    # Several programs over the same late generations: the bundle's morea
    # registers for SECONDS, then each PROGRAM times GENERATIONS from that
    # checkpoint with `morea benchmark`, programs in turns, ROUNDS times
    # (OUTDIR/NAME-ROUND.json). Programs that decide differently part ways
    # after the checkpoint, so compare them over few generations.
    out=${2:?output folder}
    seconds=${3:?seconds of the start}
    backend=${4:?backend}
    generations=${5:?generations}
    rounds=${6:?rounds}
    shift 6
    mkdir -p "$out" /tmp/ab
    unpack_bundle
    rm -rf /tmp/ab/late-ab
    register /tmp/b/bin/morea /tmp/ab/late-ab "$seconds" "$backend" || true
    tail -n 2 /tmp/ab/late-ab/register.log > "$out/start-tail.log"
    for round in $(seq "$rounds"); do
      for program in "$@"; do
        name=$(basename "$program")
        "$program" benchmark "${PROBLEM[@]}" --backends "$backend" --generations "$generations" --probe 0 \
          --from-checkpoint /tmp/ab/late-ab/checkpoint.bin -o "$out/$name-$round.json" > "$out/$name-$round.log" 2>&1 ||
          { tail -3 "$out/$name-$round.log"; continue; }
        summary "$out/$name-$round.json" "$backend" "$name"
        python3 tools/profiling/device-phases.py "$out/$name-$round.json" "$backend" 2>/dev/null | sed -n 2p || true
      done
    done
    ;;
  bound)
    # The refusal bound on and off over the same late generations: the
    # bundle's morea registers for SECONDS, then `morea benchmark` of each
    # PROGRAM (default: the bundle's morea) times GENERATIONS from that
    # checkpoint on BACKEND with --refusal-bound on and off in turns, ROUNDS
    # times (OUTDIR/[PROGRAM-]BACKEND-on|off-ROUND.json).
    out=${2:?output folder}
    seconds=${3:?seconds of the start}
    backend=${4:?backend}
    generations=${5:?generations}
    rounds=${6:-1}
    shift $(( $# < 6 ? $# : 6 ))
    programs=("$@")
    [ ${#programs[@]} -gt 0 ] || programs=(/tmp/b/bin/morea)
    mkdir -p "$out" /tmp/ab
    unpack_bundle
    rm -rf /tmp/ab/bound
    register /tmp/b/bin/morea /tmp/ab/bound "$seconds" cuda-texture || true
    for round in $(seq "$rounds"); do
      for program in "${programs[@]}"; do
        for bound in on off; do
          name="$backend-$bound-$round"
          [ ${#programs[@]} -eq 1 ] || name="$(basename "$program")-$name"
          "$program" benchmark "${PROBLEM[@]}" --backends "$backend" --generations "$generations" \
            --cpu-generations "$generations" --threads 16 --probe 0 --refusal-bound "$bound" \
            --from-checkpoint /tmp/ab/bound/checkpoint.bin -o "$out/$name.json" > "$out/$name.log" 2>&1
          summary "$out/$name.json" "$backend" "$name"
        done
      done
    done
    ;;
  command)
    # The whole `morea register` command as a user runs it (no resume):
    # reading, preprocessing, mesh, optimisation, outputs, timed from
    # outside; per PROGRAM in turns, ROUNDS times. OUTDIR/NAME-ROUND/ gets
    # the command's log tail, summary.json (its stage times) and front.csv.
    out=${2:?output folder}
    rounds=${3:?rounds}
    backend=${4:?backend}
    shift 4
    unpack_bundle
    for round in $(seq "$rounds"); do
      for program in "$@"; do
        name=$(basename "$program")-$round
        rm -rf "/tmp/command/$name"
        mkdir -p "$out/$name" "/tmp/command/$name"
        begin=$(date +%s.%N)
        status=0
        "$program" register "${PROBLEM[@]}" --backend "$backend" -o "/tmp/command/$name" \
          > "/tmp/command/$name.log" 2>&1 || status=$?
        end=$(date +%s.%N)
        tail -n 12 "/tmp/command/$name.log" > "$out/$name/register-tail.log"
        cp "/tmp/command/$name"/summary.json "/tmp/command/$name"/front.csv "$out/$name/" 2>/dev/null || true
        python3 - "$out/$name/summary.json" "$name" "$status" "$begin" "$end" <<'EOF2'
import json, os, sys
path, name, status, begin, end = sys.argv[1:]
seconds = json.load(open(path)).get("seconds", {}) if os.path.exists(path) else {}
def show(d):
    return ", ".join(f"{k} {v:.2f}" if isinstance(v, float) else f"{k} ({show(v)})" for k, v in d.items())
print(f"{name}: exit {status}, command {float(end) - float(begin):.2f} s from outside; {show(seconds)}")
EOF2
      done
    done
    ;;
  *)
    echo "usage: $0 bundle [PROGRAM...] | run OUTDIR [morea benchmark options] | register OUTDIR RUNDIR [SECONDS [BACKEND [OPTIONS]]]" \
      "| ab OUTDIR SECONDS BACKEND PROGRAM... | late OUTDIR SECONDS BACKEND [GENERATIONS]" \
      "| early OUTDIR GENERATIONS ROUNDS BACKEND PROGRAM... | profile OUTDIR SECONDS BACKEND GENERATIONS [OPTIONS]" \
      "| bound OUTDIR SECONDS BACKEND GENERATIONS [ROUNDS [PROGRAM...]]" \
      "| timeline OUTDIR SECONDS BACKEND GENERATIONS [OPTIONS]" \
      "| whole OUTDIR SECONDS BACKEND LABEL PROGRAM [OPTIONS] | command OUTDIR ROUNDS BACKEND PROGRAM..." >&2
    exit 2
    ;;
esac
