#!/usr/bin/env bash
# summary_plot.sh STUDY_DIR CASE...: the study's summary figure, STUDY_DIR/summary.png, which
# the study README opens with (`ppbench report`, src/drivers/report.c; scripts/bench.sh calls
# this before it). Two panels, R_x0 and T_x0 (the paper's Table 2 cells, reference: Metrics):
# per case (x) each method's rms_excess in percent (points, one colour and shape per method as
# in every plot: scripts/plot_style.gp) and the Monte Carlo's noise floor there (black bar: the
# smallest noise_rel of the cell's rows, which for a deterministic method is the reference's
# own). Read from STUDY_DIR/CASE/summary.csv, nothing re-derived. Log y from 0.1 %: an excess
# below it (0 where the RMS is within the noise) is drawn on the axis at 0.1.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: summary_plot.sh STUDY_DIR CASE..." >&2; exit 2; }
dir=$1
shift
here=$(cd "$(dirname "$0")" && pwd)
command -v gnuplot > /dev/null || { echo "summary_plot.sh: gnuplot not found" >&2; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ppb-summary.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

# data: one block per cell (R_x0, T_x0): "index case method excess% noise%" rows; methods in
# the order of their first appearance (the configs' order), mc1 (the Monte Carlo's own part)
# left out.
methods=()
i=0
for c in "$@"; do
  f=$dir/$c/summary.csv
  [ -f "$f" ] || { echo "summary_plot.sh: $f missing" >&2; exit 1; }
  while IFS=, read -r m cell rms noise excess; do
    [ "$m" = method ] || [ "$m" = mc1 ] && continue
    case $cell in R_x0 | T_x0) ;; *) continue ;; esac
    printf '%d %s %s %s %s\n' "$i" "$c" "$m" "$excess" "$noise" >> "$tmp/$cell"
    [[ " ${methods[*]-} " == *" $m "* ]] || methods+=("$m")
  done < "$f"
  i=$((i + 1))
done
n=$#
[ ${#methods[@]} -gt 0 ] || { echo "summary_plot.sh: no method rows at R_x0, T_x0" >&2; exit 1; }

{
  echo "load '$here/plot_style.gp'"
  echo "set terminal pngcairo size 1100,760 font ',10' noenhanced"
  echo "set output '$dir/summary.png'"
  echo "set multiplot layout 2,1 title 'Excess RMS against the Monte Carlo at the Table 2 cells (rms_excess in %; black bars: the Monte Carlo noise floor, noise_rel)'"
  echo "set logscale y"
  echo "set yrange [0.1:150]"
  echo "set ytics ('0.1' 0.1, '0.3' 0.3, '1' 1, '3' 3, '10' 10, '30' 30, '100' 100)"
  echo "set grid ytics lc rgb '#dddddd'"
  echo "set xrange [-0.6:$n - 0.4]"
  echo "set key outside right top vertical"
  echo "set lmargin 15" # room for the first case name, rotated below it
  echo "set rmargin 16"
  xt="" xe=""
  k=0
  for c in "$@"; do
    xt="$xt${xt:+, }'$c' $k" xe="$xe${xe:+, }'' $k"
    k=$((k + 1))
  done
  for cell in R_x0 T_x0; do
    if [ $cell = R_x0 ]; then
      echo "set xtics ($xe)"
      echo "unset xlabel"
      echo "set tmargin 3"
      echo "set bmargin 1"
    else
      echo "set xtics ($xt) rotate by 30 right"
      echo "set tmargin 1"
      echo "set bmargin 9"
    fi
    echo "set ylabel '$cell: excess RMS, %'"
    plot="plot '$tmp/$cell' using 1:(\$5 * 100):(0.32) with xerrorbars pt -1 lw 3 lc rgb '#000000' title 'mc noise'"
    j=0
    nm=${#methods[@]}
    for m in "${methods[@]}"; do
      off=$(awk -v j=$j -v n=$nm 'BEGIN {printf "%.4f", (j - (n - 1) / 2) * 0.6 / n}')
      plot="$plot, '$tmp/$cell' using (strcol(3) eq '$m' ? \$1 + $off : NaN):(\$4 * 100 < 0.1 ? 0.1 : \$4 * 100) with points pt mpoint('$m') ps 1.3 lc rgb mcolor('$m') title '$m'"
      j=$((j + 1))
    done
    echo "$plot"
  done
  echo "unset multiplot"
} > "$tmp/plot.gp"
gnuplot "$tmp/plot.gp"
echo "summary_plot.sh: wrote $dir/summary.png" >&2
