#!/usr/bin/env bash
# device_check_objects.sh: the object Monte Carlo (`mc3d`, docs/methods.md) on a lent GPU
# machine (docs/performance.md, "On a GPU"): test_mc3d on the GPU's OpenCL device, the five
# configs/objects/*.ini at 1e7 photons (seconds, events/s, energy balance), and the same bytes
# across work-group sizes there. Needs scripts/device_bundle.sh's .devlibs/ with test_mc3d
# copied into .devlibs/bin (docs/performance.md). Under 5 minutes. Writes $OUT/objects.txt. A dry
# run here: PPB_CHECK_DEVICE=pthread PPB_CHECK_PHOTONS=1e5 OUT=/tmp/oc bash scripts/device_check_objects.sh
set -uo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "${OUT:-build/device_check_objects}")
mkdir -p "$out"
work=$(mktemp -d)
say() { echo "objects: $*" | tee -a "$out/objects.txt"; }
bin=./ppbench tests=build/tests
. scripts/device_env.sh
device_env "$work"
$bin devices > "$work/devices.txt" 2>&1
gpu=$(device_gpu "$work/devices.txt")
say "devices: gpu=${gpu:-none} ($(tr '\n' ';' < "$work/devices.txt"))"
[ -n "$gpu" ] || exit 1
export PPBENCH_DEVICE=$gpu PPBENCH_CACHE=
mkdir -p "$work/tmp"
PPBENCH=$PWD/$bin TMPDIR=$work/tmp timeout 120 "$tests/test_mc3d" > "$out/test_mc3d.log" 2>&1
say "test_mc3d on the GPU: rc $? ($(grep -E 'PASSED|FAILED' "$out/test_mc3d.log" | tr '\n' ' '))"
for c in box cube_two_faces sphere yokan blob; do
  /usr/bin/time -f "%e" -o "$work/$c.time" timeout 100 $bin object --out "$work/$c" \
    --set mc.photons=${PPB_CHECK_PHOTONS:-1e7} --set mc.batches=32 "configs/objects/$c.ini" > "$work/$c.log" 2>&1
  say "$c ${PPB_CHECK_PHOTONS:-1e7}: rc $?, $(cat "$work/$c.time") s wall; $(tail -1 "$work/$c.log")"
done
for wg in 64 256; do
  timeout 60 $bin object --quiet --out "$work/wg$wg" --set mc.photons=2e6 --set mc.workgroup=$wg \
    configs/objects/yokan.ini > /dev/null 2>&1
done
if cmp -s "$work/wg64/radiance.csv" "$work/wg256/radiance.csv"; then
  say "yokan 2e6, work-group 256 against 64: radiance.csv byte-identical"
else
  say "yokan 2e6, work-group 256 against 64: radiance.csv DIFFERS"
fi
cp "$work/yokan/totals.csv" "$out/yokan_totals.csv" 2>/dev/null
cp "$work/yokan/images/mc3d.png" "$out/yokan_mc3d.png" 2>/dev/null
