#!/usr/bin/env bash
# bench.sh [--quick] [--out DIR] [--set SEC.KEY=VAL ...]: the accuracy study (docs/reference.md,
# Cases): every case of configs/study.list with every method, its plots, Table 2, the summary
# figure (scripts/summary_plot.sh: summary.png) and the study README. Full runs write results/ (committed); --quick writes build/bench-quick/ with a
# small photon budget, for a look in about a minute.
set -euo pipefail
cd "$(dirname "$0")/.."
out=results
sets=()
quick=0
while [ $# -gt 0 ]; do
  case $1 in
    --quick) out=build/bench-quick quick=1
             sets+=(--set mc.photons=2e6 --set pp.directions=128 --set bins.samples_dir=2
                   --set rte2d.spacing=0.25 --set rte2d.directions=48) ;;
    --out) out=$2; shift ;;
    --set) sets+=(--set "$2"); shift ;;
    *) echo "bench.sh: unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done
mapfile -t cases < configs/study.list
# The Monte Carlo references are kept by fingerprint (docs/external.md): a second
# bench that only adds a method traces no photon. PPB_REF_CACHE moves it.
cache=${PPB_REF_CACHE:-build/ref-cache}
mkdir -p "$out"
# The whole study's ETA weighs the cases by their cost in the previous study in $out (its
# timings.csv: every result's seconds, a companion result counting its method's again (a
# weight, not a time), plus 5 s of writing and figures), read before this run overwrites them:
# the n = 1.4 cases cost about twice the others. Cases without a previous timing weigh as the mean of those with one (1 if none).
weights=() known=0 nknown=0
for c in "${cases[@]}"; do
  w=$(awk -F, 'NR > 1 {s += $2} END {if (NR > 1) printf "%d", s + 5}' \
      "$out/$c/timings.csv" 2> /dev/null || true)
  weights+=("${w:-0}")
  [ -n "$w" ] && known=$((known + w)) nknown=$((nknown + 1))
done
mean=$(( nknown > 0 ? known / nknown : 1 ))
for i in "${!weights[@]}"; do [ "${weights[$i]}" -gt 0 ] || weights[$i]=$mean; done
t0=$(date +%s) done_w=0 total_w=0
for w in "${weights[@]}"; do total_w=$((total_w + w)); done
for i in "${!cases[@]}"; do
  c=${cases[$i]}
  # ETA: the time so far scaled by the weight left over the weight done.
  el=$(( $(date +%s) - t0 )) eta=
  [ "$i" -gt 0 ] && eta=$(printf ', study ETA %ds more' $(( el * (total_w - done_w) / done_w )))
  printf '[%d/%d] %s (%ds elapsed%s)\n' $((i + 1)) ${#cases[@]} "$c" $el "$eta" >&2
  # ppbench run draws the case's figures itself (scripts/plots.sh, theta_L from provenance).
  PPB_BENCH_STUDY=1 ./ppbench run "${sets[@]}" --ref-cache "$cache" --out "$out/$c" "configs/$c.ini"
  done_w=$((done_w + weights[i]))
done
# The quick study's README says what it is: ppbench report copies notes.md into it (and states
# the photon budget itself, from the cases' provenance.txt).
if [ $quick = 1 ]; then
  settings=$(printf '%s ' "${sets[@]}" | sed 's/--set //g; s/ $//; s/ /, /g')
  cat > "$out/notes.md" <<EOF

## The quick study

This is the quick study (\`QUICK=1 make bench\`, \`scripts/bench.sh --quick\`), a look in a few
minutes, run with $settings instead of the configs' own settings. Its noise floor (above) is
far higher than that of the full study in results/ (\`make bench\`): its numbers are not the
study's.
EOF
fi
# The study README opens with the summary figure (the excess RMS at the Table 2 cells per case
# and method, beside the noise floor), drawn from the cases' summary.csv before the report.
bash scripts/summary_plot.sh "$out" "${cases[@]}"
./ppbench report "$out" "${cases[@]}"
# The materials study (scripts/materials_study.sh; docs/reference.md: Colour): the colour cases
# of configs/materials.list into $out/materials, with their own report.
[ $quick = 1 ] && mkdir -p "$out/materials" && cp "$out/notes.md" "$out/materials/notes.md"
bash scripts/materials_study.sh --out "$out/materials" --cache "$cache" "${sets[@]}"
# The three-dimensional study (scripts/objects_study.sh; docs/reference.md: Objects): mc3d,
# ss3d and pp3d on configs/objects into $out/objects, its own README (6-9 minutes; the quick
# study's settings apply).
bash scripts/objects_study.sh --out "$out/objects" "${sets[@]}"
printf 'study written to %s/ in %ds: see %s/README.md\n' "$out" $(( $(date +%s) - t0 )) "$out" >&2
# The shipped references (references/<case>/, docs/reference.md: Keys) come from this study's
# cache by `make references` (scripts/references.sh), run after a full bench.
