#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# A crash says where it happened: `morea` hit by SIGABRT in the middle of a
# registration writes the signal's name and a backtrace to standard error and
# still ends by that signal (exit status 134 seen from a shell).
# Run as: CrashReport.sh <morea executable> <scratch folder>
set -uo pipefail
morea=${1:?morea executable}
work=${2:?scratch folder}
rm -rf "$work" && mkdir -p "$work"
"$morea" phantom -o "$work/phantom" >/dev/null || { echo "phantom failed"; exit 1; }
"$morea" register --problem "$work/phantom" -o "$work/run" --backend cpu --threads 1 \
  --set ea_population_size=12 --set ea_num_clusters=2 --set morea_mesh_num_points=60 \
  --set preprocess_isotropic_spacing=4 --set ea_num_generations=1000000 --checkpoint-every 0 \
  >"$work/stdout" 2>"$work/stderr" &
pid=$!
# Wait for the optimiser's first generations (at most two minutes).
for _ in $(seq 1 1200); do
  grep -q "generation" "$work/stdout" 2>/dev/null && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.1
done
kill -ABRT "$pid"
wait "$pid"
rc=$?
cat "$work/stderr"
[ "$rc" -eq 134 ] || { echo "exit status $rc, expected 134 (SIGABRT)"; exit 1; }
grep -q "^morea: crashed with signal SIGABRT" "$work/stderr" || { echo "no crash report"; exit 1; }
[ "$(grep -c "morea(" "$work/stderr")" -ge 3 ] || { echo "no backtrace"; exit 1; }
echo "crash report: ok"
