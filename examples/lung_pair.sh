#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Preprocesses the lung CT pair (rigid pre-alignment on the lung masks) and
# scores the result against the 51 expert landmarks.
set -euo pipefail
DATA=${1:-../shared/data/lung-ct-pair}
OUT=${2:-lung-out}
MOREA=${MOREA:-./build/bin/morea}
"$MOREA" preprocess \
  --fixed "$DATA/baseline.mha" --moving "$DATA/followup.mha" \
  --fixed-structure lungs="$DATA/baseline_lung_mask.mha" \
  --moving-structure lungs="$DATA/followup_lung_mask.mha" \
  --fixed-landmarks "$DATA/baseline_landmarks51_mm.txt" \
  --moving-landmarks "$DATA/followup_landmarks51_mm.txt" \
  --set preprocess_rigid_structure=lungs -o "$OUT/preprocessed"
"$MOREA" evaluate --problem "$OUT/preprocessed" --border-margin 0 \
  -o "$OUT/scores.json" --render "$OUT/render" --focus lungs
# MOREA with the small configuration (a few minutes on 2 cores): front, chosen
# solutions' fields and transforms, scores against the landmarks and masks.
"$MOREA" register \
  --fixed "$DATA/baseline.mha" --moving "$DATA/followup.mha" \
  --fixed-structure lungs="$DATA/baseline_lung_mask.mha" \
  --moving-structure lungs="$DATA/followup_lung_mask.mha" \
  --fixed-landmarks "$DATA/baseline_landmarks51_mm.txt" \
  --moving-landmarks "$DATA/followup_landmarks51_mm.txt" \
  --parameters "$(dirname "$0")/lung_small.toml" -o "$OUT/morea"
