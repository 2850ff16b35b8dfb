#!/usr/bin/env bash
# regress.sh: the regression gate `make test` runs after the unit tests.
# Runs the reduced study (every case of configs/study.list at a small photon budget) and the
# slab checks (tests/regress/*.ini) under build/regress/ -- never over results/ -- then checks
# every line of tests/thresholds.txt and prints each check with its measured value.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${REGRESS_OUT:-build/regress}
photons=${REGRESS_PHOTONS:-3e6}
ppbench=${PPBENCH:-./ppbench}
# No Monte Carlo reference cache (PPBENCH_CACHE empty turns off the default one): the gate
# traces every reference, so a changed Monte Carlo is measured, never answered from an old
# cache.
export PPBENCH_CACHE=
mkdir -p "$out"
t0=$(date +%s)
mapfile -t cases < configs/study.list
for c in "${cases[@]}"; do
  echo "regress: $c ($(( $(date +%s) - t0 ))s)" >&2
  # rte2d (in the study configs) costs 10-40 s a case at its defaults: the gate checks it in
  # its own reduced case, tests/regress/rte2d_tube.ini, and runs the study without it.
  "$ppbench" run --quiet --set mc.photons="$photons" --set experiment.methods=mc,pp,ss,mp,mp+ss \
    --out "$out/$c" "configs/$c.ini"
done
for f in tests/regress/*.ini; do
  c=$(basename "$f" .ini)
  echo "regress: $c ($(( $(date +%s) - t0 ))s)" >&2
  "$ppbench" run --quiet --out "$out/$c" "$f"
done

# value CASE FILE METHOD CELL COLUMN: one number from a case's CSV, as ppbench wrote it (every
# metric is computed by src/model/metrics.c, the one owner of the Metrics of docs/reference.md;
# nothing is re-derived here).
#   FILE summary*.csv: the row (METHOD, CELL), COLUMN by name.
#   FILE regions.csv:  the row (METHOD, REGION), e.g. "S1:x>x0+2" (model/metrics.h lists them).
#   FILE totals.csv:   COLUMN by name, or "balance" = |R + T + sides + absorbed + ballistic +
#                      specular - 1| (specular, the beam's reflection at entry, is 0 at n = 1).
value() {
  local case=$1 file=$2 method=$3 cell=$4 col=$5
  local dir="$out/$case"
  case $file in
    summary*.csv|regions.csv)
      awk -F, -v m="$method" -v c="$cell" -v col="$col" '
        NR == 1 {for (i = 1; i <= NF; i++) idx[$i] = i; next}
        $1 == m && $2 == c {print $(idx[col]); found = 1}
        END {if (!found) print "missing"}' "$dir/$file" ;;
    totals.csv)
      awk -F, -v m="$method" -v col="$col" '
        NR == 1 {for (i = 1; i <= NF; i++) idx[$i] = i; next}
        $1 == m {sum = $2 + $3 + $4 + $5 + $6 + $(idx["specular"]) - 1
                 v = (col == "balance") ? sum : $(idx[col]);
                 if (v < 0 && col == "balance") v = -v; print v; found = 1}
        END {if (!found) print "missing"}' "$dir/$file" ;;
    *) echo "missing" ;;
  esac
}

fail=0 n=0
while read -r case file method cell col op limit rest; do
  [[ -z "$case" || "$case" == \#* ]] && continue
  v=$(value "$case" "$file" "$method" "$cell" "$col")
  lim=$limit
  # A method id as the limit compares against that method's value in the same cell.
  if ! [[ "$limit" =~ ^[0-9.eE+-]+$ ]]; then lim=$(value "$case" "$file" "$limit" "$cell" "$col"); fi
  ok=$(awk -v v="$v" -v l="$lim" -v op="$op" 'BEGIN {
    if (v == "missing" || l == "missing" || v != v + 0) {print 0; exit}
    print (op == "<" ? v < l : v > l) }')
  n=$((n + 1))
  if [ "$ok" = 1 ]; then status=ok; else status=FAIL; fail=1; fi
  shown=$limit; [ "$lim" = "$limit" ] || shown="$limit ($lim)"
  printf '%-4s %-20s %-18s %-6s %-10s %-10s = %-12s %s %s\n' "$status" "$case" "$file" \
    "$method" "$cell" "$col" "$v" "$op" "$shown"
done < tests/thresholds.txt
echo "regress: $n checks, $([ $fail = 0 ] && echo all passed || echo FAILURES) in $(( $(date +%s) - t0 ))s"
exit $fail
