#!/usr/bin/env bash
# Checks every dependency ppbench needs (Debian 12 packages) and installs the missing ones with
# apt-get when run as root; otherwise prints the exact command and fails. Writes nothing else.
# --cluster: only what tests/cluster.sh needs besides, a real Slurm cluster on this host
# (slurm-wlm: slurmctld, slurmd, sbatch; munge: munged), never needed to build or run ppbench.
set -euo pipefail

# pkg-config module -> Debian package
declare -A PC=(
  [OpenCL]=ocl-icd-opencl-dev [lapacke]=liblapacke-dev [openblas]=libopenblas-dev
  [OpenEXR]=libopenexr-dev [libpng]=libpng-dev [inih]=libinih-dev [cmocka]=libcmocka-dev
  [libxxhash]=libxxhash-dev [jansson]=libjansson-dev [liblzma]=liblzma-dev
)
# file or command -> Debian package
declare -A FILES=(
  [/usr/include/CL/cl.h]=opencl-headers
  [/usr/include/Random123/philox.h]=librandom123-dev
  [/etc/OpenCL/vendors/pocl.icd]=pocl-opencl-icd
)
declare -A CMDS=([pkg-config]=pkg-config [xz]=xz-utils [gnuplot]=gnuplot-nox [parallel]=parallel
  [clinfo]=clinfo [clang]=clang) # clang: `make fuzz` (libFuzzer)
if [ "${1:-}" = --cluster ]; then
  declare -A PC=() FILES=()
  declare -A CMDS=([slurmctld]=slurm-wlm [slurmd]=slurm-wlm [sbatch]=slurm-wlm [munged]=munge)
  export PATH=$PATH:/usr/sbin:/sbin
fi

missing=()
for c in "${!CMDS[@]}"; do command -v "$c" >/dev/null 2>&1 || missing+=("${CMDS[$c]}"); done
for f in "${!FILES[@]}"; do [ -e "$f" ] || missing+=("${FILES[$f]}"); done
if command -v pkg-config >/dev/null 2>&1; then
  for m in "${!PC[@]}"; do pkg-config --exists "$m" || missing+=("${PC[$m]}"); done
else
  missing+=("${PC[@]}")
fi
[ ${#missing[@]} -eq 0 ] && exit 0

mapfile -t missing < <(printf '%s\n' "${missing[@]}" | sort -u)
# Two builds at once (make -j, worktrees side by side) would race for dpkg's lock: the second
# waits for it rather than failing (and for our own lock first, so one install runs at a time).
cmd="apt-get -o DPkg::Lock::Timeout=900 install -y --no-install-recommends ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "ppbench: missing packages: ${missing[*]}" >&2
  echo "ppbench: install them with: sudo apt-get update && sudo $cmd" >&2
  exit 1
fi
echo "ppbench: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
exec 9>/var/lock/ppbench-deps.lock
flock -w 1800 9 || { echo "ppbench: another install holds /var/lock/ppbench-deps.lock" >&2; exit 1; }
apt-get -o DPkg::Lock::Timeout=900 update -qq >&2
$cmd >&2
