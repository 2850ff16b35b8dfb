#!/usr/bin/env bash
# plots.sh CASE_DIR THETA_DEG: the case's plots as PNG with gnuplot, from its CSVs.
#   plots/rms_vs_x.png    RMS against the Monte Carlo at each sample point of S1 and S2, every
#                         method, with the Monte Carlo's noise floor (paper Fig. 8)
#   plots/angular_x0.png  in-plane exit radiance at x = 0 on S1 and S2 against the signed
#                         theta-bin centre, phi bin 0 (+, along t) and the last phi bin (-), with
#                         the light direction marked (paper Fig. 5)
set -euo pipefail
dir=$1
theta_l=${2:-0}
mkdir -p "$dir/plots"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

mapfile -t methods < <(awk -F, 'NR > 1 {print $1}' "$dir/rms.csv" | awk '!seen[$0]++')
for m in "${methods[@]}"; do
  for s in S1 S2; do
    awk -F, -v m="$m" -v s="$s" '$1 == m && $2 == s {print $4, $5, $6}' "$dir/rms.csv" \
      > "$tmp/rms_${m//+/_}_$s.dat"
  done
done

plot_rms() {
  local s=$1 cmd="" m
  for m in "${methods[@]}"; do
    cmd+="'$tmp/rms_${m//+/_}_$s.dat' using 1:(100*\$2) with linespoints pt 7 ps 0.4 title '$m', "
  done
  local m0=${methods[0]}
  cmd+="'$tmp/rms_${m0//+/_}_$s.dat' using 1:(100*\$3) with lines dt 2 lc rgb 'black' title 'MC noise floor'"
  echo "$cmd"
}

gnuplot <<GP
set terminal pngcairo size 1100,420 font ',10' noenhanced
set output '$dir/plots/rms_vs_x.png.tmp'
set multiplot layout 1,2 title '$(basename "$dir"): RMS error against Monte Carlo per sample point'
set logscale y
set grid
set xlabel 'x (mfp)'
set ylabel 'RMS (%)'
set key top left
set title 'S1 (top, reflectance)'
plot $(plot_rms S1)
set title 'S2 (bottom, transmittance)'
plot $(plot_rms S2)
unset multiplot
GP
mv "$dir/plots/rms_vs_x.png.tmp" "$dir/plots/rms_vs_x.png"

# In-plane cut at x = 0: the two middle segments, phi bins 0 and nphi-1.
read -r nt np nseg <<<"$(awk -F, 'NR > 1 && $2 == "S1" {if ($5 > t) t = $5; if ($6 > p) p = $6; if ($3 > s) s = $3}
  END {print t + 1, p + 1, s + 1}' "$dir/radiance.csv")"
mapfile -t all_methods < <(awk -F, 'NR > 1 {print $1}' "$dir/radiance.csv" | awk '!seen[$0]++')
for m in "${all_methods[@]}"; do
  for s in S1 S2; do
    awk -F, -v m="$m" -v s="$s" -v nt="$nt" -v np="$np" -v ns="$nseg" '
      $1 == m && $2 == s && ($3 == int(ns / 2) || $3 == int((ns - 1) / 2)) &&
      ($6 == 0 || $6 == np - 1) {
        th = atan2(sqrt(($5 + 0.5) / nt), sqrt(1 - ($5 + 0.5) / nt)) * 180 / 3.14159265358979;
        key = ($6 == 0 ? th : -th); sum[key] += $7; cnt[key]++ }
      END { for (k in sum) print k, sum[k] / cnt[k] }' "$dir/radiance.csv" | sort -g \
      > "$tmp/ang_${m//+/_}_$s.dat"
  done
done
plot_ang() {
  local s=$1 cmd="" m
  for m in "${all_methods[@]}"; do
    cmd+="'$tmp/ang_${m//+/_}_$s.dat' using 1:2 with linespoints pt 7 ps 0.5 title '$m', "
  done
  echo "${cmd%, }"
}
gnuplot <<GP
set terminal pngcairo size 1100,420 font ',10' noenhanced
set output '$dir/plots/angular_x0.png.tmp'
set multiplot layout 1,2 title '$(basename "$dir"): in-plane exit radiance at x = 0 (1/sr per unit irradiance)'
set grid
set xlabel 'signed theta (deg; + along t, - against t)'
set ylabel 'radiance'
set xrange [-90:90]
set key top left
set title 'S1 (t = +x); arrow: mirror direction of the light'
set arrow 1 from $theta_l, graph 0 to $theta_l, graph 1 nohead dt 3 lc rgb 'red'
plot $(plot_ang S1)
set title 'S2 (t = -x); arrow: the beam direction'
set arrow 1 from -$theta_l, graph 0 to -$theta_l, graph 1 nohead dt 3 lc rgb 'red'
plot $(plot_ang S2)
unset multiplot
GP
mv "$dir/plots/angular_x0.png.tmp" "$dir/plots/angular_x0.png"
