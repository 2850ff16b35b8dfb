#!/usr/bin/env bash
# device_check.sh: the checks a session runs at once when it is lent a machine with a GPU
# (docs/performance.md, "On a GPU"). Under 5 minutes. It runs the kernel test suites on the
# GPU's OpenCL device, the Monte Carlo and rte2d benchmarks (events/s, seconds per case), one
# study case's Monte Carlo at the study's budget, the bit-identity of the Monte Carlo across
# work-group sizes on that device, and rte2d beside it. The CPU side of the comparison (PoCL,
# the same seed and an independent one) runs where PoCL is: scripts/device_compare.sh.
#
# The lent machine's image has CUDA but not ppbench's Debian libraries, and no package
# registry: scripts/device_bundle.sh puts the built binaries and their libraries under
# .devlibs/ here, which the device tool carries. The NVIDIA OpenCL driver is the machine's own;
# it is looked up and named to the ICD loader through $OCL_ICD_VENDORS.
# Writes $OUT/summary.txt and $OUT/device_check.tar.gz (default OUT: build/device_check).
set -uo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "${OUT:-build/device_check}")
work=$(mktemp -d)/device_check
mkdir -p "$out" "$work"
say() { echo "device_check: $*" | tee -a "$work/summary.txt"; }
finish() { cp "$work/summary.txt" "$out/"; tar -C "$work/.." --exclude=device_check/refs/cache --exclude=device_check/tmp \
    -czf "$out/device_check.tar.gz" device_check; }
trap finish EXIT

bin=./ppbench tests=build/tests
. scripts/device_env.sh
if device_env "$work"; then
  say "prebuilt binaries (.devlibs), NVIDIA OpenCL driver: ${lib:-not found}"
elif ! make -j"$(nproc)" ppbench build/tests/test_ocl build/tests/test_mc > "$work/build.log" 2>&1; then
  say "build failed (build.log)"; exit 1
fi
{ nvidia-smi || true; } > "$work/hardware.txt" 2>&1
$bin devices > "$work/devices.txt" 2>&1
# $PPB_CHECK_DEVICE (a selector) stands in for the GPU in a dry run on any machine.
gpu=$(device_gpu "$work/devices.txt")
say "devices: gpu=${gpu:-none} ($(tr '\n' ';' < "$work/devices.txt"))"
[ -n "$gpu" ] || { say "no GPU OpenCL device"; exit 1; }
export PPBENCH_DEVICE=$gpu PPBENCH_CACHE=
mkdir -p "$work/tmp"

for t in test_ocl test_mc; do
  PPBENCH=$PWD/$bin TMPDIR=$work/tmp timeout 150 "$tests/$t" > "$work/$t.log" 2>&1
  say "$t on the GPU: rc $? ($(grep -E 'PASSED|FAILED' "$work/$t.log" | tr '\n' ' '))"
done

# The Monte Carlo benchmark at 2e8 photons: at the CPU's 1e7 a GPU's launch costs dominate.
PPBENCH_PERF_MC_PHOTONS=200000000 PPBENCH_PERF_ONLY=mc timeout 120 $bin perf > "$work/perf_mc.txt" 2>&1
say "perf mc: rc $?: $(grep -v '^==' "$work/perf_mc.txt" | tr '\n' ' ')"
PPBENCH_PERF_ONLY=rte2d timeout 90 $bin perf > "$work/perf_rte2d.txt" 2>&1
say "perf rte2d: rc $?: $(grep -v '^==' "$work/perf_rte2d.txt" | tr '\n' ' ')"

# One study case: the Monte Carlo at the study's budget with rte2d scored against it, then
# 4e7 photons at the default seed three times over work-group sizes (32, 64, 128): the same
# bytes (docs/reference.md, Rules). device_compare.sh sets the 4e7 run beside PoCL's.
run() { # name, extra args...
  local name=$1; shift
  /usr/bin/time -f "%e" -o "$work/$name.time" timeout 120 $bin run --quiet --no-ref-cache \
    --out "$work/$name" "$@" > "$work/$name.log" 2>&1
  say "run $name: rc $?, $(cat "$work/$name.time" 2>/dev/null) s"
}
case=configs/uniform_g0_normal.ini
run study "$case" --set experiment.methods=mc,rte2d --set mc.photons=${PPB_CHECK_PHOTONS:-4e8}
[ -f "$work/study/summary.csv" ] &&
  say "rte2d against the GPU's 4e8 photons: $(grep '^rte2d,' "$work/study/summary.csv" | head -3 | tr '\n' ' ')"
for wg in 64 32 128; do
  run "mc4e7_wg$wg" "$case" --set experiment.methods=mc --set mc.photons=4e7 --set mc.workgroup=$wg
done
for wg in 32 128; do
  if cmp -s "$work/mc4e7_wg64/radiance.csv" "$work/mc4e7_wg$wg/radiance.csv"; then
    say "work-group $wg against 64: radiance.csv byte-identical"
  else
    say "work-group $wg against 64: radiance.csv DIFFERS"
  fi
done

# With the time left (until $PPB_CHECK_BUDGET seconds from the start, default 380): the study's
# cases at 4e9 photons each in 256 batches (scripts/rte2d_reference.sh's: with the study's 16
# an exact method's chi-square per bin is 1.154), the realistic ones first, stored in a
# reference cache and brought back xz-compressed in parts of at most 15 MiB (refs.tar.xz.aa,
# .ab, ...). Each run's
# provenance.txt names its shipped key (mc.shipped_key), under which the file serves as a
# reference on any device (mc_cache.h).
budget=${PPB_CHECK_BUDGET:-380}
mkdir -p "$work/refs"
for c in realistic_g09_normal_n14 realistic_g08_step_oblique_n14 \
         $(grep -v -E '^(#|$)|^realistic' configs/study.list); do
  left=$((budget - SECONDS))
  [ $left -gt 20 ] || { say "refs: no time left for $c"; continue; }
  t0=$SECONDS
  timeout $((left < 90 ? left : 90)) $bin run --quiet --ref-cache "$work/refs/cache" \
    --out "$work/refs/$c" "configs/$c.ini" --set experiment.methods=mc \
    --set mc.photons=${PPB_CHECK_REF_PHOTONS:-4e9} --set mc.target_noise=0 \
    --set mc.batches=256 > "$work/refs/$c.log" 2>&1
  say "refs $c: rc $?, $((SECONDS - t0)) s, $(grep -m1 shipped_key "$work/refs/$c/provenance.txt" 2>/dev/null)"
  rm -rf "$work/refs/$c/images" "$work/refs/$c/plots" "$work/refs/$c/radiance.csv" "$work/refs/$c/angular.csv"
done
if command -v xz > /dev/null; then
  tar -C "$work" -cf - refs | xz -T0 -6 | split -b 15M - "$out/refs.tar.xz."
else
  tar -C "$work" -czf - refs | split -b 15M - "$out/refs.tar.gz."
fi
