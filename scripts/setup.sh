#!/usr/bin/env bash
# Installs groovetrace's build and test dependencies from Debian's packages.
# Quick when everything is already there: apt is only called for missing packages.
set -euo pipefail
pkgs=(build-essential cmake pkg-config
      libpcl-dev libeigen3-dev libomp-dev
      pocl-opencl-icd ocl-icd-opencl-dev opencl-clhpp-headers opencl-c-headers clinfo
      libgtest-dev libgmock-dev libbenchmark-dev clang-format
      libcli11-dev nlohmann-json3-dev libyaml-cpp-dev libpng-dev
      python3-numpy python3-matplotlib chromium
      munge slurm-wlm)
# munge and slurm-wlm (slurmctld, slurmd, the client commands) are for tests/slurm, which starts
# its own munged, slurmctld and slurmd with their own key, sockets, ports and configuration:
# daemons the packages may start on a host with an init system neither serve nor disturb it.
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#pkgs[@]} dependencies present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO apt-get update -q
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
