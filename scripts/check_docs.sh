#!/usr/bin/env bash
# check_docs.sh: keeps docs/reference.md true to the code (run by `make test`, target `docs`).
#
# Runs a tiny tube experiment (mc, pp, ss, mp, mp+ss), a tiny slab one (with ppslab), a tiny
# two-key slab sweep and the study report, then fails, naming what is missing, when
#   - a file they write is not named in the reference (a name with a method id or a point hash
#     matches a `<method>` or `<hash>` pattern of the reference, e.g. `images/<method>.png`);
#   - a CSV header line (and table2.md's) does not appear verbatim as a line of the reference
#     (sweep.csv's from `method` on: its first columns are the swept keys);
#   - a key of provenance.txt (with `<method>.` for a method id) or a key `ppbench keys` prints
#     (as `section.key`) is not in the reference, in backquotes;
#   - a `reference: Section` cited in src/, kernels/, configs/, tests/ or scripts/ names no
#     heading of the reference;
#   - `ppbench --help` does not point to docs/reference.md;
#   - any file of the repository links to ../shared (a path outside any clone), or a document or
#     comment the reference replaced still cites SPEC.md;
#   - a comment or document cites a tracker's issue number ("issue 14"), which a reader of the
#     repository cannot follow: cite docs/reference.md or the literature.
# PPBENCH selects the binary (default ./ppbench); TMPDIR where the runs go.
set -uo pipefail
cd "$(dirname "$0")/.."
ref=docs/reference.md
bin=${PPBENCH:-./ppbench}
[ -x "$bin" ] || { echo "check_docs: no binary $bin (make first, or set PPBENCH)"; exit 1; }
[ -f "$ref" ] || { echo "check_docs: $ref missing"; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/check_docs.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail=0
missing() {
  echo "check_docs: $ref lacks $1"
  fail=1
}

# The reference's lines with leading blanks removed (code blocks are indented), and its
# backquoted names.
sed 's/^[[:space:]]*//' "$ref" > "$tmp/lines"
grep -o '`[^`]*`' "$ref" | tr -d '`' | sort -u > "$tmp/names"

# --- the runs (small: a few seconds each) ---
small=(--quiet --set mc.photons=1e4 --set pp.directions=16 --set bins.samples_dir=2)
run() {
  local what=$1
  shift
  if ! timeout 300 "$bin" "$@" > "$tmp/$what.log" 2>&1; then
    echo "check_docs: the $what run failed:"
    cat "$tmp/$what.log"
    exit 1
  fi
}
run tube run "${small[@]}" --set experiment.methods=mc,pp,ss,mp,mp+ss \
  --set tube.segments_top=16 --set tube.segments_side=6 --out "$tmp/out/tube" \
  configs/uniform_g0_normal.ini
run slab run "${small[@]}" --out "$tmp/out/slab" configs/slab_g0.ini
run sweep sweep "${small[@]}" --set mc.photons=2e3 --set experiment.methods=mc,ss \
  --set medium.g=0,0.5 --set medium.albedo=0.5,0.9 --out "$tmp/out/sweep" configs/slab_g0.ini
run report report "$tmp/out" tube slab

# The result ids the runs wrote (mc1 beside the methods).
tail -q -n +2 "$tmp"/out/{tube,slab}/radiance.csv | cut -d, -f1 | sort -u > "$tmp/methods"

# --- every file written is named ---
# A name with placeholders matches as a regex: <...> stands for a part of one path component
# without "/" or "_" (method ids and hashes have neither).
grep '<[a-z_]*>' "$tmp/names" | sed -e 's/[.[\^$*+?(){}|]/\\&/g' -e 's/<[a-z_]*>/[^\/_]+/g' \
  -e 's/^/^/' -e 's/$/$/' > "$tmp/patterns"
files=$(cd "$tmp/out" && for d in tube slab sweep; do (cd $d && find . -type f | sed 's|^\./||'); done
  find . -maxdepth 1 -type f | sed 's|^\./||')
for f in $(printf '%s\n' "$files" | sort -u); do
  grep -qxF -- "$f" "$tmp/names" && continue
  printf '%s\n' "$f" | grep -qEf "$tmp/patterns" && continue
  missing "the file \`$f\` (written by ppbench, named nowhere)"
done

# --- every CSV header, verbatim ---
for f in $(cd "$tmp/out" && find . -name '*.csv' ! -path '*/points/*' | sort); do
  h=$(head -n 1 "$tmp/out/$f")
  case $f in */sweep.csv | */failures.csv) h=method,${h#*,method,} ;; esac
  grep -qxF -- "$h" "$tmp/lines" || missing "the header line of $(basename "$f"): $h"
done
h=$(head -n 1 "$tmp/out/table2.md")
grep -qxF -- "$h" "$tmp/lines" || missing "the header line of table2.md: $h"

# --- provenance keys and config keys ---
"$bin" keys | awk -F' *[|] *' 'NR > 2 {print $2 "." $3}' > "$tmp/keys"
[ -s "$tmp/keys" ] || { echo "check_docs: ppbench keys printed no key"; exit 1; }
while read -r k; do
  grep -qxF -- "$k" "$tmp/names" || missing "the config key \`$k\`"
done < "$tmp/keys"
for p in "$tmp"/out/{tube,slab}/provenance.txt; do
  first=$(head -n 1 "$p")
  grep -qxF -- "$first" "$tmp/lines" || missing "provenance.txt's first line: $first"
  sed -n 's/^\([^ ]*\) = .*/\1/p' "$p" | while read -r k; do
    grep -qxF -- "$k" "$tmp/keys" && continue
    id=${k%.*}
    grep -qxF -- "$id" "$tmp/methods" && k="<method>.${k##*.}"
    grep -qxF -- "$k" "$tmp/names" || { echo "check_docs: $ref lacks the provenance key \`$k\`"; exit 1; }
  done || fail=1
done

# --- sections cited by the code exist ---
self=scripts/check_docs.sh
sections=$(sed -n 's/^##* //p' "$ref" | sed 's/ (.*//') # "Sweeps (`ppbench sweep`...)": Sweeps
cites=$(grep -rhoE 'reference: [A-Z][A-Za-z]*' src kernels configs tests \
  $(ls scripts/*.sh | grep -vxF "$self"))
for s in $(sed 's/.*: //' <<<"$cites" | sort -u); do
  printf '%s\n' "$sections" | grep -qxF -- "$s" || missing "the section '$s' that code comments cite"
done

# --- the help points here; nothing points outside the repository ---
# (captured first: grep -q stops reading at the match, and under pipefail the help's SIGPIPE
# would fail the check at random)
help=$("$bin" --help)
grep -qF docs/reference.md <<<"$help" || {
  echo "check_docs: ppbench --help does not name docs/reference.md"
  fail=1
}
if out=$(git ls-files -co --exclude-standard | grep -vxF "$self" |
  xargs -d '\n' grep -nIE '\.\./shared|shared/SPEC' 2>/dev/null); then
  echo "check_docs: links out of the repository (../shared):"
  echo "$out"
  fail=1
fi
# The documents and comments the reference replaced, as committed (work in progress that is not
# yet added to git is not held to it): no file of the project cites the specification it was
# built from (SPEC.md, "SPEC 13"), which a clone does not have.
cited=$( (ls README.md results/*.md configs/README.md docs/*.md
  git ls-files -- src kernels configs tests scripts python Makefile .ci) | grep -vxF "$self" |
  sort -u)
if out=$(printf '%s\n' "$cited" | xargs -d '\n' grep -nIE 'SPEC(\.md| [0-9])'); then
  echo "check_docs: SPEC.md (outside this repository) is still cited; cite docs/reference.md:"
  echo "$out"
  fail=1
fi

if out=$(printf '%s\n' "$cited" | xargs -d '\n' grep -nIiE '\bissues? [0-9]+\b'); then
  echo "check_docs: a tracker's issue number is cited (a clone has no tracker):"
  echo "$out"
  fail=1
fi

[ $fail = 0 ] && echo "check_docs: $ref names every file, header and key the runs wrote"
exit $fail
