#!/usr/bin/env bash
# objects_readme.sh DIR OBJECT...: the objects study's README (objects_study.sh) on stdout, one
# table per object from DIR/<object>/regions.csv (rms_rel: RMS of method - mc3d over the
# reference's mean, per region, over patch cells and over pixels; the Monte Carlo's noise as its
# mean standard error over its mean), timings.csv and totals_pp3d.csv (pp3d's frame time), and
# the findings (docs/methods.md, pp and ss in three dimensions).
set -euo pipefail
dir=$1
shift
cat <<'EOF'
# The paper's method on three-dimensional objects

`bash scripts/objects_study.sh` (part of `make bench`): each object of `configs/objects/` with
`mc3d` (the reference, 2e7 photons, 16 batches), `ss3d` (single scattering) and `pp3d` (the
paper's plane-parallel method, Sec. 3.3-3.5), 334 directions, 2 x 2 direction samples a bin,
the paper's albedos where it gives them (Fig. 9: alpha 0.95, g 0 for the bunny's material; the
yokan's and the chestnut's red channel, 0.16 and 0.51). Per object `<object>/figure.png`
(images on one exposure, error images against mc3d), `regions.csv`, `timings.csv`,
`totals_*.csv` and the PNG images (docs/reference.md, Objects; the EXR images, `radiance.csv`
and `object.vox` are not kept: rerun `ppbench object` with the study's settings for them).

Tables: rms_rel = RMS of (method - mc3d) over a region's cells divided by mc3d's mean there,
over the patch cells (radiance per patch and direction bin) and over the camera's pixels;
noise = mc3d's mean standard error over its mean (what the reference cannot resolve). Regions
(docs/reference.md, Objects): faces, edges, corners by the voxels' boundary faces, shadowed
(facing away from the light or behind medium), inclusion (the chestnut). A region with no cells
is left out. The figures' error images saturate at +-10 % of L_max (the driver's PNG scale,
docs/reference.md, Objects) and pp3d's image is clipped at white where it passes L_max: at
albedo 0.95 pp3d's errors pass that nearly everywhere, so the tables carry the magnitudes (a
wider scale needs the EXR images, which the study does not keep).

EOF
for o in "$@"; do
  d=$dir/$o
  printf '## %s\n\n![%s](%s/figure.png)\n\n' "$o" "$o" "$o"
  printf '| region | patch cells | ss3d rms_rel | pp3d rms_rel | mc3d noise | pixels | ss3d rms_rel | pp3d rms_rel | mc3d noise |\n'
  printf '|---|---|---|---|---|---|---|---|---|\n'
  awk -F, 'NR > 1 { k = $1 SUBSEP $2 SUBSEP $3; n[k] = $4; r[k] = $6;
                    if ($7 > 0) nz[$2 SUBSEP $3] = $8 / $7; if (!($3 in seen)) { seen[$3] = 1; ord[++no] = $3 } }
           END { for (i = 1; i <= no; i++) { g = ord[i]; if (n["mc3d" SUBSEP "patches" SUBSEP g] + 0 == 0) continue;
                   printf "| %s | %d | %.3f | %.3f | %.3f | %d | %.3f | %.3f | %.3f |\n", g,
                     n["mc3d" SUBSEP "patches" SUBSEP g], r["ss3d" SUBSEP "patches" SUBSEP g],
                     r["pp3d" SUBSEP "patches" SUBSEP g], nz["patches" SUBSEP g],
                     n["mc3d" SUBSEP "pixels" SUBSEP g], r["ss3d" SUBSEP "pixels" SUBSEP g],
                     r["pp3d" SUBSEP "pixels" SUBSEP g], nz["pixels" SUBSEP g] } }' "$d/regions.csv"
  awk -F, 'NR > 1 { t[$1] = $2 } END { printf "\nTimes (2 shared cores): mc3d %.1f s, ss3d %.1f s, pp3d %.1f s", t["mc3d"], t["ss3d"], t["pp3d"] }' "$d/timings.csv"
  awk -F, 'NR == 2 { printf "; pp3d pre-process (map, tables) %.2f s, one frame (the camera image alone, %d rays) %.3f s against the paper'"'"'s 0.17 s a frame (Sec. 4.2: ~7.5 K vertices, 2 GHz Athlon 64).\n\n", $1, $4, $3 }' "$d/totals_pp3d.csv"
done
if [ -f "$dir/FINDINGS.md" ]; then cat "$dir/FINDINGS.md"; fi
