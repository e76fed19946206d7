#!/usr/bin/env bash
# Installs grainlab's build and test dependencies from Debian's packages.
# Idempotent: does nothing (and needs no network) when everything is present.
set -euo pipefail
PKGS=(build-essential cmake pkg-config libeigen3-dev libtomlplusplus-dev libcli11-dev
      libfmt-dev libspdlog-dev nlohmann-json3-dev libgtest-dev
      python3 python3-numpy python3-matplotlib python3-pytest python3-pytest-xdist python3-meshio
      libboost-dev)  # libboost-dev: header-only Boost.Math (Gauss–Legendre rules, micromechanics)
# Checksums of checkpoints and packing files (xxHash), for the program and the Python readers.
PKGS+=(libxxhash-dev python3-xxhash)
# grainlab calibrate (NLopt optimisers) and --scheduler (Dask distributed).
PKGS+=(python3-nlopt python3-distributed)
# The Python module (pybind11, headers of /usr/bin/python3) and Result.dataframe() (pandas).
PKGS+=(pybind11-dev python3-dev python3-pandas)
# Vectorised kernels with run-time dispatch (Google Highway).
PKGS+=(libhwy-dev)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "install-deps: installing ${missing[*]}" >&2
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
