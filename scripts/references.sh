#!/usr/bin/env bash
# references.sh [--from DIR] [--out DIR] [CASE...]: the shipped Monte Carlo references
# (docs/reference.md, "The reference cache": shipped references) from a study already run:
# for every case (default: configs/study.list) the tally file its run loaded or stored
# (DIR/<case>/provenance.txt's mc.reference, under make bench's cache), xz-compressed into
# OUT/<case>/mc-<key>.bin.xz (<key>: its mc.shipped_key, the cache's key without the device, so
# that every device is served: docs/reference.md, Keys), with OUT/<case>/provenance.txt saying what it is (photons, seed,
# batches, version, commit, device, key). DIR defaults to results (what `make bench` wrote),
# OUT to references. Refuses a case whose run was partial, traced no reference, or whose file
# is gone; fails when the whole layer passes 50 MB. `make references` runs it. Without CASEs:
# the study's cases and each channel of the materials study's (materials/<case>/<r|g|b>).
set -euo pipefail
cd "$(dirname "$0")/.."
from=results out=references cases=()
while [ $# -gt 0 ]; do
  case $1 in
    --from) from=$2; shift ;;
    --out) out=$2; shift ;;
    -*) echo "references.sh: unknown option $1" >&2; exit 2 ;;
    *) cases+=("$1") ;;
  esac
  shift
done
# Default: the study's cases, then each channel of the materials study's colour cases
# (configs/materials.list; results/materials/<case>/<r|g|b>, a channel's own output set).
if [ ${#cases[@]} -eq 0 ]; then
  mapfile -t cases < configs/study.list
  while read -r m; do [ -n "$m" ] && cases+=("materials/$m/r" "materials/$m/g" "materials/$m/b"); done < configs/materials.list
fi
val() { sed -n "s/^$2 = //p" "$1" | head -1; }
for c in "${cases[@]}"; do
  p=$from/$c/provenance.txt
  [ -f "$p" ] || { echo "references.sh: $c: no $p (run make bench first)" >&2; exit 1; }
  src=$(val "$p" mc.reference)
  [ -n "$src" ] || { echo "references.sh: $c: $p names no mc.reference (a run without the reference cache)" >&2; exit 1; }
  [ -f "$src" ] || { echo "references.sh: $c: $src (its mc.reference) is gone" >&2; exit 1; }
  [ "$(val "$p" partial)" = 0 ] || { echo "references.sh: $c: $p is a partial run" >&2; exit 1; }
  name=$(val "$p" mc.shipped_key)
  # the shipped layer is one level deep (references/<dir>/mc-<key>.bin.xz, mc_cache.h): a
  # channel of a colour case, materials/<case>/<r|g|b>, ships as <case>_<r|g|b>
  d=${c#materials/}
  d=${d//\//_}
  [ -n "$name" ] || { echo "references.sh: $c: $p names no mc.shipped_key (an older ppbench's run)" >&2; exit 1; }
  rm -rf "$out/$d.tmp" && mkdir -p "$out/$d.tmp"
  # a case served from the shipped layer itself (mc.reference ends .xz) is copied as it is
  if [ "${src%.xz}" != "$src" ]; then cp "$src" "$out/$d.tmp/$name.xz"; else xz -9e -T1 -c "$src" > "$out/$d.tmp/$name.xz"; fi
  {
    echo "# ppbench shipped reference: the Monte Carlo tallies (mc and mc1) of case $c"
    echo "case = $c"
    echo "file = $name.xz"
    echo "key = ${name#mc-}" | sed 's/\.bin$//'
    echo "cache_file = $(basename "${src%.xz}")"
    for k in mc.photons mc.seed mc.batches mc.first mc.target_noise ppbench.version ppbench.commit device opencl.driver_version date; do
      echo "$k = $(val "$p" "$k")"
    done
    echo "source = $src"
  } > "$out/$d.tmp/provenance.txt"
  rm -rf "$out/$d" && mv "$out/$d.tmp" "$out/$d"
  printf '%s: %s (%s bytes)\n' "$c" "$out/$d/$name.xz" "$(stat -c %s "$out/$d/$name.xz")" >&2
done
total=$(du -cb "$out"/*/mc-*.bin.xz | tail -1 | cut -f1)
printf 'references.sh: %s holds %s bytes of references\n' "$out" "$total" >&2
# 30 MB for the study's 13 cases (about 2 MB each at 4e8 photons), 20 MB more for the materials
# study's 15 channels (0.8-1.5 MB each at 4e7 photons).
[ "$total" -le $((50 * 1024 * 1024)) ] || { echo "references.sh: over 50 MB" >&2; exit 1; }
