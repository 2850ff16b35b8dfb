#!/usr/bin/env bash
# searchlight_study.sh [OUT_DIR]: the line-searchlight validation of the profile models
# (reference: Outputs, results/searchlight), the figure the models' papers show (Christensen &
# Burley 2015 Fig. 3-5, d'Eon 2012, Habel et al. 2013): S1's exitance against the distance from a
# lit line, per albedo, each model beside the Monte Carlo.
#
# Per albedo in ALBEDOS: a line searchlight ([light] lit = strip, width = 0, x0 = 0) at normal
# incidence, g = 0, n = 1, on a tube semi-infinite near the line: width 2 D and height D with
# D = max(10, ceil(10 / sigma_tr)) mfp, sigma_tr = sqrt(3 (1 - albedo)) (the diffusion length
# 1 / sigma_tr; the profile falls by e^-10 over D), S1 at SEG mfp a segment (the segment count
# capped at tube.segments_top's limit 4096: the width then shrinks to 4096 SEG, said in
# provenance.txt), one direction bin (bins.theta = bins.phi = 1: a segment's radiance is its
# exitance / pi exactly). Methods: mc, burley, bdipole, dirpole, pbd on the line; mp refuses a
# line, so it runs on a strip of width MP_W = 0.01 mfp and its radiance is divided by MP_W (the
# line is that limit, reference: Light; mp's profile is smooth on the scale of its sources'
# depth, 1 mfp, so the centred strip differs from the line by about MP_W^2 / 24 relative).
# S1 is folded about the line (the two sides averaged; the Monte Carlo's standard errors
# combined as independent). Writes OUT_DIR (default results/searchlight):
#   profile_a<ALBEDO>.csv  distance (segment centre, mfp), seg_lo, seg_hi, then the exitance per
#                          unit line strength (pi x radiance) of mc, mc_se, burley, bdipole,
#                          dirpole, pbd, mp
#   rms.csv                per albedo and model: RMS of model / mc - 1 over 0.1 <= d <= 10 mfp
#                          (rms), the Monte Carlo's own relative noise there (noise), and
#                          sqrt(max(rms^2 - noise^2, 0)) (excess), in %; totals: R of each
#   burley_fit.csv         Burley's s refitted to each Monte Carlo profile (build/burley_fit:
#                          scripts/burley_fit.c) beside Eq. 5's 1.85 - A + 7 |A - 0.8|^3
#   searchlight.png        the figure (scripts/searchlight_plot.gp, plot_style.gp's colours):
#                          log exitance per albedo, and Burley's s refit beside Eq. 5
#   searchlight_ratio.png  the same profiles as model / mc, the Monte Carlo's 1 s.e. about 1
#   provenance.txt         ppbench version, the runs' commands, sizes, photons and timings
# PHOTONS (default 4e7; 2e7 at albedo 0.999, whose photons live longest) sets the Monte Carlo's
# budget. Measured on the 2-core machine: 114 s wall, 103 s user CPU in all (the Monte Carlo
# 91 s of it, 46 s at albedo 0.999 on its 366 x 183 tube).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
out=${1:-$root/results/searchlight}
ALBEDOS=${ALBEDOS:-"0.5 0.8 0.95 0.99 0.999"}
SEG=0.1
MP_W=0.01
DMIN=0.1
DMAX=10
ppb=$root/ppbench
(cd "$root" && make -s ppbench build/burley_fit > /dev/null)
tmp=$(mktemp -d 2> /dev/null || mktemp -d -p /tmp)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"
export PPBENCH_CACHE= # every Monte Carlo traced here, none read from or stored in a cache

photons_for() { [ "$1" = 0.999 ] && echo "${PHOTONS:-2e7}" || echo "${PHOTONS:-4e7}"; }

# size ALBEDO: "D WIDTH SEGMENTS" (see above).
size() {
  awk -v a="$1" -v seg="$SEG" 'BEGIN {
    d = 10 / sqrt(3 * (1 - a)); d = d == int(d) ? d : int(d) + 1; if (d < 10) d = 10
    w = 2 * d; n = int(w / seg + 0.5); if (n > 4096) { n = 4096; w = n * seg }
    print d, w, n }'
}

# fold RADIANCE_CSV METHOD SCALE: "seg_index distance lo hi value se" for S1's segments right of
# the line (x > 0), each averaged with its mirror image, times SCALE (pi; pi / MP_W for mp).
fold() {
  awk -F, -v m="$2" -v k="$3" -v seg="$SEG" '
    $1 == m && $2 == "S1" { s[$3] = $4; v[$3] = $7; e[$3] = $8; n = $3 + 1 }
    END { for (i = n / 2; i < n; i++) { j = n - 1 - i
            printf "%d %.4f %.4f %.4f %.10g %.10g\n", i - n / 2, s[i], s[i] - seg / 2,
              s[i] + seg / 2, k * (v[i] + v[j]) / 2, k * sqrt(e[i] ^ 2 + e[j] ^ 2) / 2 } }' "$1"
}

prov=$out/provenance.txt
{
  echo "ppbench.version = $("$ppb" --version 2> /dev/null | head -1)"
  echo "script = scripts/searchlight_study.sh"
  echo "date = $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "light = line (width 0) at x0 = 0, normal incidence; g = 0, n = 1; mp on a strip of width $MP_W divided by it"
  echo "segment = $SEG mfp; bins = 1 x 1; rms window = $DMIN .. $DMAX mfp"
} > "$prov"
echo "albedo,method,rms,noise,excess,R" > "$out/rms.csv"
echo "albedo,A_mc,A_pp,s_fit,s_fit_pp,s_eq5,s_eq5_pp,fit_rms,eq5_rms" > "$out/burley_fit.csv"

for a in $ALBEDOS; do
  read -r d w n <<< "$(size "$a")"
  ph=$(photons_for "$a")
  common=(--set medium.albedo="$a" --set medium.g=0 --set medium.n=1 --set light.theta_deg=0
    --set light.x0=0 --set tube.width="$w" --set tube.height="$d" --set tube.segments_top="$n"
    --set tube.segments_side=50 --set bins.theta=1 --set bins.phi=1 --quiet)
  t0=$(date +%s.%N)
  "$ppb" run "$root/configs/searchlight_line.ini" "${common[@]}" --set light.width=0 \
    --set experiment.methods=mc,burley,bdipole,dirpole,pbd --set mc.photons="$ph" \
    --out "$tmp/line_$a" > /dev/null
  "$ppb" run "$root/configs/searchlight_line.ini" "${common[@]}" --set light.width="$MP_W" \
    --set experiment.methods=mp --out "$tmp/mp_$a" > /dev/null
  t1=$(date +%s.%N)
  echo "albedo $a: tube $w x $d mfp, $n segments on S1, mc.photons $ph, $(awk -v a="$t0" -v b="$t1" \
    'BEGIN {printf "%.1f", b - a}') s (mc $(awk -F, '$1 == m {print $2}' m=mc "$tmp/line_$a/timings.csv") s)" \
    | tee -a "$prov" >&2
  pi=3.14159265358979
  for m in mc burley bdipole dirpole pbd; do fold "$tmp/line_$a/radiance.csv" "$m" "$pi" > "$tmp/$m"; done
  fold "$tmp/mp_$a/radiance.csv" mp "$(awk -v p=$pi -v w=$MP_W 'BEGIN {print p / w}')" > "$tmp/mp"
  prof=$out/profile_a$a.csv
  {
    echo "distance,seg_lo,seg_hi,mc,mc_se,burley,bdipole,dirpole,pbd,mp"
    paste -d' ' "$tmp/mc" "$tmp/burley" "$tmp/bdipole" "$tmp/dirpole" "$tmp/pbd" "$tmp/mp" |
      awk '{printf "%s,%s,%s,%s,%s,%s,%s,%s,%s,%s\n", $2, $3, $4, $5, $6, $11, $17, $23, $29, $35}'
  } > "$prof"
  # RMS per model over the window; the totals' R from each run (mp's the strip's).
  for m in burley bdipole dirpole pbd mp; do
    col=$(head -1 "$prof" | tr , '\n' | grep -nx "$m" | cut -d: -f1)
    R=$(awk -F, -v m="$m" '$1 == m {print $2}' "$tmp/line_$a/totals.csv" "$tmp/mp_$a/totals.csv")
    awk -F, -v c="$col" -v lo=$DMIN -v hi=$DMAX -v a="$a" -v m="$m" -v R="$R" '
      NR > 1 && $1 >= lo && $1 <= hi && $4 > 0 { r = $c / $4 - 1; s += r * r; q += ($5 / $4) ^ 2; k++ }
      END { rms = sqrt(s / k); noise = sqrt(q / k); ex = rms ^ 2 - noise ^ 2
            printf "%s,%s,%.3f,%.3f,%.3f,%s\n", a, m, 100 * rms, 100 * noise,
              100 * sqrt(ex > 0 ? ex : 0), R }' "$prof" >> "$out/rms.csv"
  done
  A_mc=$(awk -F, '$1 == m {printf "%.6f", $2}' m=mc "$tmp/line_$a/totals.csv")
  echo "$a,mc,0,0,0,$A_mc" >> "$out/rms.csv"
  IFS=, read -r s_fit fit_rms A_pp <<< "$("$root/build/burley_fit" "$prof" "$A_mc" "$a" $DMIN $DMAX)"
  IFS=, read -r s_fit_pp _ _ <<< "$("$root/build/burley_fit" "$prof" "$A_pp" "$a" $DMIN $DMAX)"
  eq5() { awk -v x="$1" 'BEGIN { printf "%.6f", 1.85 - x + 7 * (x > 0.8 ? x - 0.8 : 0.8 - x) ^ 3 }'; }
  s5=$(eq5 "$A_mc")
  s5pp=$(eq5 "$A_pp")
  IFS=, read -r _ eq5_rms _ <<< "$("$root/build/burley_fit" "$prof" "$A_mc" "$a" $DMIN $DMAX "$s5")"
  awk -v a="$a" -v A="$A_mc" -v P="$A_pp" -v s="$s_fit" -v sp="$s_fit_pp" -v s5="$s5" \
    -v s5pp="$s5pp" -v fr="$fit_rms" -v er="$eq5_rms" \
    'BEGIN { printf "%s,%s,%s,%s,%s,%s,%s,%.3f,%.3f\n", a, A, P, s, sp, s5, s5pp, 100 * fr, 100 * er }' \
    >> "$out/burley_fit.csv"
done

# The figure: one panel per albedo, log exitance against the distance from the line; the last
# panel Burley's s refit beside Eq. 5.
gnuplot -e "DIR='$out'; ALBEDOS='$ALBEDOS'; DMAX=$DMAX" -e "load '$here/plot_style.gp'" \
  "$here/searchlight_plot.gp"
echo "searchlight_study: wrote $out" >&2
