#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# MOREA's runs of the comparison study (study/) on a GPU machine that has no ITK
# and no Python packages beyond numpy/scipy; the competitors run elsewhere.
#
#   Here (1):     build/study-venv/bin/python -m study prepare --pair PAIR --out STUDY/PAIR
#                 (per pair: the preprocessed problem, landmarks by kind, morea_job.json)
#   Here (2):     bench/run-study-morea.sh bundle STUDY/PAIR...
#                 packs build/bin/morea (as built; nothing is rebuilt), the libraries it
#                 needs and each pair's small inputs (problem/, landmarks/, morea_job.json,
#                 morea_parameters.toml; a data pair's raw files (lung-paper, abdomen-paper;
#                 from ../shared/data or $MOREA_SHARED_DATA_DIR); not the phantom's images:
#                 they are written again there and checked against the study's checksums) into
#                 device-carry/study-morea.tar.xz (git-ignored: name it in carry).
#   On the GPU:   bench/run-study-morea.sh run "$OUT"
#                 per pair, MOREA configuration and seed: `morea register` on the raw
#                 problem with the study's parameter file and pre-alignment (backend
#                 auto: the GPU), the check that its preprocessing is the study's
#                 problem, `morea evaluate` of the chosen solution (best guidance) on the
#                 problem, with the landmarks per kind, and of the knee beside it (configuration
#                 VARIANT-knee: the report's side row "MOREA (knee)", not tested); keeps only scores.json, run.json
#                 and front.csv per run, plus renders of the first seed. Writes, into
#                 OUTDIR, study-morea-TAG.tar.gz (the tree to unpack into STUDY/),
#                 study-morea-TAG.csv (one line per run) and study-morea-TAG.log.
#                 The archive is rewritten after every run, so a run killed at the
#                 time limit still returns what finished.
#   Here (3):     bench/run-study-morea.sh unpack OUTDIR/study-morea-TAG.tar.gz STUDY
#                 then: build/study-venv/bin/python -m study run --pair PAIR --out STUDY/PAIR
#                 (it skips every run whose scores.json exists: these MOREA runs).
#
# Selection on the GPU (environment; default: everything in the bundle):
#   MOREA_STUDY_PAIRS="phantom-emptying phantom-static"   pairs (folder names)
#   MOREA_STUDY_VARIANTS="default no-bone-guidance"       MOREA configurations
#   MOREA_STUDY_SEEDS="1 2 3 4 5"                         seeds (default: the job's)
#   MOREA_STUDY_DEADLINE_S=540   start no registration that would end after this
#                                many seconds from the script's start (a command may
#                                run 10 minutes); what is left is for another call
#   MOREA_STUDY_TAG=NAME         names the outputs (default: the pairs and seeds)
#   MOREA_STUDY_KEEP_FIELDS=1    also keep both fields of the first seed (a few MB each)
#   MOREA_STUDY_FRONT=N          also write N members spread over the front (--select spread:N)
#                                and score each (study/front_scores.py): front_scores.csv per
#                                run, TRE and Dice along the front; "all" for every member
#                                (slow: a paper-scale front holds 500-1700)
#   MOREA_STUDY_SET="K=V ..."    an experiment outside the study: these overrides on every run,
#   MOREA_STUDY_LABEL=NAME       whose results go to configuration VARIANT-NAME (required with
#                                MOREA_STUDY_SET, so that they never mix with the study's runs)
#   MOREA_STUDY_WORK=/tmp/study-morea   scratch (runs finished there are not redone
#                                while the machine stays the same)
#   MOREA_BIN, MOREA_BUNDLE_DIR  a morea binary / unpacked bundle (default /tmp/b, unpacked
#                                from device-carry/study-morea.tar.xz when missing)
# A device call (carry: device-carry/study-morea.tar.xz, not all of device-carry),
# e.g. one pair (10 registrations) per call:
#   MOREA_STUDY_PAIRS=phantom-emptying bench/run-study-morea.sh run "$OUT"
# When the deadline stops a call, its log names the first run left: call again
# with MOREA_STUDY_PAIRS / MOREA_STUDY_VARIANTS / MOREA_STUDY_SEEDS naming what is
# left (on a fresh machine finished runs are not known), and unpack every archive.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

usage() { awk 'NR >= 4 && /^set -euo/ {exit} NR >= 4' "$0" >&2; exit 2; }

case "${1:-}" in
  bundle)
    shift
    [ $# -gt 0 ] || usage
    stage=$(mktemp -d)
    trap 'rm -rf "$stage"' EXIT
    data=()
    for d in "$@"; do
      [ -f "$d/morea_job.json" ] || { echo "$d: no morea_job.json (python -m study prepare first)" >&2; exit 1; }
      pair=$(basename "$d")
      mkdir -p "$stage/$pair"
      cp "$d/morea_job.json" "$d/morea_parameters.toml" "$stage/$pair/"
      cp -r "$d/problem" "$stage/$pair/"
      [ -d "$d/landmarks" ] && cp -r "$d/landmarks" "$stage/$pair/"
      # A data pair's raw files (morea_job.json's raw_files, relative to the data folder).
      data_root=${MOREA_SHARED_DATA_DIR:-../shared/data}
      while IFS= read -r f; do
        [ -n "$f" ] || continue
        mkdir -p "$stage/$pair/raw/$(dirname "$f")"
        cp "$data_root/$f" "$stage/$pair/raw/$f"
      done < <(python3 -c "import json,sys; print('\n'.join(json.load(open(sys.argv[1])).get('raw_files', [])))" "$d/morea_job.json")
      data+=(--data "$stage/$pair")
    done
    MOREA_BUNDLE=${MOREA_BUNDLE:-device-carry/study-morea.tar.xz} \
      tools/device-bundle.sh "${data[@]}" build/bin/morea
    ;;

  run)
    out=${2:?usage: $0 run OUTDIR}
    label=${MOREA_STUDY_LABEL:+-$MOREA_STUDY_LABEL}
    if [ -n "${MOREA_STUDY_SET:-}" ] && [ -z "$label" ]; then
      echo "MOREA_STUDY_SET needs MOREA_STUDY_LABEL (an experiment's runs are kept apart)" >&2; exit 2
    fi
    select=best-guidance,knee
    front=${MOREA_STUDY_FRONT:-0}
    case "$front" in
      0) ;;
      all) select=$select,all ;;
      ''|*[!0-9]*) echo "MOREA_STUDY_FRONT=$front: a number of solutions, or all" >&2; exit 2 ;;
      *) select=$select,spread:$front ;;
    esac
    mkdir -p "$out"
    out=$(cd "$out" && pwd)
    t0=$(date +%s)
    bundle=${MOREA_BUNDLE_DIR:-/tmp/b}
    if [ -z "${MOREA_BIN:-}" ]; then
      # Calls side by side share the bundle: one unpacks it (whole, then
      # renamed into place) while the others wait for the lock.
      (
        flock 9
        if [ ! -x "$bundle/bin/morea" ]; then
          rm -rf "$bundle.part" && mkdir -p "$bundle.part"
          tar xJf device-carry/study-morea.tar.xz -C "$bundle.part"
          rm -rf "$bundle" && mv -T "$bundle.part" "$bundle"
        fi
      ) 9> "$bundle.lock"
      export LD_LIBRARY_PATH="$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
      morea="$bundle/bin/morea"
    else
      morea=$MOREA_BIN
    fi
    work=${MOREA_STUDY_WORK:-/tmp/study-morea}
    results="$work/results"
    mkdir -p "$results" "$work/raw" "$work/reg"
    deadline=${MOREA_STUDY_DEADLINE_S:-540}
    pairs_sel=${MOREA_STUDY_PAIRS:-}
    if [ -z "$pairs_sel" ]; then
      for j in "$bundle"/data/*/morea_job.json; do pairs_sel="$pairs_sel $(basename "$(dirname "$j")")"; done
    fi
    tag=${MOREA_STUDY_TAG:-$(echo $pairs_sel ${MOREA_STUDY_VARIANTS:-} ${MOREA_STUDY_SEEDS:+s${MOREA_STUDY_SEEDS}} | tr ' ' '_' | tr -cd 'A-Za-z0-9._-')}
    log="$out/study-morea-$tag.log"
    csv="$out/study-morea-$tag.csv"
    gpu=$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -1 || true)
    host="${gpu:-no GPU}, $(nproc) host cores"
    echo "pair,config,seed,seconds,backend,tre_mean_mm,tre_bone_mm,primary_dice,bladder_dice,jacobian_nonpositive_fraction,status" >"$csv"
    say() { echo "$(date +%T) $*" | tee -a "$log"; }
    pack() { tar czf "$out/study-morea-$tag.tar.gz.tmp" -C "$results" . && mv "$out/study-morea-$tag.tar.gz.tmp" "$out/study-morea-$tag.tar.gz"; }
    jq_() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); v=eval(sys.argv[2]); print(v if not isinstance(v,(list,dict)) else json.dumps(v))" "$@"; }
    # score SOLUTION_DIR RUN_DIR SOLUTION CONFIG: scores.json.tmp (with the landmarks per
    # kind) and run.json of one selected solution of the registration in $reg.
    score() {
      local sol=$1 rd=$2 solution=$3 config=$4 parts=() k
      "$morea" evaluate --problem "$pd/problem" --field "$sol/preprocessed_fixed_to_moving.nii.gz" \
        --inverse-field "$sol/preprocessed_moving_to_fixed.nii.gz" -o "$rd/scores.main.json" >>"$log" 2>&1
      for k in $kinds; do
        "$morea" evaluate --problem "$pd/problem" --field "$sol/preprocessed_fixed_to_moving.nii.gz" \
          --fixed-landmarks "$pd/landmarks/$k/fixed_landmarks.txt" \
          --moving-landmarks "$pd/landmarks/$k/moving_landmarks.txt" -o "$rd/scores.$k.json" >>"$log" 2>&1
        parts+=("$k=$rd/scores.$k.json")
      done
      if [ ${#parts[@]} -gt 0 ]; then
        python3 -m study.landmark_kinds merge "$rd/scores.json.tmp" "$rd/scores.main.json" "${parts[@]}"
      else
        cp "$rd/scores.main.json" "$rd/scores.json.tmp"
      fi
      rm -f "$rd"/scores.*.json
      python3 -m study.morea_record record "$reg" "$rd/run.json" --seed "$seed" --config "$config" \
        --parameters "study/params/$(jq_ "$job" "d['parameters_source']")" --seconds "$seconds" \
        --host "$host" --extra-args "${extra[*]:-}" --solution "$solution"
    }
    say "morea: $morea ($("$morea" info 2>/dev/null | head -1 || true)); $host; deadline ${deadline} s"
    last=0
    stop=0
    for pair in $pairs_sel; do
      [ $stop = 0 ] || break
      pd="$bundle/data/$pair"
      job="$pd/morea_job.json"
      [ -f "$job" ] || { say "$pair: not in the bundle"; continue; }
      raw_args=()
      case_args=$(jq_ "$job" "' '.join(d.get('phantom_arguments') or []) if 'phantom_arguments' in d else '-'")
      raw="$work/raw/$pair"
      [ -d "$pd/raw" ] && raw="$pd/raw"   # a data pair's files, carried in the bundle
      if [ "$case_args" != "-" ]; then
        if ! python3 -m study.morea_record md5 "$raw" "$job" 2>/dev/null; then
          rm -rf "$raw"
          # shellcheck disable=SC2086
          "$morea" phantom $case_args -o "$raw" >>"$log" 2>&1
          if ! python3 -m study.morea_record md5 "$raw" "$job" 2>>"$log"; then
            say "$pair: the phantom written here differs from the study's; skipped"
            continue
          fi
        fi
      fi
      while IFS= read -r a; do raw_args+=("${a//\{raw\}/$raw}"); done < <(jq_ "$job" "'\n'.join(d['raw_args'])")
      variants=${MOREA_STUDY_VARIANTS:-$(jq_ "$job" "' '.join(d['variants'])")}
      seeds=${MOREA_STUDY_SEEDS:-$(jq_ "$job" "' '.join(map(str, d['seeds']))")}
      first_seed=$(jq_ "$job" "min(d['seeds'])")
      focus=$(jq_ "$job" "d['focus']")
      init=$(jq_ "$job" "d.get('initial_transform') or ''")
      kinds=$(jq_ "$job" "' '.join(d.get('landmark_kinds') or [])")
      for variant in $variants; do
        [ $stop = 0 ] || break
        extra=()
        while IFS= read -r a; do [ -n "$a" ] && extra+=("$a"); done < <(jq_ "$job" "'\n'.join(d['variants']['$variant'])")
        for o in ${MOREA_STUDY_SET:-}; do extra+=(--set "$o"); done
        for seed in $seeds; do
          rd="$results/$pair/runs/morea/$variant$label/seed$seed"
          if [ -f "$rd/scores.json" ]; then continue; fi
          now=$(( $(date +%s) - t0 ))
          if [ $(( now + last + last / 5 )) -gt "$deadline" ]; then
            say "deadline: $pair $variant seed $seed and later runs left for another call"
            stop=1
            break
          fi
          reg="$work/reg/$pair-$variant-$seed"
          rm -rf "$reg" "$rd"
          mkdir -p "$rd"
          cmd=("$morea" register "${raw_args[@]}" --parameters "$pd/morea_parameters.toml" --set "seed=$seed"
               "${extra[@]}" --select "$select" --checkpoint-every 0)
          [ -n "$init" ] && cmd+=(--initial-transform "$pd/$init")
          cmd+=(-o "$reg")
          say "$pair $variant$label seed $seed"
          s0=$(date +%s.%N)
          if ! "${cmd[@]}" >"$work/reg/$pair-$variant-$seed.log" 2>&1; then
            say "  FAILED (morea register), see the log in the archive"
            tail -c 3000 "$work/reg/$pair-$variant-$seed.log" >"$rd/failed.log"
            python3 -c "import json,sys; json.dump({'error': 'morea register failed on the GPU machine', 'log_tail': open(sys.argv[2]).read()}, open(sys.argv[1], 'w'))" "$rd/failed.json" "$rd/failed.log"
            echo "$pair,$variant,$seed,,,,,,,,failed" >>"$csv"
            pack
            continue
          fi
          seconds=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.3f}')" "$s0" "$(date +%s.%N)")
          last=${seconds%.*}
          if ! python3 -m study.morea_record check "$reg" "$pd/problem" 2>>"$log"; then
            say "  FAILED: the run's preprocessing is not the study's problem"
            python3 -c "import json,sys; json.dump({'error': 'preprocessing differs from the study problem (see the log)'}, open(sys.argv[1], 'w'))" "$rd/failed.json"
            echo "$pair,$variant,$seed,$seconds,,,,,,,failed-check" >>"$csv"
            pack
            continue
          fi
          sol="$reg/best_guidance"
          score "$sol" "$rd" best_guidance "$variant$label"
          if [ -d "$reg/knee" ]; then   # beside the chosen solution: the knee, its own configuration
            kd="$results/$pair/runs/morea/$variant$label-knee/seed$seed"
            rm -rf "$kd" && mkdir -p "$kd"
            score "$reg/knee" "$kd" knee "$variant$label-knee"
            mv "$kd/scores.json.tmp" "$kd/scores.json"
          fi
          cp "$reg/front.csv" "$rd/"
          if [ "$front" != 0 ]; then
            python3 -m study.front_scores "$reg" "$pd/problem" "$rd/front_scores.csv" --morea "$morea" \
              ${kinds:+--landmarks "$pd/landmarks"} 2>>"$log" || say "  front scores failed (see the log)"
          fi
          if [ "$seed" = "$first_seed" ]; then
            mkdir -p "$results/$pair/renders"
            "$morea" evaluate --problem "$pd/problem" --field "$sol/preprocessed_fixed_to_moving.nii.gz" \
              --render "$results/$pair/renders/morea_${variant}${label}_seed${seed}" --focus "$focus" >>"$log" 2>&1 || true
            if [ "${MOREA_STUDY_KEEP_FIELDS:-0}" = 1 ]; then
              cp "$sol/preprocessed_fixed_to_moving.nii.gz" "$rd/fixed_to_moving.nii.gz"
              cp "$sol/preprocessed_moving_to_fixed.nii.gz" "$rd/moving_to_fixed.nii.gz"
            fi
          fi
          mv "$rd/scores.json.tmp" "$rd/scores.json"   # last: the study skips runs with scores.json
          line=$(python3 - "$rd/scores.json" "$rd/run.json" "$focus" <<'EOF_PY'
import json, sys
s, r, focus = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), sys.argv[3]
st = s.get("structures", {})
kind = (s.get("landmarks_by_kind") or {}).get("bone") or {}
f = lambda v: "" if v is None else (f"{v:.6g}" if isinstance(v, float) else str(v))
print(",".join(f(v) for v in (r.get("backend"), (s.get("landmarks") or {}).get("tre_mean_mm"),
      kind.get("tre_mean_mm"), (st.get(focus) or {}).get("dice"), (st.get("bladder") or {}).get("dice"),
      s.get("jacobian_nonpositive_fraction"))))
EOF_PY
)
          echo "$pair,$variant$label,$seed,$seconds,$line,ok" >>"$csv"
          say "  $seconds s: $line"
          rm -rf "$reg" "$work/reg/$pair-$variant-$seed.log"
          pack
        done
      done
    done
    pack
    say "done after $(( $(date +%s) - t0 )) s: $out/study-morea-$tag.tar.gz"
    ;;

  unpack)
    archive=${2:?usage: $0 unpack ARCHIVE STUDY_ROOT}
    root=${3:?usage: $0 unpack ARCHIVE STUDY_ROOT}
    mkdir -p "$root"
    # Runs that exist here already are kept (a run is whole once scores.json is there).
    tar xzf "$archive" -C "$root" --skip-old-files
    tar tzf "$archive" | grep -c 'scores.json$' | sed 's/^/MOREA runs in the archive: /'
    ;;

  *) usage ;;
esac
