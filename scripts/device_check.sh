#!/usr/bin/env bash
# device_check.sh: the checks a session runs at once when it is lent a machine with a GPU
# (README.md, Performance). Under 5 minutes: builds, finds the GPU's OpenCL device, runs the
# kernel tests there, the Monte Carlo and rte2d benchmarks (events/s, time per case), and one
# study case's Monte Carlo on the GPU and on the CPU device (PoCL) with the same seed, compared
# bin by bin: chi2 per bin of (a - b)^2 / (se_a^2 + se_b^2), which is about 1 when the two
# devices agree within noise (docs/reference.md, Rules: across devices the same within noise).
# Writes everything under $OUT (default build/device_check) and prints a summary.
set -uo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-build/device_check}
mkdir -p "$out"
say() { echo "device_check: $*" | tee -a "$out/summary.txt"; }
: > "$out/summary.txt"
{ nvidia-smi || true; clinfo -l || true; } > "$out/hardware.txt" 2>&1
if ! make -j"$(nproc)" ppbench build/tests/test_ocl build/tests/test_mc > "$out/build.log" 2>&1; then
  say "build failed (build.log)"; exit 1
fi
./ppbench devices > "$out/devices.txt" 2>&1
gpu=$(grep -i -m1 -E 'nvidia|cuda|amd|gpu' "$out/devices.txt" | sed 's/^ *\([0-9]*\).*/\1/')
cpu=$(grep -i -m1 -E 'pthread|cpu' "$out/devices.txt" | sed 's/^ *\([0-9]*\).*/\1/')
say "devices: gpu=${gpu:-none} cpu=${cpu:-none} ($(tr '\n' ';' < "$out/devices.txt"))"
[ -n "$gpu" ] || { say "no GPU OpenCL device"; exit 1; }
mkdir -p build/tmp
for t in test_ocl test_mc; do
  PPBENCH_DEVICE=$gpu PPBENCH=$PWD/ppbench PPBENCH_CACHE= TMPDIR=$PWD/build/tmp \
    timeout 120 "build/tests/$t" > "$out/$t.log" 2>&1
  say "$t on the GPU: rc $? ($(grep -E 'PASSED|FAILED' "$out/$t.log" | tr '\n' ' '))"
done
for m in mc rte2d; do
  PPBENCH_DEVICE=$gpu PPBENCH_PERF_ONLY=$m timeout 150 ./ppbench perf > "$out/perf_$m.txt" 2>&1
  say "perf $m: rc $?: $(grep -v '^==' "$out/perf_$m.txt" | head -3 | tr '\n' ' ')"
done
case=configs/uniform_g0_normal.ini
for d in gpu cpu; do
  dev=${!d}
  [ -n "$dev" ] || continue
  photons=$([ $d = gpu ] && echo 4e8 || echo 4e7)
  /usr/bin/time -f "%e s" -o "$out/run_$d.time" timeout 240 ./ppbench run --quiet --device "$dev" \
    --no-ref-cache --set experiment.methods=mc --set mc.photons=$photons --out "$out/run_$d" \
    "$case" > "$out/run_$d.log" 2>&1
  say "$case mc on $d ($photons photons): rc $?, $(cat "$out/run_$d.time")"
done
if [ -f "$out/run_gpu/radiance.csv" ] && [ -f "$out/run_cpu/radiance.csv" ]; then
  # Every result of the run (the Monte Carlo and its once-scattered part), bin by bin.
  awk -F, 'FNR == 1 {next}
    NR == FNR {r[$1,$2,$3,$5,$6] = $7; s[$1,$2,$3,$5,$6] = $8; next}
    ($1,$2,$3,$5,$6) in r {k = $1 SUBSEP $2 SUBSEP $3 SUBSEP $5 SUBSEP $6
      v = s[k]^2 + $8^2; if (v > 0) {d = r[k] - $7; c += d*d/v; n++}}
    END {printf "GPU against CPU, Monte Carlo bins: chi2/bin %.3f over %d bins\n", c / n, n}' \
    "$out/run_gpu/radiance.csv" "$out/run_cpu/radiance.csv" | tee -a "$out/summary.txt"
fi
