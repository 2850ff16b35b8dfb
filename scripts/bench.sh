#!/usr/bin/env bash
# bench.sh [--quick] [--out DIR] [--set SEC.KEY=VAL ...]: the accuracy study (docs/reference.md,
# Cases): every case of configs/study.list with every method, its plots, Table 2 and the
# study README. Full runs write results/ (committed); --quick writes build/bench-quick/ with a
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
t0=$(date +%s)
for i in "${!cases[@]}"; do
  c=${cases[$i]}
  # The whole study's ETA: the mean time of the cases done so far times the cases left.
  el=$(( $(date +%s) - t0 )) eta=
  [ "$i" -gt 0 ] && eta=$(printf ', study ETA %ds more' $(( el * (${#cases[@]} - i) / i )))
  printf '[%d/%d] %s (%ds elapsed%s)\n' $((i + 1)) ${#cases[@]} "$c" $el "$eta" >&2
  ./ppbench run "${sets[@]}" --ref-cache "$cache" --out "$out/$c" "configs/$c.ini"
  theta=$(awk -F' *= *' '$1 == "theta_deg" {print $2}' "configs/$c.ini")
  bash scripts/plots.sh "$out/$c" "${theta:-0}"
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
./ppbench report "$out" "${cases[@]}"
printf 'study written to %s/ in %ds: see %s/README.md\n' "$out" $(( $(date +%s) - t0 )) "$out" >&2
