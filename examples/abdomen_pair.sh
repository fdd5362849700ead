#!/usr/bin/env bash
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# Loads the abdominal CBCT pair from its RT Structure Sets (DICOM), preprocesses
# it around the stomach and prints the baseline scores.
set -euo pipefail
DATA=${1:-../shared/data/abdomen-cbct-pair}
OUT=${2:-abdomen-out}
MOREA=${MOREA:-./build/bin/morea}
mkdir -p "$OUT"
[ -d "$OUT/dicom" ] || tar xJf "$DATA/dicom.tar.xz" -C "$OUT"
D="$OUT/dicom"
"$MOREA" preprocess \
  --fixed "$D/CB02_image" --moving "$D/CB07_image" \
  --fixed-structure Stomach_duo_CBCT="$D/CB02_rtstruct:Stomach_duo_CBCT" \
  --moving-structure Stomach_duo_CBCT="$D/CB07_rtstruct:Stomach_duo_CBCT" \
  --fixed-structure Bowel_sm_CBCT="$D/CB02_rtstruct:Bowel_sm_CBCT" \
  --moving-structure Bowel_sm_CBCT="$D/CB07_rtstruct:Bowel_sm_CBCT" \
  --set preprocess_rigid_structure=none -o "$OUT/preprocessed"
"$MOREA" evaluate --problem "$OUT/preprocessed" -o "$OUT/scores.json" --render "$OUT/render"
# MOREA with the small configuration (a few minutes on 2 cores), from the
# provided masks and label maps (moving CB07, fixed CB02).
"$MOREA" register \
  --fixed "$DATA/CB02.mha" --moving "$DATA/CB07.mha" \
  --fixed-structure Stomach_duo_CBCT="$DATA/CB02_labels.mha:Stomach_duo_CBCT" \
  --moving-structure Stomach_duo_CBCT="$DATA/CB07_masks/Stomach_duo_CBCT.mha" \
  --fixed-structure Bowel_sm_CBCT="$DATA/CB02_labels.mha:Bowel_sm_CBCT" \
  --moving-structure Bowel_sm_CBCT="$DATA/CB07_masks/Bowel_sm_CBCT.mha" \
  --parameters "$(dirname "$0")/abdomen_small.toml" -o "$OUT/morea"
