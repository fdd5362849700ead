#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
#
# A cohort through `morea batch` (morea.cohort on Dask) on a GPU machine: N
# phantom patients (noise seeds 1..N) registered with the paper's
# configuration, first on all GPUs (one worker each), then the same cohort on
# GPU 0 alone; nvidia-smi samples every GPU meanwhile. Prints both wall times
# and their ratio. Runs from a bundle of tools/device-bundle.sh:
#   MOREA_BUNDLE=device-carry/bundle.tar.xz tools/device-bundle.sh --python build/python/morea \
#     --python-site VENV/lib/python3.11/site-packages --python-dist distributed build/bin/morea
#   bench/run-cohort-benchmark.sh device-carry/bundle.tar.xz [N] [PARAMETERS.toml]
# Results: $RESULTS (default ./cohort-benchmark). DEADLINE=S stops the
# one-GPU cohort S seconds after the start (its finished registrations are kept).
# SAMPLE_MS=N samples every GPU's utilisation every N ms (default 5000; 0:
# off). Sampling every 500 ms slowed the two-GPU cohort by about 5 %
# (bench/results/cohort-batch.md); the snapshot 45 s in is always taken;
# CHECKPOINT_EVERY=N|Ns sets the batch's --checkpoint-every (default: the
# batch's, 30s; 0: only after the last generation).
# RUNS="all-gpus" or RUNS="one-gpu" runs one of the two cohorts (default both),
# for a lease whose command time limit is shorter than both together; the
# ratio is then the two calls' wall times, on the same machine while it is held.
set -uo pipefail
bundle=$1
n=${2:-8}
parameters=$(readlink -f "${3:-examples/paper_parameters.toml}")
out=${RESULTS:-$PWD/cohort-benchmark}
mkdir -p "$out"
t0=$(date +%s)
b=/tmp/morea-bundle
mkdir -p $b && tar xJf "$bundle" -C $b
export PYTHONHOME=$b PYTHONPATH=$b/site LD_LIBRARY_PATH=$b/lib PYTHONUNBUFFERED=1
work=$(mktemp -d)
for k in $(seq 1 "$n"); do $b/bin/morea phantom --seed "$k" -o "$work/p$k" > /dev/null & done
wait
{ echo "id,problem,seed"; for k in $(seq 1 "$n"); do echo "p$k,p$k,$k"; done; } > "$work/cohort.csv"
gpus=$(nvidia-smi --query-gpu=index --format=csv,noheader 2>/dev/null | paste -sd, -)
gpus=${gpus:-0,1}
echo "GPUs: $gpus; $(nproc) cores; bundle ready after $(( $(date +%s) - t0 )) s"
smi=""
if [ "${SAMPLE_MS:-5000}" -gt 0 ]; then
  nvidia-smi --query-gpu=timestamp,index,utilization.gpu,memory.used --format=csv,noheader -lms "${SAMPLE_MS:-5000}" \
    > "$out/nvidia-smi.csv" 2>/dev/null &
  smi=$!
fi

run() { # NAME GPUS [TIMEOUT]
  local name=$1 start end
  start=$(date +%s%N)
  (sleep 45; echo "== nvidia-smi 45 s into $name"; nvidia-smi) > "$out/$name-nvidia-smi.txt" 2>&1 &
  local snap=$!
  ${3:+timeout --signal=INT $3} $b/bin/python3 -m morea.cohort "$work/cohort.csv" -o "$work/$name" --gpus "$2" \
    --parameters "$parameters" --var experiment_descriptor=cohort --morea $b/bin/morea --no-plots \
    ${CHECKPOINT_EVERY:+--checkpoint-every $CHECKPOINT_EVERY} 2>&1 |
    tee "$out/$name.log"
  end=$(date +%s%N)
  kill $snap 2>/dev/null
  echo "$name: $(( (end - start) / 1000000 )) ms from $(( start / 1000000 )) to $(( end / 1000000 )) (epoch ms)" |
    tee -a "$out/times.txt"
  cp "$work/$name/registrations.csv" "$out/$name-registrations.csv" 2>/dev/null
  cp "$work/$name/cohort_summary.csv" "$out/$name-summary.csv" 2>/dev/null
  grep -h "^times:" "$work/$name"/logs/*.log > "$out/$name-times.txt" 2>/dev/null
  cat "$out/$name-nvidia-smi.txt"
}

runs=${RUNS:-all-gpus one-gpu}
case " $runs " in *" all-gpus "*) run all-gpus "$gpus" ;; esac
left=""
if [ -n "${DEADLINE:-}" ]; then left=$(( DEADLINE - ($(date +%s) - t0) )); fi
case " $runs " in *" one-gpu "*) run one-gpu 0 $left ;; esac
[ -n "$smi" ] && kill $smi 2>/dev/null
$b/bin/python3 - "$out/times.txt" <<'EOF'
import re, sys
t = {m.group(1): int(m.group(2)) for m in re.finditer(r"(\S+): (\d+) ms", open(sys.argv[1]).read())}
if "all-gpus" in t and "one-gpu" in t:
    print(f"wall time: all GPUs {t['all-gpus'] / 1000:.1f} s, one GPU {t['one-gpu'] / 1000:.1f} s, "
          f"ratio {t['all-gpus'] / t['one-gpu']:.3f}")
EOF
