#!/usr/bin/env bash
# device_compare.sh DIR: sets a GPU's device_check runs (DIR, unpacked from
# device_check.tar.gz) beside this machine's PoCL CPU device. Runs the same 4e7-photon case at
# the default seed and at seed 2, and compares bin by bin: chi2 per bin of
# (a - b)^2 / (se_a^2 + se_b^2), about 1 when two independent runs agree within noise, far below
# 1 when they trace the same photons (docs/reference.md, Rules: across devices the same within
# noise). Also rte2d, GPU against CPU (deterministic: the largest relative difference).
set -euo pipefail
cd "$(dirname "$0")/.."
gpu=$1
cpu=${2:-build/device_compare}
make -s ppbench
chi2() { # two radiance.csv: every result of the run (mc, mc1), bin by bin
  awk -F, 'FNR == 1 {next}
    NR == FNR {r[$1,$2,$3,$5,$6] = $7; s[$1,$2,$3,$5,$6] = $8; next}
    ($1,$2,$3,$5,$6) in r {k = $1 SUBSEP $2 SUBSEP $3 SUBSEP $5 SUBSEP $6
      v = s[k]^2 + $8^2; if (v > 0) {d = r[k] - $7; c += d*d/v; n++}}
    END {printf "chi2/bin %.3f over %d bins\n", c / n, n}' "$1" "$2"
}
case=configs/uniform_g0_normal.ini
for seed in 1 2; do
  [ -f "$cpu/seed$seed/radiance.csv" ] ||
    PPBENCH_DEVICE=pthread ./ppbench run --quiet --no-ref-cache --out "$cpu/seed$seed" "$case" \
      --set experiment.methods=mc --set mc.photons=4e7 --set mc.seed=$seed
  echo "GPU 4e7 (seed 1) against PoCL 4e7 (seed $seed): $(chi2 "$gpu/mc4e7_wg64/radiance.csv" "$cpu/seed$seed/radiance.csv")"
done
echo "GPU 4e8 (seed 1) against PoCL 4e7 (seed 2): $(chi2 "$gpu/study/radiance.csv" "$cpu/seed2/radiance.csv")"
[ -f "$cpu/rte2d/radiance.csv" ] ||
  PPBENCH_DEVICE=pthread ./ppbench run --quiet --out "$cpu/rte2d" "$case" --set experiment.methods=rte2d
# The device check measures the Monte Carlo and rte2d by name: they are the two methods with
# kernels heavy enough for a GPU to matter.
awk -F, -v id=rte2d 'FNR == 1 {next} $1 != id {next}
  NR == FNR {r[$2,$3,$5,$6] = $7; next}
  ($2,$3,$5,$6) in r {a = r[$2,$3,$5,$6]; if (a != 0) {d = ($7 - a) / a; if (d < 0) d = -d; if (d > m) m = d}; n++}
  END {printf "rte2d GPU against PoCL: largest relative difference %.2e over %d bins\n", m, n}' \
  "$gpu/study/radiance.csv" "$cpu/rte2d/radiance.csv"
