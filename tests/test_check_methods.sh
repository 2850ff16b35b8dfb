#!/usr/bin/env bash
# test_check_methods.sh: scripts/check_methods.sh passes on the tree and fails, naming the
# place, on a copy of it with a method id planted outside its slice: in the runner (drivers/),
# in another slice, and in a kernel header; a comment citing a method and the config key
# table's section names are not violations. Prints "N passed, M failed".
set -uo pipefail
cd "$(dirname "$0")/.."
tmp=$(mktemp -d "${TMPDIR:-/tmp}/check_methods.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
check() { # name expected-rc grep-pattern tree
  local out rc
  out=$(bash scripts/check_methods.sh "$4" 2>&1); rc=$?
  if [ "$rc" = "$2" ] && grep -q -- "$3" <<< "$out"; then pass=$((pass + 1))
  else fail=$((fail + 1)); echo "FAIL $1: rc $rc, output: $out"; fi
}
fresh() { rm -rf "$tmp/t"; mkdir -p "$tmp/t"; cp -r src kernels scripts "$tmp/t/"; }
check "the tree" 0 "no method named" .
fresh; echo 'static const char *x = "rte2d";' >> "$tmp/t/src/drivers/experiment.c"
check "runner names rte2d" 1 "src/drivers/experiment.c:.*'rte2d'" "$tmp/t"
fresh; echo 'static const char *y = "mc1";' >> "$tmp/t/src/methods/pp/method_pp.c"
check "slice names another's companion" 1 "method_pp.c:.*'mc1'" "$tmp/t"
fresh; echo '#define PPB_X "mp+ss"' >> "$tmp/t/kernels/ppb_conventions.h"
check "kernel header names a sum" 1 "ppb_conventions.h:.*'mp+ss'" "$tmp/t"
fresh; printf '/* as "mc" does */\n' >> "$tmp/t/src/drivers/sweep.c"
check "a comment is no violation" 0 "no method named" "$tmp/t"
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
