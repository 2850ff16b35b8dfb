#!/usr/bin/env bash
# device_bundle.sh: prepares, on this (Debian) machine, what scripts/device_check.sh needs on a
# lent GPU machine whose image has CUDA but none of ppbench's Debian libraries: the built
# ppbench and the two kernel test suites, and every shared library they load apart from the C
# library itself (ldd, links followed), under .devlibs/ (git-ignored; name it in the device
# tool's carry). The GPU's OpenCL driver is the machine's own: device_check.sh finds it there.
set -euo pipefail
cd "$(dirname "$0")/.."
make -j"$(nproc)" ppbench build/tests/test_ocl build/tests/test_mc > /dev/null
rm -rf .devlibs
mkdir -p .devlibs/lib .devlibs/bin
cp ppbench build/tests/test_ocl build/tests/test_mc .devlibs/bin/
for b in .devlibs/bin/*; do ldd "$b"; done | awk '$3 ~ /^\// {print $3}' | sort -u |
  grep -v -E '/(libc|libm|libpthread|libdl|librt|ld-linux[^/]*)\.so' |
  while read -r l; do cp -L "$l" .devlibs/lib/; done
du -sh .devlibs
