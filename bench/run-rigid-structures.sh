#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Bone landmark TRE with and without bones among the guidance structures,
# with and without the rigidity term (morea_rigid_weight 0), on a case of the
# phantom suite whose truth is known (bones do not move in its new cases).
# Per run and chosen solution (best guidance, knee): the mean TRE per
# landmark kind (bone, wall, organ, soft, all), scored on the preprocessed grid.
#   bench/run-rigid-structures.sh MOREA OUTDIR [CASE [PARAMETERS.toml [KEY=VALUE...]]]
# KEY=VALUE pairs override parameters (e.g. ea_num_generations=60).
# MOREA_RIGID_RUNS picks runs as GUIDANCE:WEIGHT words (default: all four of
# all:0 all:default without-bones:0 without-bones:default). Writes
# OUTDIR/rigid-structures.csv and prints it.
set -euo pipefail
morea=$1
out=$2
case_name=${3:-bladder-emptying}
parameters=${4:-}
overrides=("${@:5}")
# Bones stay inside the crop; the bones' pre-alignment is left out so that
# only the registration can move them (they do not move in the truth).
settings=(--set preprocess_crop_margin=80 --set preprocess_rigid_structure=none --set num_runs=1 --set zip=false)
[ -n "$parameters" ] && settings+=(--parameters "$parameters" --var experiment_descriptor=rigid --var problem_id="$case_name")
for o in "${overrides[@]}"; do settings+=(--set "$o"); done

mkdir -p "$out"
"$morea" phantom --case "$case_name" -o "$out/phantom" >/dev/null
"$morea" preprocess --problem "$out/phantom" -o "$out/pre" "${settings[@]}" >/dev/null

# Landmark files per kind, from phantom.json's landmark_kinds (one per landmark).
kinds=$(awk '/"landmark_kinds"/{on=1; next} on && /\]/{exit} on{gsub(/[ ",]/, ""); print}' "$out/phantom/phantom.json")
for side in fixed moving; do
  for kind in bone wall organ soft all; do
    mkdir -p "$out/landmarks/$kind"
    paste <(echo "$kinds") <(tail -n +3 "$out/phantom/${side}_landmarks.txt") |
      awk -v k="$kind" -F'\t' 'k == "all" || $1 == k {print $2}' >"$out/landmarks/$kind/points"
    { echo point; wc -l <"$out/landmarks/$kind/points"; cat "$out/landmarks/$kind/points"; } \
      >"$out/landmarks/$kind/${side}_landmarks.txt"
  done
done

number() { sed -n "s/.*\"$1\": *\([-0-9.eE+]*\).*/\1/p" "$2" | head -1; }
echo "guidance,rigid_weight,solution,seconds,tre_bone_mm,tre_bone_max_mm,tre_wall_mm,tre_organ_mm,tre_soft_mm,tre_all_mm,bladder_dice,jacobian_nonpositive" \
  >"$out/rigid-structures.csv"
for guidance in all without-bones; do
  selection=-1
  [ "$guidance" = without-bones ] && selection=bladder,rectum,bowel
  for weight in 0 default; do
    case " ${MOREA_RIGID_RUNS:-all:0 all:default without-bones:0 without-bones:default} " in
      *" $guidance:$weight "*) ;;
      *) continue ;;
    esac
    run="$out/$guidance-rigid-$weight"
    rigid=()
    [ "$weight" = 0 ] && rigid=(--set morea_rigid_weight=0)
    start=$(date +%s.%N)
    "$morea" register --problem "$out/phantom" -o "$run" --select best-guidance,knee "${settings[@]}" \
      --set problem_guidance_selection="$selection" "${rigid[@]}" >"$run.log" 2>&1
    seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    for solution in best_guidance knee; do
      line="$guidance,$weight,$solution,$seconds"
      for kind in bone wall organ soft all; do
        "$morea" evaluate --problem "$out/pre" --field "$run/$solution/preprocessed_fixed_to_moving.nii.gz" \
          --inverse-field "$run/$solution/preprocessed_moving_to_fixed.nii.gz" \
          --fixed-landmarks "$out/landmarks/$kind/fixed_landmarks.txt" \
          --moving-landmarks "$out/landmarks/$kind/moving_landmarks.txt" -o "$run/$solution/tre-$kind.json" >/dev/null
        line="$line,$(number tre_mean_mm "$run/$solution/tre-$kind.json")"
        [ "$kind" = bone ] && line="$line,$(number tre_max_mm "$run/$solution/tre-$kind.json")"
      done
      dice=$(sed -n '/"bladder"/,/}/s/.*"dice": *\([0-9.eE+-]*\).*/\1/p' "$run/$solution/tre-all.json" | head -1)
      line="$line,$dice,$(number jacobian_nonpositive_fraction "$run/$solution/tre-all.json")"
      echo "$line" >>"$out/rigid-structures.csv"
    done
  done
done
cat "$out/rigid-structures.csv"
