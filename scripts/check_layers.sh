#!/usr/bin/env bash
# check_layers.sh: the include graph of src/ points only downward (README.md, Layout).
# A module may include its own layer's headers and those of the layers below it; kernels/
# headers are shared by every layer. No include cycle, within a layer or across. Prints each violation and exits 1 if there is one.
set -euo pipefail
cd "$(dirname "$0")/.."
# Bottom to top. Layers on one line are peers: neither includes the other.
order=(base model "physics io runtime" methods drivers)
declare -A rank
for i in "${!order[@]}"; do for l in ${order[$i]}; do rank[$l]=$i; done; done
bad=0
for f in src/*/*.[ch]; do
  from=$(basename "$(dirname "$f")")
  [ -n "${rank[$from]:-}" ] || { echo "$f: folder '$from' is not a layer"; bad=1; continue; }
  while IFS= read -r inc; do
    to=${inc%%/*}
    [ "$to" = kernels ] && continue
    if [ -z "${rank[$to]:-}" ]; then echo "$f: includes \"$inc\" (no layer)"; bad=1
    elif [ "$to" != "$from" ] && [ "${rank[$to]}" -ge "${rank[$from]}" ]; then
      echo "$f: $from includes \"$inc\" ($to is not below $from)"; bad=1
    fi
  done < <(sed -n 's/^#include "\([^"]*\)".*/\1/p' "$f")
done
# No cycles inside a layer either: module -> included module pairs, one per line, for tsort.
edges=$(for f in src/*/*.[ch]; do m=${f#src/}; m=${m%.*}
  sed -n 's/^#include "\([a-z]*\/[a-z_0-9]*\)\.h".*/\1/p' "$f" | grep -v '^kernels/' |
    while read -r t; do [ "$t" = "$m" ] || echo "$m $t"; done; done)
if ! echo "$edges" | tsort >/dev/null 2>/tmp/check_layers.$$; then
  echo "include cycle:"; sed 's/^tsort: /  /' /tmp/check_layers.$$; bad=1
fi
rm -f /tmp/check_layers.$$
[ $bad = 0 ] && echo "layers: every include of src/ points down, no cycles"
exit $bad
