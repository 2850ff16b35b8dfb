#!/usr/bin/env bash
# test_layers.sh: scripts/check_layers.sh against planted violations, one of each kind, each in
# a tiny tree of its own (the script, a src/LAYERS, a few files), plus trees it must pass and
# the real tree. The expected outcome of each case is the rule it plants, stated in
# check_layers.sh's header and src/LAYERS: exit 1 and a message naming the file, the line and
# the rule; or exit 0.
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/test_layers.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
failed=0 n=0

# A fresh tree: the script, the layer order of the real src/LAYERS' shape, one clean file per
# layer and slice (so every layer exists), and the registry's allowance.
tree() {
  rm -rf "$tmp/t"
  mkdir -p "$tmp/t/scripts" "$tmp/t/kernels" "$tmp/t/src"/{base,model,physics,io,runtime,drivers} \
    "$tmp/t/src/methods"/{mc,pp} "$tmp/t/python/ppbench"
  cp "$here/scripts/check_layers.sh" "$tmp/t/scripts/"
  printf '%s\n' base model 'physics io runtime' methods drivers \
    'allow src/methods/registry.c src/methods/*/*' >"$tmp/t/src/LAYERS"
  for f in base/err model/scene physics/maps io/csv runtime/ocl methods/method drivers/main \
    methods/mc/mc_tally methods/pp/march; do
    echo "/* $f */" >"$tmp/t/src/$f.h"
  done
  echo '#define PPB_X 1' >"$tmp/t/kernels/ppb_conventions.h"
  echo '"""the package"""' >"$tmp/t/python/ppbench/__init__.py"
}
put() { mkdir -p "$(dirname "$tmp/t/$1")" && printf '%b' "$2" >"$tmp/t/$1"; }

# expect NAME CODE NEEDLE: check_layers.sh on the tree exits CODE and prints NEEDLE.
expect() {
  n=$((n + 1))
  out=$(bash "$tmp/t/scripts/check_layers.sh" 2>&1)
  rc=$?
  if [ "$rc" != "$2" ] || ! grep -qF -- "$3" <<<"$out"; then
    echo "FAIL $1: exit $rc (want $2), output lacks '$3':"
    sed 's/^/  /' <<<"$out"
    failed=1
  else
    echo "ok   $1"
  fi
}

tree
put src/base/a.c '#include "base/err.h"\n#include <stdio.h>\n'
put src/drivers/z.c '/* no project include: the last file globbed */\n#include <stdio.h>\n'
expect "clean tree (last file without project include)" 0 "layers: every include"

tree
put src/base/a.c '#include "base/err.h"\n#include <drivers/main.h>\n'
expect "angle-bracket include upward" 1 \
  'src/base/a.c:2: #include <drivers/main.h> (src/drivers/main.h): base may not include drivers (above it in src/LAYERS)'

tree
put src/model/a.c 'int x;\n   #  include "drivers/main.h"\n'
expect "indented '#  include' upward" 1 \
  'src/model/a.c:2: #include "drivers/main.h" (src/drivers/main.h): model may not include drivers (above it'

tree
put src/base/a.c '#include "kernels/../src/drivers/main.h"\n'
expect "path through .. normalised" 1 \
  'src/base/a.c:1: #include "kernels/../src/drivers/main.h" (src/drivers/main.h): base may not include drivers'

tree
put src/io/a.c '#include "physics/maps.h"\n'
expect "peers" 1 'src/io/a.c:1: #include "physics/maps.h" (src/physics/maps.h): io may not include physics (peers in src/LAYERS)'

tree
put kernels/ppb_x.h '#include "ppb_conventions.h"\n#include "../src/base/err.h"\n'
expect "kernels/ header includes src/" 1 \
  'kernels/ppb_x.h:2: #include "../src/base/err.h" (src/base/err.h): kernels/ headers may include only kernels/ headers'

tree
put src/methods/mc/mc.cl '#include "ppb_conventions.h"\n#include "../pp/march.h"\n'
expect "kernel of a slice includes another slice" 1 \
  'src/methods/mc/mc.cl:2: #include "../pp/march.h" (src/methods/pp/march.h): the slice methods/mc may not include another slice (methods/pp)'

tree
put src/methods/mc/method_mc.c '#include "methods/mc/mc_tally.h"\n#include "methods/method.h"\n#include "methods/pp/march.h"\n'
expect "host code of a slice includes another slice" 1 \
  'src/methods/mc/method_mc.c:3: #include "methods/pp/march.h" (src/methods/pp/march.h): the slice methods/mc may not include another slice'

tree
put src/methods/work.c '#include "methods/method.h"\n#include "methods/mc/mc_tally.h"\n'
put src/methods/registry.c '#include "methods/mc/mc_tally.h"\n#include "methods/pp/march.h"\n'
expect "methods core includes a slice (registry.c may)" 1 \
  'src/methods/work.c:2: #include "methods/mc/mc_tally.h" (src/methods/mc/mc_tally.h): the methods core may not include a slice (methods/mc)'
if grep -q registry.c <<<"$out"; then echo "FAIL registry.c was refused:"; echo "$out"; failed=1; fi

tree
put src/methods/pp/method_pp.c '#include "methods/mc/mc_tally.h"\n'
echo 'allow src/methods/pp/method_pp.c src/methods/mc/mc_tally.h' >>"$tmp/t/src/LAYERS"
expect "an allow line of src/LAYERS lets one slice include another" 0 "layers: every include"

tree
put src/model/a.h '#include "model/b.h"\n'
put src/model/b.h '#include "base/err.h"\n#include "model/a.h"\n'
expect "include cycle within a layer" 1 \
  'src/model/b.h:2: includes src/model/b -> src/model/a: part of a cycle (src/model/a src/model/b)'

tree
put src/base/a.c '#include "base/missing.h"\n'
expect "quoted include of no project file" 1 \
  'src/base/a.c:1: #include "base/missing.h": no such file in the project'

tree
put src/base/a.c '#include "tests/testutil.h"\n'
put tests/testutil.h '/* test helpers */\n'
expect "src includes tests/" 1 \
  'src/base/a.c:1: #include "tests/testutil.h" (tests/testutil.h): base may include only layers of src/LAYERS and kernels/, not tests/'

tree
put src/gui/a.c '#include "base/err.h"\n'
expect "folder that is not a layer" 1 "src/gui/a.c: folder 'src/gui' is not a layer of src/LAYERS"

tree
put src/methods/mc/deep/x.h '#include "methods/pp/march.h"\n'
expect "a file deeper in a slice" 1 \
  'src/methods/mc/deep/x.h:1: #include "methods/pp/march.h" (src/methods/pp/march.h): the slice methods/mc may not include another slice'

tree
put tests/x.c '#include "drivers/main.h"\n#include "../src/methods/mc/mc_tally.h"\n'
expect "tests/ may include anything" 0 "layers: every include"

if command -v python3 >/dev/null; then
  tree
  put python/ppbench/a.py '"""import ppbench.b (a docstring, not an import)"""\nimport os\n'
  put python/ppbench/b.py 'from ppbench import a\n'
  expect "python: an import in a docstring is no import" 0 "layers: every include"
  put python/ppbench/a.py 'import os\nfrom . import b\n'
  expect "python import cycle" 1 \
    'python/ppbench/a.py:2: imports ppbench.a -> ppbench.b: part of a cycle'
fi

tree
rm "$tmp/t/src/LAYERS"
expect "no src/LAYERS" 1 "src/LAYERS is missing"

n=$((n + 1))
if out=$(bash "$here/scripts/check_layers.sh" "$here" 2>&1); then
  echo "ok   the real tree"
else
  echo "FAIL the real tree:"
  sed 's/^/  /' <<<"$out"
  failed=1
fi

[ $failed = 0 ] && echo "test_layers: $n cases pass"
exit $failed
