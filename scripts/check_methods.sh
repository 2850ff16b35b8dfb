#!/usr/bin/env bash
# check_methods.sh: no method is named outside its slice and the registry (README.md, Layout;
# docs/reference.md, Methods: "Adding a method"). The runner, sweeps, benchmarks, report,
# writers and plots reach a method only through its registry entry (src/methods/method.h).
#
# The ids are read from the registry (src/methods/registry.c: `.id = "..."`, `.also = "..."`);
# a method's slice is the folder of src/methods/ that defines its run function. An id may stand
# as a string literal ("mc") only in the registry and in its own slice. Exempt, each for its
# reason:
#   src/model/config.c  the key table: a method's settings section is named as the id.
# Comment lines are passed over (a comment may cite a method). The scope is the harness: src/,
# kernels/ and scripts/ (python/ is a client that reads output sets). Prints each place and
# exits 1 if there is one; a tree given as $1 is checked instead (tests).
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root"
reg=src/methods/registry.c
[ -f "$reg" ] || { echo "check_methods: $reg: missing"; exit 1; }
# "id run-function" per registry entry; a companion (also) shares its method's run function.
entries=$(awk '
  /\{\.id = "/ || /^ *\{ *\.id *= *"/ { id = ""; also = ""; run = "" }
  { if (match($0, /\.id *= *"[^"]*"/)) { s = substr($0, RSTART, RLENGTH); sub(/.*= *"/, "", s); sub(/"$/, "", s); id = s }
    if (match($0, /\.also *= *"[^"]*"/)) { s = substr($0, RSTART, RLENGTH); sub(/.*= *"/, "", s); sub(/"$/, "", s); also = s }
    if (match($0, /\.run *= *[a-z_0-9]+/)) { s = substr($0, RSTART, RLENGTH); sub(/.*= */, "", s); run = s }
    if (id != "" && run != "" && $0 ~ /\}/) { print id, run; if (also != "") print also, run; id = "" } }' "$reg")
[ -n "$entries" ] || { echo "check_methods: $reg: no method entries found"; exit 1; }
bad=0
while read -r id run; do
  # The slice: the folder whose .c defines the run function at the start of a line.
  def=$(grep -l -E "^int $run\(" src/methods/*/*.c 2>/dev/null | head -1 || true)
  slice=${def:+$(dirname "$def")}
  lit="\"$(printf '%s' "$id" | sed 's/[+.]/\\&/g')\""
  while IFS= read -r hit; do
    f=${hit%%:*}
    text=${hit#*:*:}
    case $f in
      *.sh|*.gp) [[ $text =~ ^[[:space:]]*# ]] && continue ;;
      *) [[ $text =~ ^[[:space:]]*(/\*|\*|//) ]] && continue ;;
    esac
    case $f in
      "$reg"|src/model/config.c) continue ;;
    esac
    [ -n "$slice" ] && [[ $f == "$slice"/* ]] && continue
    echo "check_methods: $hit: names method '$id' outside its slice (${slice:-the registry}) and the registry"
    bad=1
  done < <(grep -rn -E --include='*.c' --include='*.h' --include='*.cl' --include='*.sh' \
             --include='*.gp' "$lit" src kernels scripts 2>/dev/null || true)
done <<< "$entries"
[ $bad = 0 ] && echo "methods: no method named outside its slice and the registry"
exit $bad
