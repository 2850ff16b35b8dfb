#!/usr/bin/env bash
# plots.sh CASE_DIR [THETA_DEG]: a case's figures with gnuplot, from its CSVs and images, each
# as PNG (pngcairo) and PDF (pdfcairo) (reference: Outputs). `ppbench run` calls it on the
# staged output directory; it plots what exists (no Monte Carlo: no RMS plot, no error images)
# and fails only when gnuplot does. The scene (light angle, step, sigma_t) is read from
# provenance.txt; THETA_DEG, when given, overrides the light angle. Colours, markers and
# palettes: scripts/plot_style.gp (one colour per method in every plot). PPB_PLOTS_KEEP=DIR
# keeps each figure's gnuplot script body in DIR (the tests read them).
# A figure gnuplot cannot draw is left out and the next one drawn: its path under CASE_DIR and
# gnuplot's reason, "<figure>TAB<why>", is the one kind of line on stdout (src/io/plots.c puts
# it in provenance.txt and on stderr; reference: Outputs). Paths and names reach gnuplot only as
# data, its ARG variables (set in render: OUT, NAME, TMP, DIR), never as script text.
#   plots/rms_vs_x.{png,pdf}     (tube) RMS against the Monte Carlo per sample point of S1, S2,
#                                S3, S4, every method, with the Monte Carlo's noise floor; the four
#                                panels on one y range (compared at a glance); dashed lines at step_x and at
#                                step_x +- 2 mfp (paper Fig. 8; the claim is about that band)
#   plots/angular_x0.{png,pdf}   in-plane exit radiance at x = 0 on S1 and S2 against the signed
#                                theta-bin centre (phi bin 0: +, along t; the last phi bin: -),
#                                each half its own line, Monte Carlo +- 1 standard error
#   plots/angular_x0_polar.{png,pdf}  the same as a polar plot (paper Fig. 5)
#   images/all.{png,pdf}         every method's picture side by side (rows of 7), titled, over a
#                                colour bar of the grey levels (radiance / L_white; paper
#                                Fig. 6-7); the light arrow is in the pictures (src/io/images.c)
#   images/error_<m>.{png,pdf}   errmap_<m>.png titled "<m> vs mc", with a colour bar numbered
#                                -50% .. +50%
#   images/colour.{png,pdf}      (a colour set, docs/reference.md: Colour: CASE_DIR holds the
#                                subsets r, g, b, y) every method's colour picture (sRGB,
#                                images/<m>.png) in a row, the reference first, over its
#                                luminance error map against the reference (y/images/errmap_<m>.png)
set -euo pipefail
dir=$1
here=$(cd "$(dirname "$0")" && pwd)
style=$here/plot_style.gp
tmp=$(mktemp -d 2> /dev/null || mktemp -d -p /tmp)
trap 'rm -rf "$tmp"' EXIT
# Every message but the figures left out goes to stderr (stdout: see above).
exec 3>&1 1>&2

prov() { awk -F' = ' -v k="$1" '$1 == k {print $2; exit}' "$dir/provenance.txt" 2> /dev/null; }
# A CSV with data rows, not only its header (an interrupted or failed method writes none).
has_rows() { [ -f "$1" ] && [ "$(awk 'NR > 1 {n++} END {print n + 0}' "$1")" -gt 0 ]; }
name=$(prov experiment.name)
name=${name:-$(basename "$dir")}
# A number, or empty: provenance.txt's values reach the scripts as text, so only numbers pass.
num() { [[ $1 =~ ^[-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$ ]] && printf '%s' "$1"; }
theta_l=$(num "${2:-$(prov light.theta_deg)}" || true)
theta_l=${theta_l:-0}
step=$(prov medium.step)
step_x=$(num "$(prov medium.step_x)" || true)
sigma_t=$(num "$(prov medium.sigma_t)" || true)
# The result the others were measured against (ppbench passes its id), as the CSVs name it.
ref=${PPB_REFERENCE:-}
[[ $ref =~ ^[A-Za-z0-9_.+-]*$ ]] || ref=
# Method ids are read from the CSVs only as ppbench's config allows them ([A-Za-z0-9_.+-], the
# grep after each list below): the only CSV text the gnuplot scripts hold.
# failed FIGURE WHY: the figure is left out, said on stdout (fd 3).
failed() { printf '%s\t%s\n' "${1#"$dir"/}" "$2" >&3; }

# render BASENAME: $tmp/body.gp drawn to BASENAME.png and BASENAME.pdf, each atomically.
# $1: output path without extension; $2, $3: PNG size in pixels (the PDF is the same at 100 dpi).
# The body reads NAME (the experiment), TMP (this script's data files) and DIR (the case) as
# gnuplot variables; gnuplot gets them, and the output path, as arguments (ARG1..ARG5).
render() {
  local out=$1 w=$2 h=$3 t why
  if ! mkdir -p "$(dirname "$out")" 2> "$tmp/err"; then
    failed "$out" "$(tail -n 1 "$tmp/err")"
    return 0
  fi
  { echo "set terminal pngcairo size $w,$h font ',10' noenhanced"
    echo "OUT = ARG1; NAME = ARG3; TMP = ARG4; DIR = ARG5"
    echo "set output OUT"
    echo "load ARG2"
    cat "$tmp/body.gp"; } > "$tmp/png.gp"
  { echo "set terminal pdfcairo size $(awk -v w="$w" 'BEGIN {print w / 100}')in,$(awk -v h="$h" 'BEGIN {print h / 100}')in font ',7' noenhanced"
    echo "OUT = ARG1; NAME = ARG3; TMP = ARG4; DIR = ARG5"
    echo "set output OUT"
    echo "load ARG2"
    cat "$tmp/body.gp"; } > "$tmp/pdf.gp"
  # from a file, not a pipe: gnuplot then stops at the first error with a non-zero status
  for t in png pdf; do
    if ! gnuplot -c "$tmp/$t.gp" "$out.$t.tmp" "$style" "$name" "$tmp" "$dir" > "$tmp/err" 2>&1 \
       || [ ! -s "$out.$t.tmp" ]; then
      # gnuplot's reason: its last line that is not blank or only the caret under the column
      why=$(grep -v '^[[:space:]^]*$' "$tmp/err" | tail -n 1 | sed 's/^"[^"]*" //')
      rm -f "$out.png.tmp" "$out.pdf.tmp"
      failed "$out" "gnuplot: ${why:-failed, or wrote nothing}"
      return 0
    fi
  done
  mv "$out.png.tmp" "$out.png"
  mv "$out.pdf.tmp" "$out.pdf"
  # PPB_PLOTS_KEEP=DIR keeps each figure's gnuplot body as DIR/<figure>.gp (tests/test_plots.c)
  if [ -n "${PPB_PLOTS_KEEP:-}" ]; then cp "$tmp/body.gp" "$PPB_PLOTS_KEEP/$(basename "$out").gp"; fi
}

# ---- rms_vs_x: four panels, one key beside them ----
if has_rows "$dir/rms.csv" && [ "$(prov experiment.geometry)" != slab ]; then
  mapfile -t methods < <(awk -F, 'NR > 1 {print $1}' "$dir/rms.csv" | awk '!seen[$0]++' | grep -E '^[A-Za-z0-9_.+-]+$')
  for m in "${methods[@]}"; do
    for s in S1 S2 S3 S4; do
      awk -F, -v m="$m" -v s="$s" '$1 == m && $2 == s {print $4, $5, $6}' "$dir/rms.csv" \
        > "$tmp/rms_${m//+/_}_$s.dat"
    done
  done
  # the y range (%, log) of all four panels, over every curve and the floor: panels on different
  # ranges read alike while their errors differ tenfold
  yr() { awk -F, 'NR > 1 && $2 ~ /^S[1-4]$/ {
           for (i = 5; i <= 6; i++) if ($i ~ /^[-+]?[0-9.]+([eE][-+]?[0-9]+)?$/ && $i > 0) { v = 100 * $i; if (!n++ || v < lo) lo = v;
                                                  if (v > hi) hi = v } }
           END {if (!n) {lo = 0.1; hi = 100}
                a = log(lo) / log(10); f = int(a); if (f > a) f--
                b = log(hi) / log(10); c = int(b); if (c < b) c++
                printf "[%g:%g]", 10 ^ f, 10 ^ c}' \
           "$dir/rms.csv"; }
  yr_all=$(yr)
  {
    echo "set multiplot title NAME.': RMS error against Monte Carlo per sample point'"
    echo "set logscale y; set grid; set ylabel 'RMS (%)'"
    if [ -n "$step" ] && [ "$step" != none ] && [ -n "$step_x" ]; then
      mfp=$(awk -v s="${sigma_t:-1}" 'BEGIN {print 1 / s}')
      echo "set arrow 1 from $step_x, graph 0 to $step_x, graph 1 nohead dt 2 lw 1.5 lc rgb '#444444'"
      for d in -2 2; do
        echo "set arrow $((d < 0 ? 2 : 3)) from ($step_x + $d * $mfp), graph 0 to ($step_x + $d * $mfp), graph 1 nohead dt '.-' lw 1.5 lc rgb '#7B3294'"
      done
      markers="grey dashed: step_x = $step_x; purple dash-dot: step_x +- 2 mfp (mfp = 1/sigma_t = $mfp)"
    else
      markers="no step"
    fi
    echo "set label 1 '$markers' at screen 0.01, 0.015 left font ',8'"
    # the surfaces that have sample points (a slab has S1 and S2 only)
    mapfile -t surfs < <(awk -F, 'NR > 1 {print $2}' "$dir/rms.csv" | awk '!seen[$0]++' | grep -E '^S[1-4]$')
    i=0
    for s in "${surfs[@]}"; do
      case $s in
        S1) t='S1 (top, reflectance)'; xl='x (mfp)'; r=$yr_all ;;
        S2) t='S2 (bottom, transmittance)'; xl='x (mfp)'; r=$yr_all ;;
        S3) t='S3 (left side)'; xl='y (mfp; S1 at 0)'; r=$yr_all ;;
        S4) t='S4 (right side)'; xl='y (mfp; S1 at 0)'; r=$yr_all ;;
      esac
      col=$((i % 2)); row=$((i / 2))
      echo "set lmargin at screen $(awk -v c=$col 'BEGIN {print 0.07 + c * 0.41}')"
      echo "set rmargin at screen $(awk -v c=$col 'BEGIN {print 0.42 + c * 0.41}')"
      echo "set tmargin at screen $(awk -v r=$row 'BEGIN {print 0.90 - r * 0.45}')"
      echo "set bmargin at screen $(awk -v r=$row 'BEGIN {print 0.56 - r * 0.45}')"
      echo "set title '$t'; set xlabel '$xl'; set yrange $r"
      if [ $i -eq 2 ]; then echo "unset arrow"; fi
      if [ $i -eq 0 ]; then
        echo "set key at screen 0.99, 0.90 right top vertical box opaque title 'method'"
      else
        echo "unset key"
      fi
      cmd=""
      for m in "${methods[@]}"; do
        cmd+="TMP.'/rms_${m//+/_}_$s.dat' using 1:(100*\$2) with linespoints pt mpoint('$m') ps 0.4 lc rgb mcolor('$m') title '$m', "
      done
      cmd+="TMP.'/rms_${methods[0]//+/_}_$s.dat' using 1:(100*\$3) with lines dt 2 lc rgb 'black' title 'MC noise floor'"
      echo "plot $cmd"
      i=$((i + 1))
    done
    echo "unset multiplot"
  } > "$tmp/body.gp"
  render "$dir/plots/rms_vs_x" 1200 820
fi

# ---- angular_x0: the in-plane cut at x = 0 from angular.csv ----
if has_rows "$dir/angular.csv"; then
  mapfile -t all_methods < <(awk -F, 'NR > 1 {print $1}' "$dir/angular.csv" | awk '!seen[$0]++' | grep -E '^[A-Za-z0-9_.+-]+$')
  for m in "${all_methods[@]}"; do
    for s in S1 S2; do
      # columns: signed theta, radiance, se; the + half (phi bin 0), a blank line, the - half
      awk -F, -v m="$m" -v s="$s" '
        NR == 1 {for (i = 1; i <= NF; i++) c[$i] = i; next}
        {rows[NR] = $0; if ($c["phi_bin"] + 0 > np) np = $c["phi_bin"] + 0}
        END {for (r in rows) { split(rows[r], f, ",");
               if (f[c["method"]] != m || f[c["surface"]] != s) continue;
               se = ("se" in c) ? f[c["se"]] : 0
               if (f[c["phi_bin"]] == 0) print 1, f[c["theta_deg"]], f[c["radiance"]], se;
               else if (f[c["phi_bin"]] == np) print 0, -f[c["theta_deg"]], f[c["radiance"]], se }}' \
        "$dir/angular.csv" | sort -k1,1 -k2,2g \
        | awk '{if (NR > 1 && $1 != h) print ""; h = $1; print $2, $3, $4}' > "$tmp/ang_${m//+/_}_$s.dat"
    done
  done
  ang_plot() { # $1 surface, $2: cartesian or polar
    local s=$1 cmd="" m
    for m in "${all_methods[@]}"; do
      f="TMP.'/ang_${m//+/_}_$s.dat'"
      if [ "$2" = cartesian ] && [ "$m" = "$ref" ]; then
        cmd+="$f using 1:2:3 with yerrorbars pt 7 ps 0.5 lc rgb mcolor('$m') title '$m +- 1 s.e.', "
        cmd+="$f using 1:2 with lines lc rgb mcolor('$m') notitle, "
      elif [ "$2" = cartesian ]; then
        cmd+="$f using 1:2 with linespoints pt mpoint('$m') ps 0.5 lc rgb mcolor('$m') title '$m', "
      else
        cmd+="$f using 1:2 with linespoints pt mpoint('$m') ps 0.5 lc rgb mcolor('$m') title '$m', "
      fi
    done
    echo "plot ${cmd%, }"
  }
  {
    echo "set multiplot layout 1,2 title NAME.': in-plane exit radiance at x = 0 (1/sr per unit irradiance); + half: phi bin 0 (along t), - half: the last phi bin'"
    echo "set grid; set xlabel 'signed theta from the normal (deg; + along t, - against t)'"
    echo "set ylabel 'radiance'; set xrange [-90:90]; set key outside right top vertical"
    echo "set title 'S1 (t = +x); red dotted line: mirror direction of the light ($theta_l deg)'"
    echo "set arrow 1 from $theta_l, graph 0 to $theta_l, graph 1 nohead dt 3 lc rgb 'red'"
    ang_plot S1 cartesian
    echo "set title 'S2 (t = -x); red dotted line: the beam direction continued'"
    echo "set arrow 1 from -$theta_l, graph 0 to -$theta_l, graph 1 nohead dt 3 lc rgb 'red'"
    ang_plot S2 cartesian
    echo "unset multiplot"
  } > "$tmp/body.gp"
  render "$dir/plots/angular_x0" 1200 460
  # Polar (paper Fig. 5): radius = radiance, angle = signed theta from the surface normal (up).
  rmax=$(awk -F, 'NR > 1 && ($2 == "S1" || $2 == "S2") && $7 > m {m = $7} END {print (m > 0 ? 1.1 * m : 1)}' "$dir/angular.csv")
  {
    echo "set multiplot layout 1,2 title NAME.': in-plane exit radiance at x = 0, polar (radius: radiance, 1/sr per unit irradiance; angle: theta from the normal, + along t)'"
    echo "set polar; set angles degrees; set theta top clockwise; set grid polar 15"
    echo "set rrange [0:$rmax]; set xrange [-$rmax:$rmax]; set yrange [0:$rmax]; set size ratio -1"
    echo "unset border; unset xtics; unset ytics; set rtics; set ttics -75, 15, 75"
    echo "set key outside below center horizontal"
    echo "set title 'S1 (t = +x); red dotted: mirror direction of the light'"
    echo "set arrow 1 from 0,0 to $rmax * sin($theta_l), $rmax * cos($theta_l) nohead dt 3 lc rgb 'red'"
    ang_plot S1 polar
    echo "set title 'S2 (t = -x); red dotted: the beam direction continued'"
    echo "set arrow 1 from 0,0 to -$rmax * sin($theta_l), $rmax * cos($theta_l) nohead dt 3 lc rgb 'red'"
    ang_plot S2 polar
    echo "unset multiplot"
  } > "$tmp/body.gp"
  render "$dir/plots/angular_x0_polar" 1200 520
fi

# ---- images: all (labelled) and error figures (titled, numbered colour bar) ----
img=$dir/images
if [ -d "$img" ] && has_rows "$dir/angular.csv"; then
  mapfile -t all_methods < <(awk -F, 'NR > 1 {print $1}' "$dir/angular.csv" | awk '!seen[$0]++' | grep -E '^[A-Za-z0-9_.+-]+$')
  present=()
  for m in "${all_methods[@]}"; do [ -s "$img/$m.png" ] && present+=("$m"); done
  n=${#present[@]}
  if [ "$n" -gt 0 ]; then
    cols=$((n < 7 ? n : 7)) rows=$(((n + 6) / 7))
    page_h=$((73 + rows * 392 + 95))
    {
      echo "set multiplot title NAME.\": every method's picture\\ntop: S1, S3 from above; bottom: S2, S3 from below\\nyellow arrow: the light (theta_L = $theta_l deg); brown: the cut; grey: the bar below\""
      echo "unset border; unset tics; unset key; set size ratio -1; set margins 0.5, 0.5, 0.5, 2"
      # the pictures in rows of at most 7 above the colour bar: a page of a title band (73 px),
      # rows of 392 px and the bar's band (95 px), so that a picture keeps its size however
      # many methods ran (14 in one row were too small to read)
      i=0
      for m in "${present[@]}"; do
        echo "set origin $(awk -v i=$i -v c="$cols" -v r="$rows" -v h="$page_h" 'BEGIN {print (i % c) / c, (95 + (r - 1 - int(i / c)) * 392) / h}' | tr ' ' ,); set size $(awk -v c="$cols" -v h="$page_h" 'BEGIN {print 1 / c ", " 392 / h}')"
        echo "set title '$m' font ',14'"
        echo "plot DIR.'/images/$m.png' binary filetype=png with rgbimage"
        i=$((i + 1))
      done
      # The colour bar of the pictures' grey levels: the tone curve of src/io/images.c (x =
      # L / L_white, the identity to 0.75, the shoulder above, sRGB-encoded), so a grey in a
      # picture reads off as a radiance relative to its view's L_white.
      echo "set origin 0, 0; set size 1, $(awk -v h="$page_h" 'BEGIN {print 95 / h}'); set size noratio; unset title"
      echo "sh(x) = x <= 0.75 ? x : 0.75 + 0.25 * (1 - exp(-(x - 0.75) / 0.25))"
      echo "enc(v) = v <= 0.0031308 ? 12.92 * v : 1.055 * v ** (1 / 2.4) - 0.055"
      echo "set palette functions enc(sh(2 * gray)), enc(sh(2 * gray)), enc(sh(2 * gray))"
      echo "set cbrange [0:2]; set cbtics ('0' 0, '0.25' 0.25, '0.5' 0.5, '0.75' 0.75, '1' 1, '1.5' 1.5, '2' 2) out nomirror"
      echo "set colorbox horizontal user origin screen 0.1, screen $(awk -v h="$page_h" 'BEGIN {print 56 / h}') size screen 0.8, screen $(awk -v h="$page_h" 'BEGIN {print 17 / h}')"
      echo "set cblabel 'radiance / L_white (the Monte Carlo 99th percentile of the view); linear to 0.75, a shoulder above' offset 0, 0.4"
      echo "set xrange [0:1]; set yrange [0:1]"
      echo "plot '+' using (NaN):(NaN):(0) with points lc palette notitle"
      echo "unset multiplot"
    } > "$tmp/body.gp"
    render "$img/all" $((cols * 250 + 20)) "$page_h"
  fi
  for m in "${present[@]}"; do
    [ -s "$img/errmap_$m.png" ] || continue
    {
      echo "set title NAME.\": $m vs $ref\\nrelative error (L_$m - L_$ref) / L_$ref\\ntop: S1, S3 from above; bottom: S2, S3 from below\\nblack: no reference; brown: the cut\""
      echo "unset border; unset tics; unset key; set size ratio -1"
      echo "@coolwarm"
      echo "set cbrange [-50:50]; set cbtics ('-50%%' -50, '-25%%' -25, '0' 0, '+25%%' 25, '+50%%' 50)"
      echo "set colorbox vertical user origin screen 0.74, screen 0.12 size screen 0.04, screen 0.62"
      echo "set lmargin at screen 0.04; set rmargin at screen 0.70; set tmargin at screen 0.82; set bmargin at screen 0.02"
      echo "set cblabel 'relative error, clamped at +-50%' offset 1.5, 0"
      # the map alone: errmap's strip at the right carries its own bar (src/io/images.c), drawn
      # here by gnuplot instead; the map is the size of $m.png (its IHDR: width, height)
      read -r wm hm < <(od -An -tu1 -j16 -N8 "$img/$m.png" | awk '{print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4, $5 * 16777216 + $6 * 65536 + $7 * 256 + $8}')
      echo "set xrange [-0.5:$wm - 0.5]; set yrange [-0.5:$hm - 0.5]"
      echo "plot DIR.'/images/errmap_$m.png' binary filetype=png with rgbimage, '+' using (NaN):(NaN):(0) with points lc palette"
    } > "$tmp/body.gp"
    render "$img/error_$m" 560 640
  done
fi

# ---- a colour set: every method's colour picture over its luminance error map ----
if [ -d "$dir/y/images" ] && has_rows "$dir/timings.csv"; then
  mapfile -t all_methods < <(awk -F, '$1 == "y" {print $2}' "$dir/timings.csv" | awk '!seen[$0]++' | grep -E '^[A-Za-z0-9_.+-]+$')
  present=()
  [ -n "$ref" ] && [ -s "$img/$ref.png" ] && present+=("$ref")
  for m in "${all_methods[@]}"; do
    [ "$m" != "$ref" ] && [ -s "$img/$m.png" ] && [ -s "$dir/y/images/errmap_$m.png" ] && present+=("$m")
  done
  n=${#present[@]}
  if [ "$n" -gt 1 ]; then
    {
      echo "set multiplot title NAME.\": every method's colour picture (sRGB; top: S1, S3 from above, bottom: S2, S3 from below)\\nover its luminance error against $ref, (Y_m - Y_$ref) / Y_$ref: blue -50% .. grey 0 .. red +50%\""
      echo "unset border; unset tics; unset key; set size ratio -1; set margins 0.5, 0.5, 0.5, 2"
      i=0
      for m in "${present[@]}"; do
        x=$(awk -v i=$i -v n="$n" 'BEGIN {print i / n}')
        wd=$(awk -v n="$n" 'BEGIN {print 1 / n}')
        echo "set origin $x, 0.46; set size $wd, 0.46"
        echo "set title '$m' font ',14'"
        echo "plot DIR.'/images/$m.png' binary filetype=png with rgbimage"
        if [ "$m" != "$ref" ]; then
          # the map alone (errmap's strip at the right holds its own bar, cut off here)
          read -r wm hm < <(od -An -tu1 -j16 -N8 "$img/$m.png" | awk '{print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4, $5 * 16777216 + $6 * 65536 + $7 * 256 + $8}')
          echo "set origin $x, 0.0; set size $wd, 0.46"
          echo "set title '$m vs $ref (Y)' font ',11'"
          echo "set xrange [-0.5:$wm - 0.5]; set yrange [-0.5:$hm - 0.5]"
          echo "plot DIR.'/y/images/errmap_$m.png' binary filetype=png with rgbimage"
          echo "set autoscale xy"
        fi
        i=$((i + 1))
      done
      echo "unset multiplot"
    } > "$tmp/body.gp"
    render "$img/colour" $((n * 200 + 20)) 700
  fi
fi

