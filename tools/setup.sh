#!/usr/bin/env bash
# Installs the system packages yarnhom needs on a fresh Debian machine (idempotent, quiet when
# everything is there): libhdf5 for the HDF5 export, and h5py for the interop test.
set -euo pipefail

missing=()
for pkg in libhdf5-dev pkg-config; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if ((${#missing[@]})); then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  echo "setup: installing ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}" >/dev/null
fi

if ! python3 -c "import h5py, numpy" 2>/dev/null; then
  echo "setup: installing h5py and numpy from PyPI" >&2
  python3 -m pip install --quiet --disable-pip-version-check h5py numpy ||
    echo "setup: warning: h5py could not be installed; the h5py interop test will report SKIPPED" >&2
fi
