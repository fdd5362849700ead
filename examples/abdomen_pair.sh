#!/usr/bin/env bash
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
