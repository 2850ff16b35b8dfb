#!/usr/bin/env bash
# objects_study.sh [--out DIR] [--set SEC.KEY=VAL ...]: the three-dimensional study
# (docs/reference.md: Objects; docs/methods.md: pp and ss in three dimensions), part of
# `make bench` (bench.sh calls it after the materials study) and runnable alone: every object of
# configs/objects (the box, the cube lit on two faces, the ball, the yokan with its chestnut and
# the mesh blob) with mc3d (the reference), ss3d and pp3d, into DIR/<object> (default
# results/objects), one figure per object (figure.png: the methods' images beside the Monte
# Carlo's and their error images, with colour bars) and DIR/README.md (a table per object from
# regions.csv, timings.csv and totals_pp3d.csv). About 6-9 minutes on the project's 2-core CPU.
set -euo pipefail
cd "$(dirname "$0")/.."
out=results/objects
sets=()
while [ $# -gt 0 ]; do
  case $1 in
    --out) out=$2; shift ;;
    --set) sets+=(--set "$2"); shift ;;
    *) echo "objects_study.sh: unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done
# The paper's albedos where it gives them (Sec. 4.2, Fig. 9): the bunny's g = 0, alpha = 0.95
# (the configs' medium for box, cube, ball and blob); the yokan's and the chestnut's red channel,
# 0.16 and 0.51 (their g is not given: the config's 0.5). 2e7 photons: the Monte Carlo's mean
# standard error over its mean is under 1 % a pixel and 2-10 % a patch cell (the staircase
# ball's and blob's small patches), the noise column of the README, below the errors reported. 2 x 2 direction samples a bin keep pp3d's
# patches to seconds; 334 directions as the paper's.
# shellcheck disable=SC2054 # the commas are inside one value
common=(--set experiment.methods=mc3d,ss3d,pp3d --set mc.photons=2e7 --set mc.batches=16
        --set bins.samples_dir=2 --set pp.directions=334)
objects=(box cube_two_faces sphere yokan blob)
declare -A extra=([yokan]="--set medium.albedo=0.16 --set object.inclusion_albedo=0.51")
mkdir -p "$out"
t0=$(date +%s)
for i in "${!objects[@]}"; do
  o=${objects[$i]}
  printf '[objects %d/%d] %s (%ds elapsed)\n' $((i + 1)) ${#objects[@]} "$o" $(( $(date +%s) - t0 )) >&2
  # shellcheck disable=SC2086
  PPB_BENCH_STUDY=1 ./ppbench object "${common[@]}" ${extra[$o]:-} "${sets[@]}" --out "$out/$o" \
    "configs/objects/$o.ini"
  bash scripts/objects_figure.sh "$out/$o" "$o"
  # committed results stay small: the linear images, the voxels and the per-cell radiance
  # (tens of MB) are left out; rerun the object's line to get them
  rm -f "$out/$o"/images/*.exr "$out/$o/object.vox" "$out/$o/radiance.csv"
done
bash scripts/objects_readme.sh "$out" "${objects[@]}" > "$out/README.md.tmp"
mv "$out/README.md.tmp" "$out/README.md"
printf 'objects study written to %s/ in %ds: see %s/README.md\n' "$out" $(( $(date +%s) - t0 )) "$out" >&2
