#!/usr/bin/env bash
# materials_study.sh [--out DIR] [--cache DIR] [--set SEC.KEY=VAL ...]: the materials study
# (docs/reference.md: Colour; results/materials/README.md), part of `make bench` (bench.sh calls
# it after the accuracy study) and runnable alone: every case of configs/materials.list, a
# measured material in colour (channel = rgb), into DIR/<case> (default results/materials), its
# subsets r, g, b and y (the luminance) each a case of the materials' own report (Table 2,
# ranking, Fig. 8 and the pictures per material and channel) and summary figure. The Monte Carlo
# references are shipped (references/material_*_<r|g|b>, scripts/references.sh): with the
# reference cache (default build/ref-cache, PPB_REF_CACHE) the study traces no photon.
set -euo pipefail
cd "$(dirname "$0")/.."
out=results/materials
cache=${PPB_REF_CACHE:-build/ref-cache}
sets=()
while [ $# -gt 0 ]; do
  case $1 in
    --out) out=$2; shift ;;
    --cache) cache=$2; shift ;;
    --set) sets+=(--set "$2"); shift ;;
    *) echo "materials_study.sh: unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done
mapfile -t materials < configs/materials.list
mkdir -p "$out"
t0=$(date +%s)
subsets=()
for i in "${!materials[@]}"; do
  c=${materials[$i]}
  printf '[materials %d/%d] %s (%ds elapsed)\n' $((i + 1)) ${#materials[@]} "$c" $(( $(date +%s) - t0 )) >&2
  PPB_BENCH_STUDY=1 ./ppbench run "${sets[@]}" --ref-cache "$cache" --out "$out/$c" "configs/$c.ini"
  for s in r g b y; do subsets+=("$c/$s"); done
done
bash scripts/summary_plot.sh "$out" "${subsets[@]}"
./ppbench report "$out" "${subsets[@]}"
printf 'materials study written to %s/ in %ds: see %s/README.md\n' "$out" $(( $(date +%s) - t0 )) "$out" >&2
