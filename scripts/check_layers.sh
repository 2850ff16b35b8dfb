#!/usr/bin/env bash
# check_layers.sh: the include graph of the project points only downward (README.md, Layout).
# Usage: scripts/check_layers.sh [ROOT] (default: the repository holding this script).
#
# Reads the layer order from ROOT/src/LAYERS (its only statement) and checks every include of
# every .c, .h and .cl file under src/ (every depth, the method slices included) and kernels/:
# quoted and angle-bracket includes, indented or written "# include". Each include is resolved as
# the compilers do (the host: the file's folder for quotes, then -Isrc -I. -Ikernels; a kernel:
# its folder, then -I kernels) to the first project file that exists, its path normalised
# ("kernels/../src/drivers/x.h" is src/drivers/x.h). An angle-bracket include that names no
# project file is a system header; a quoted one is a failure. The rules:
#   - a file of src/<layer>/ includes its own layer, the layers below it and kernels/ headers;
#     never a layer above, a peer, tests/ or anything else of the repository;
#   - kernels/ headers include only kernels/ headers;
#   - a method slice (src/methods/<slice>/) includes its own slice, the methods core and the
#     layers below, never another slice; the core includes no slice; except where src/LAYERS
#     allows one file an include ("allow FILE PATTERN": those two rules only, never the order);
#   - no include cycle among the modules (x.c and x.h are module x), within a layer or across
#     (tsort);
#   - python/ppbench: its modules have no natural order (the package's __init__ and the
#     modules under it import each other's names), so only import cycles are refused.
# tests/ may include anything and is not read. Every failure is one line naming the file, the
# line, the include and the rule it breaks; exit 1 if any, else 0 with one line saying so.
set -uo pipefail
root=${1:-$(dirname "$0")/..}
cd "$root" || { echo "check_layers: no directory $root"; exit 2; }
layers_file=src/LAYERS
[ -f "$layers_file" ] || { echo "check_layers: $layers_file is missing: it states the layer order"; exit 1; }

declare -A rank
allows=()
r=0
while IFS= read -r line || [ -n "$line" ]; do
  line=${line%%#*}
  read -r -a words <<<"$line"
  [ ${#words[@]} = 0 ] && continue
  if [ "${words[0]}" = allow ]; then
    [ ${#words[@]} = 3 ] || { echo "$layers_file: '$line': expected allow FILE PATTERN"; exit 1; }
    allows+=("${words[1]} ${words[2]}")
    continue
  fi
  for l in "${words[@]}"; do rank[$l]=$r; done
  r=$((r + 1))
done <"$layers_file"
[ ${#rank[@]} -gt 0 ] || { echo "$layers_file: names no layer"; exit 1; }

bad=0
fail() { echo "$*"; bad=1; }

# norm PATH: PATH with "." and "x/.." removed, as realpath -m prints it relative to the root
# (no link is followed: the project holds none), without a process per include. Sets NORM.
norm() {
  local IFS=/ part
  local -a out=()
  for part in $1; do
    case $part in
      '' | .) ;;
      ..) if [ ${#out[@]} -gt 0 ] && [ "${out[-1]}" != .. ]; then unset 'out[-1]'; else out+=(..); fi ;;
      *) out+=("$part") ;;
    esac
  done
  NORM="${out[*]}"
}

# where PATH: what PATH belongs to. Sets CLS (a layer, "kernels", "tests", "src" for a file of
# src/ outside a layer folder, or "outside") and SLICE (the method slice, or "" for the core).
where() {
  SLICE=
  case $1 in
    kernels/*) CLS=kernels ;;
    tests/*) CLS=tests ;;
    src/methods/*/*) CLS=methods SLICE=${1#src/methods/} SLICE=${SLICE%%/*} ;;
    src/*/*) CLS=${1#src/} CLS=${CLS%%/*} ;;
    src/*) CLS=src ;;
    *) CLS=outside ;;
  esac
}

allowed() { # FROM TO: an "allow" line of src/LAYERS covers it
  local a
  for a in "${allows[@]+"${allows[@]}"}"; do
    # shellcheck disable=SC2053 # the pattern is a pattern
    [[ $1 == "${a%% *}" && $2 == ${a#* } ]] && return 0
  done
  return 1
}

files=$(find src kernels -type f \( -name '*.c' -o -name '*.h' -o -name '*.cl' \) 2>/dev/null | sort)
edges=() # "from_module to_module file:line"
for f in $files; do
  where "$f"
  from=$CLS fslice=$SLICE
  if [ "$from" != kernels ] && [ -z "${rank[$from]:-}" ]; then
    fail "$f: folder '${f%/*}' is not a layer of $layers_file"
    continue
  fi
  dir=${f%/*}
  while IFS=: read -r ln text; do
    [[ $text =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*([\"\<])([^\"\>]*)[\"\>] ]] || continue
    kind=${BASH_REMATCH[1]} inc=${BASH_REMATCH[2]}
    shown="#include $kind$inc$([ "$kind" = '"' ] && echo '"' || echo '>')"
    if [ "$kind" = '"' ]; then search=("$dir" src . kernels); else search=(src . kernels); fi
    to=
    for s in "${search[@]}"; do
      norm "$s/$inc"
      [ -f "$NORM" ] && { to=$NORM; break; }
    done
    if [ -z "$to" ]; then
      [ "$kind" = '"' ] && fail "$f:$ln: $shown: no such file in the project (quoted includes name project files)"
      continue
    fi
    at="$f:$ln: $shown ($to)"
    where "$to"
    tcls=$CLS tslice=$SLICE
    edges+=("${f%.*} ${to%.*} $f:$ln")
    if [ "$from" = kernels ]; then
      [ "$tcls" = kernels ] || fail "$at: kernels/ headers may include only kernels/ headers"
      continue
    fi
    if [ "$tcls" = kernels ]; then continue; fi
    if [ -z "${rank[$tcls]:-}" ]; then
      fail "$at: $from may include only layers of $layers_file and kernels/, not $([ "$tcls" = outside ] || [ "$tcls" = src ] && echo "${to%/*}/" || echo "$tcls/")"
    elif [ "$tcls" = "$from" ]; then
      [ "$from" = methods ] || continue
      if [ -n "$fslice" ] && [ -n "$tslice" ] && [ "$fslice" != "$tslice" ] && ! allowed "$f" "$to"; then
        fail "$at: the slice methods/$fslice may not include another slice (methods/$tslice): only where $layers_file allows"
      elif [ -z "$fslice" ] && [ -n "$tslice" ] && ! allowed "$f" "$to"; then
        fail "$at: the methods core may not include a slice (methods/$tslice): only files $layers_file allows"
      fi
    elif [ "${rank[$tcls]}" = "${rank[$from]}" ]; then
      fail "$at: $from may not include $tcls (peers in $layers_file)"
    elif [ "${rank[$tcls]}" -gt "${rank[$from]}" ]; then
      fail "$at: $from may not include $tcls (above it in $layers_file)"
    fi
  done < <(grep -nE '^[[:space:]]*#[[:space:]]*include' "$f")
done

# cycles EDGES...: each "from to where" edge; fails naming the edges of every loop tsort finds.
cycles() {
  local what=$1
  shift
  local out loop e
  [ $# -gt 0 ] || return 0
  out=$(printf '%s\n' "$@" | awk '$1 != $2 {print $1, $2}' | tsort 2>&1 >/dev/null) && return 0
  loop=$(sed -n 's/^tsort: //p' <<<"$out" | grep -v 'input contains a loop' | sort -u)
  for e in "$@"; do
    read -r a b w <<<"$e"
    [ "$a" != "$b" ] && grep -qxF -- "$a" <<<"$loop" && grep -qxF -- "$b" <<<"$loop" &&
      fail "$w: $what $a -> $b: part of a cycle ($(tr '\n' ' ' <<<"$loop" | sed 's/ $//'))"
  done
  return 0
}
cycles includes "${edges[@]+"${edges[@]}"}"

# python/ppbench: "module imported-module file:line" for every import of a module of the
# package (import ppbench.x, from ppbench import x, from . import x, from .x import y), read by
# Python's own parser (docstrings and comments are not imports).
if [ -d python/ppbench ]; then
  if ! command -v python3 >/dev/null; then
    echo "check_layers: python3 not found: the imports of python/ppbench were not checked"
  else
    py=$(python3 - python/ppbench <<'EOF'
import ast, os, sys
pkg = sys.argv[1]
mods = {f[:-3] for f in os.listdir(pkg) if f.endswith(".py")}
name = lambda m: "ppbench" if m in ("", "__init__") else "ppbench." + m
for f in sorted(os.listdir(pkg)):
    if not f.endswith(".py"):
        continue
    path = os.path.join(pkg, f)
    me = name(f[:-3])
    try:
        tree = ast.parse(open(path, encoding="utf-8").read(), path)
    except SyntaxError as e:
        print("ERROR %s:%d: not Python: %s" % (path, e.lineno or 0, e.msg))
        continue
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = "ppbench" + ("." + base if base else "")
            targets = [base + "." + a.name if base == "ppbench" and a.name in mods else base
                       for a in node.names]
        for t in targets:
            if t == "ppbench" or t.startswith("ppbench."):
                t = t if t == "ppbench" or t[8:] in mods else "ppbench"
                print("%s %s %s:%d" % (me, t, path, node.lineno))
EOF
    ) || fail "check_layers: python3 could not read python/ppbench"
    pyedges=()
    while IFS= read -r e; do
      [ -n "$e" ] || continue
      case $e in ERROR\ *) fail "${e#ERROR }" ;; *) pyedges+=("$e") ;; esac
    done <<<"$py"
    cycles imports "${pyedges[@]+"${pyedges[@]}"}"
  fi
fi

[ $bad = 0 ] && echo "layers: every include of src/ and kernels/ points down ($layers_file), no slice includes another but as it allows, no cycles (C includes, python/ppbench imports)"
exit $bad
