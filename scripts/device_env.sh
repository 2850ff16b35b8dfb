# device_env.sh: sourced by the checks run on a lent GPU machine (scripts/device_check.sh,
# scripts/device_check_objects.sh; docs/performance.md, "On a GPU"). device_env WORK: when
# scripts/device_bundle.sh's .devlibs/ is here, sets bin and tests to its binaries, their
# libraries on LD_LIBRARY_PATH, and names the machine's own NVIDIA OpenCL driver (lib) to the ICD
# loader through a vendors folder under WORK; returns 1 when there is no bundle (bin and tests
# keep the caller's). device_gpu DEVICES: the first GPU's index in `ppbench devices` output
# DEVICES, or $PPB_CHECK_DEVICE (a dry run on any machine).
device_env() {
  [ -x .devlibs/bin/ppbench ] || return 1
  bin=.devlibs/bin/ppbench tests=.devlibs/bin
  export LD_LIBRARY_PATH=$PWD/.devlibs/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  export PPBENCH_SOURCE=$PWD
  lib=$(find /usr/local/nvidia /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib -maxdepth 3 \
          -name 'libnvidia-opencl.so*' 2>/dev/null | head -1)
  if [ -n "$lib" ]; then
    mkdir -p "$1/vendors" && echo "$lib" > "$1/vendors/nvidia.icd"
    export OCL_ICD_VENDORS=$1/vendors
  fi
  return 0
}
device_gpu() {
  echo "${PPB_CHECK_DEVICE:-$(grep -i -m1 -E 'nvidia|cuda|amd|gpu' "$1" | sed 's/^ *\([0-9]*\).*/\1/')}"
}
