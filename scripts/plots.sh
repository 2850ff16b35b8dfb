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

# In-plane cut at x = 0 from angular.csv (ppbench writes the Table 2 cells' radiance per bin
# with the bin centres): phi bin 0 (+theta, along t) and the last phi bin (-theta).
mapfile -t all_methods < <(awk -F, 'NR > 1 {print $1}' "$dir/angular.csv" | awk '!seen[$0]++')
for m in "${all_methods[@]}"; do
  for s in S1 S2; do
    awk -F, -v m="$m" -v s="$s" '
      NR == 1 {for (i = 1; i <= NF; i++) c[$i] = i; next}
      {rows[NR] = $0; if ($c["phi_bin"] + 0 > np) np = $c["phi_bin"] + 0}
      END {for (r in rows) { split(rows[r], f, ",");
             if (f[c["method"]] != m || f[c["surface"]] != s) continue;
             if (f[c["phi_bin"]] == 0) print f[c["theta_deg"]], f[c["radiance"]];
             else if (f[c["phi_bin"]] == np) print -f[c["theta_deg"]], f[c["radiance"]] }}' \
      "$dir/angular.csv" | sort -g > "$tmp/ang_${m//+/_}_$s.dat"
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
