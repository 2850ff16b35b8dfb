#!/usr/bin/env bash
# test_chi2_radiance.sh: scripts/chi2_radiance.awk on radiance.csv files built here, whose
# chi-square, z, relative RMS and largest bin difference are worked out by hand below (the
# definitions in the script's header): a wrong sum, weight or normalisation fails a line.
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/test_chi2.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail=0
# Reference A: S1 bins 1.0 +- 0.1 and 2.0 +- 0.2, S2 one bin 1.0 +- 0.5. Method B: 1.1, 1.8, 2.0.
cat > "$tmp/a.csv" <<'CSV'
method,surface,segment,s,theta_bin,phi_bin,radiance,stderr
A,S1,0,0,0,0,1.0,0.1
A,S1,0,0,0,1,2.0,0.2
A,S2,0,0,0,0,1.0,0.5
B,S1,0,0,0,0,1.1,0
B,S1,0,0,0,1,1.8,0
B,S2,0,0,0,0,2.0,0
CSV
# S1: chi2 = (0.1/0.1)^2 + (0.2/0.2)^2 = 2 over 2 bins, z = 0, rel = sqrt(0.05 / 5) = 0.1,
# max 0.1. S2: chi2 = (1/0.5)^2 = 4 over 1, z = 3/sqrt(2) = 2.12, rel 1, max 1. All: chi2 6
# over 3, z = 3/sqrt(6) = 1.22, rel = sqrt(1.05 / 6) = 0.418, max 1.
expect() { # file... -- surface bins chi2 z rel max (printed precision)
  local out; out=$(awk -v m=B -v ref=A -f "$here/scripts/chi2_radiance.awk" "$@" 2>&1)
  echo "$out"
  printf '%s\n' "$out" > "$tmp/out"
}
expect "$tmp/a.csv"
check() {
  local got; got=$(awk -v s="$1" '$1 == s {print $2, $3, $4, $5, $6}' "$tmp/out")
  if [ "$got" != "$2" ]; then echo "FAIL: $1: got '$got', expected '$2'"; fail=1; fi
}
check S1 "2 2.0 0.00 0.1 0.1"
check S2 "1 4.0 2.12 1 1"
check all "3 6.0 1.22 0.418 1"
# Two files: B of the first against B of the second (here A's values relabelled B): no chi2
# (both deterministic), rel and max as above.
sed -e '/^B,/d' -e 's/^A,/B,/' "$tmp/a.csv" > "$tmp/b.csv"
sed -e 's/,0\.[125]$/,0/' "$tmp/b.csv" > "$tmp/b0.csv"
out=$(awk -v m=B -v ref=B -f "$here/scripts/chi2_radiance.awk" "$tmp/a.csv" "$tmp/b0.csv")
echo "$out"
printf '%s\n' "$out" > "$tmp/out"
check S1 "- - - 0.1 0.1"
check all "- - - 0.418 1"
# Missing ids: exit 2.
awk -f "$here/scripts/chi2_radiance.awk" "$tmp/a.csv" >/dev/null 2>&1
[ $? -eq 2 ] || { echo "FAIL: no ids: not exit 2"; fail=1; }
# scripts/surface_totals.awk: R 0.50 +- 0.01 against B's 0.53 (z 3), T 0.2 +- 0.002 against 0.199 (z
# -0.5), sides with no standard error ("-"); mc1's rows and other methods' rows are ignored.
cat > "$tmp/mc_totals.csv" <<'CSV'
tally,total,mean,se
mc,R,0.50,0.01
mc,T,0.2,0.002
mc,sides,0.1,0
mc1,R,0.9,0.0001
CSV
cat > "$tmp/totals.csv" <<'CSV'
method,R,T,sides,absorbed,ballistic,specular
mc,0.50,0.2,0.1,0.1,0.1,0
B,0.53,0.199,0.3,0,0,0
CSV
got=$(awk -v m=B -f "$here/scripts/surface_totals.awk" "$tmp/mc_totals.csv" "$tmp/totals.csv")
[ "$got" = "3,-0.5,-" ] || { echo "FAIL: surface_totals: got '$got', expected '3,-0.5,-'"; fail=1; }
# rel=1: (0.53 - 0.5) / 0.5 = 6 %, (0.199 - 0.2) / 0.2 = -0.5 %, (0.3 - 0.1) / 0.1 = 200 %.
got=$(awk -v m=B -v rel=1 -f "$here/scripts/surface_totals.awk" "$tmp/mc_totals.csv" "$tmp/totals.csv")
[ "$got" = "6,-0.5,200" ] || { echo "FAIL: surface_totals rel=1: got '$got', expected '6,-0.5,200'"; fail=1; }
# scripts/surface_totals.awk: B's radiance summed per surface against mc's: S1 (1.1 + 1.8 - 3) / 3 =
# -3.33 %, S2 (2 - 1) / 1 = 100 %, sides (0.6 + 0.5 - 1) / 1 = 10 %; A's rows ignored.
cat > "$tmp/r.csv" <<'CSV'
method,surface,segment,s,theta_bin,phi_bin,radiance,stderr
mc,S1,0,0,0,0,1.0,0.1
mc,S1,0,0,0,1,2.0,0.2
mc,S2,0,0,0,0,1.0,0.5
mc,S3,0,0,0,0,0.5,0.1
mc,S4,0,0,0,0,0.5,0.1
A,S1,0,0,0,0,9,0
B,S1,0,0,0,0,1.1,0
B,S1,0,0,0,1,1.8,0
B,S2,0,0,0,0,2.0,0
B,S3,0,0,0,0,0.6,0
B,S4,0,0,0,0,0.5,0
CSV
got=$(awk -v m=B -v bins=1 -f "$here/scripts/surface_totals.awk" "$tmp/r.csv")
[ "$got" = "-3.33,100,10" ] || { echo "FAIL: surface_totals bins=1: got '$got', expected '-3.33,100,10'"; fail=1; }
awk -v m=C -f "$here/scripts/surface_totals.awk" "$tmp/mc_totals.csv" "$tmp/totals.csv" >/dev/null 2>&1
[ $? -eq 2 ] || { echo "FAIL: surface_totals: a method without a row: not exit 2"; fail=1; }
[ $fail -eq 0 ] && echo "test_chi2_radiance: ok"
exit $fail
