#!/usr/bin/env bash
# test_study_loop.sh: the researcher's loop (docs/external.md, "Scoring on the whole study";
# docs/reference.md, "The reference cache", Outputs). On a tiny tube (8 + 3 segments, 2 x 2 bins,
# 2e4 photons, as tests/test_external.c's tiny), each expectation from the rule it checks:
#  1. shipped references (named by mc.shipped_key, the cache's key without the device): a run
#     with an empty user cache is served from the shipped layer
#     (scripts/references.sh's output) with zero photons traced (provenance.txt has no
#     mc.photons_traced; stderr says "from the shipped reference"); a changed key (another seed)
#     is not served (PPBENCH_MC_NO_TRACE=1: the run fails, exit 1, nothing traced); a file under
#     the right key name holding another reference is refused by its header, never used;
#  2. the committed study: a run whose output is <source>/results/<case> (a case of
#     configs/study.list) is refused (exit 2, "give --out") without bench.sh's marker, and runs
#     with it (PPB_BENCH_STUDY=1); results/<name> of a config not in the study is not guarded;
#  3. score: a radiance.csv that is not the one provenance.txt's radiance.xxh64 records is
#     refused (exit 2);
#  4. external methods: {name} is the section's NAME; surfaces = S1 leaves S2..S4 not computed
#     (no radiance.csv rows, nan in summary.csv and rms.csv), and without the key the same
#     output is refused with "missing row".
# Run with PPBENCH (the binary) set, from the repository root (make test-study-loop).
set -euo pipefail
cd "$(dirname "$0")/.."
ppb=${PPBENCH:-$PWD/ppbench}
t=$(mktemp -d "${TMPDIR:-/tmp}/ppb-loop-XXXXXX")
trap "rm -rf \"$t\"" EXIT
fail() { echo "test_study_loop: FAIL: $*" >&2; exit 1; }
pass() { echo "test_study_loop: ok: $*"; }
cat > "$t/tiny.ini" <<INI
[experiment]
name = tiny
methods = mc
[tube]
segments_top = 8
segments_side = 3
[bins]
theta = 2
phi = 2
[mc]
photons = 20000
INI
unset PPBENCH_MC_NO_TRACE PPB_BENCH_STUDY

# 1. The shipped layer.
"$ppb" run --quiet --ref-cache "$t/cache" --out "$t/gen/tiny" "$t/tiny.ini"
grep -q '^mc.photons_traced = 20000$' "$t/gen/tiny/provenance.txt" || fail "the first run traced"
grep -q "^mc.reference = $t/cache/mc-" "$t/gen/tiny/provenance.txt" || fail "no mc.reference"
# The shipped name is the key without the device (mc.shipped_key), not the cache's.
key=$(sed -n 's/^mc.shipped_key = //p' "$t/gen/tiny/provenance.txt")
[ -n "$key" ] && [ "$key" != "$(basename "$(ls "$t"/cache/mc-*.bin)")" ] || fail "mc.shipped_key: '$key'"
bash scripts/references.sh --from "$t/gen" --out "$t/refs" tiny 2> /dev/null
[ -f "$t/refs/tiny/$key.xz" ] || fail "references.sh did not name the file by mc.shipped_key"
ls "$t"/refs/tiny/mc-*.bin.xz > /dev/null || fail "references.sh wrote no mc-<key>.bin.xz"
grep -q '^mc.photons = 20000$' "$t/refs/tiny/provenance.txt" || fail "shipped provenance"
export PPBENCH_REFERENCES=$t/refs
PPBENCH_MC_NO_TRACE=1 "$ppb" run --ref-cache "$t/empty" --out "$t/a" "$t/tiny.ini" 2> "$t/a.err" \
  || fail "not served from the shipped layer: $(cat "$t/a.err")"
grep -q 'mc: 20000 photons from the shipped reference .*, 0 traced' "$t/a.err" || fail "no message"
! grep -q photons_traced "$t/a/provenance.txt" || fail "photons traced with a shipped reference"
grep -q "^mc.reference = $t/refs/tiny/mc-" "$t/a/provenance.txt" || fail "mc.reference"
[ ! -e "$t/empty" ] || [ -z "$(ls "$t/empty")" ] || fail "the shipped layer was copied to the cache"
cmp <(grep '^mc,' "$t/gen/tiny/radiance.csv") <(grep '^mc,' "$t/a/radiance.csv") \
  || fail "the shipped reference is not the traced one"
pass "served from the shipped layer, 0 photons traced"
rc=0
PPBENCH_MC_NO_TRACE=1 "$ppb" run --quiet --set mc.seed=2 --ref-cache "$t/empty" --out "$t/b" \
  "$t/tiny.ini" 2> "$t/b.err" || rc=$?
[ $rc = 1 ] && grep -q 'no reference for this config' "$t/b.err" || fail "another seed served (rc $rc)"
pass "a changed key is not served"
# Another reference (seed 2) under the seed-1 key's name: its header is checked, not trusted.
"$ppb" run --quiet --set mc.seed=2 --ref-cache "$t/cache2" --out "$t/c" "$t/tiny.ini"
shipped=$(ls "$t"/refs/tiny/mc-*.bin.xz)
xz -c "$t"/cache2/mc-*.bin > "$shipped"
rc=0
PPBENCH_MC_NO_TRACE=1 "$ppb" run --quiet --ref-cache "$t/empty" --out "$t/d" "$t/tiny.ini" \
  2> "$t/d.err" || rc=$?
[ $rc = 1 ] && grep -q 'holds another reference: not used' "$t/d.err" || fail "a wrong file used (rc $rc)"
pass "a file of another reference under the key's name is not used"
xz -c "$t"/cache2/mc-*.bin | head -c 300 > "$shipped" # a truncated file
rc=0
PPBENCH_MC_NO_TRACE=1 "$ppb" run --quiet --ref-cache "$t/empty" --out "$t/e" "$t/tiny.ini" \
  2> "$t/e.err" || rc=$?
[ $rc = 1 ] && grep -q 'cannot be decompressed: not used' "$t/e.err" || fail "a damaged file used (rc $rc)"
pass "a damaged shipped file is not used"
unset PPBENCH_REFERENCES

# 2. The committed study: a source tree of our own (PPBENCH_SOURCE) with results/tiny.
src=$t/src
mkdir -p "$src/results/tiny" "$src/configs"
echo tiny > "$src/configs/study.list"
ln -s "$PWD/kernels" "$src/kernels"
ln -s "$PWD/src" "$src/src"
rc=0
PPBENCH_SOURCE=$src "$ppb" run --quiet --no-ref-cache --out "$src/results/tiny" "$t/tiny.ini" \
  2> "$t/g.err" || rc=$?
[ $rc = 2 ] && grep -q 'give --out' "$t/g.err" || fail "the committed study was written (rc $rc)"
rc=0
(cd "$src" && PPBENCH_SOURCE=$src "$ppb" run --quiet --no-ref-cache --out results/tiny/ \
  "$t/tiny.ini") 2> "$t/g2.err" || rc=$?
[ $rc = 2 ] || fail "a relative results/tiny/ was written (rc $rc)"
[ -z "$(ls "$src/results/tiny")" ] || fail "results/tiny was touched"
PPB_BENCH_STUDY=1 PPBENCH_SOURCE=$src "$ppb" run --quiet --no-ref-cache --out "$src/results/tiny" \
  "$t/tiny.ini" || fail "make bench's marker did not let it write"
PPBENCH_SOURCE=$src "$ppb" run --quiet --no-ref-cache --out "$src/results/other" "$t/tiny.ini" \
  || fail "results/other (not a study case) was refused"
pass "results/<case> is make bench's alone"

# 3. score: a radiance.csv its provenance does not record.
cp -r "$t/gen/tiny" "$t/swapped"
cp "$t/c/radiance.csv" "$t/swapped/radiance.csv" # seed 2's radiance beside seed 1's provenance
awk -F, -v OFS=, 'NR == 1 || $1 == "mc" { if (NR > 1) $1 = "mine"; print }' "$t/a/radiance.csv" \
  > "$t/mine.csv"
rc=0
"$ppb" score --quiet --ref "$t/swapped" --out "$t/s2" "$t/mine.csv" 2> "$t/s2.err" || rc=$?
[ $rc = 2 ] && grep -q 'not the one its provenance.txt records' "$t/s2.err" \
  || fail "a radiance.csv of another run was scored against (rc $rc)"
"$ppb" score --quiet --ref "$t/gen/tiny" --out "$t/s3" "$t/mine.csv" || fail "the set's own refused"
pass "score refuses a radiance.csv its provenance does not record"

# 4. {name} and surfaces: a method answering S1 only (mc's S1 rows under {name}).
cat > "$t/s1only.sh" <<SH
awk -F, -v OFS=, -v m="\$1" 'NR == 1 || (\$1 == "mc" && \$2 == "S1") { if (NR > 1) \$1 = m; print }' \
  "$t/gen/tiny/radiance.csv" > "\$2/radiance.csv"
SH
"$ppb" run --quiet --ref-cache "$t/cache" --set experiment.methods=mc,r_only \
  --set "method.r_only.command=sh $t/s1only.sh {name} {out}" --set method.r_only.surfaces=S1 \
  --out "$t/p" "$t/tiny.ini" 2> /dev/null || fail "the partial method was refused"
grep -q '^r_only,S1,' "$t/p/radiance.csv" || fail "no S1 rows"
! grep -q '^r_only,S[234],' "$t/p/radiance.csv" || fail "rows written for surfaces not computed"
grep -Eq '^r_only,S1_all,[0-9.e-]+,[0-9.e-]+,0$' "$t/p/summary.csv" || fail "S1_all: $(grep r_only "$t/p/summary.csv")"
for c in T_x0 S2_all S3_all S4_all; do
  grep -q "^r_only,$c,nan,nan,nan$" "$t/p/summary.csv" || fail "$c not nan"
done
[ "$(grep -c '^r_only,S[234],.*,nan,nan,nan$' "$t/p/rms.csv")" = 14 ] || fail "rms.csv rows not nan"
grep -q '^method.r_only.surfaces = S1$' "$t/p/provenance.txt" || fail "surfaces not recorded"
rc=0
"$ppb" run --quiet --ref-cache "$t/cache" --set experiment.methods=mc,r_only \
  --set "method.r_only.command=sh $t/s1only.sh {name} {out}" --out "$t/q" "$t/tiny.ini" \
  2> "$t/q.err" || rc=$?
grep -q 'missing row: S2 segment 0' "$t/q.err" || fail "without surfaces, missing rows accepted"
pass "{name} and surfaces = S1: S2..S4 not computed"
echo "test_study_loop: all passed"
