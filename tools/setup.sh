#!/usr/bin/env bash
# Installs the system packages yarnhom needs on a fresh Debian machine (idempotent, quiet when
# everything is there): libhdf5 for the HDF5 export; h5py, the official MCAP reader and the rerun
# CLI (pinned: the rerun crate 0.36 writes what rerun-sdk 0.41 verifies) for the interop tests.
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

if ! python3 -c "import mcap, msgpack, zstandard" 2>/dev/null; then
  echo "setup: installing the MCAP Python library (mcap, msgpack) from PyPI" >&2
  python3 -m pip install --quiet --disable-pip-version-check "mcap==1.6.0" msgpack zstandard ||
    echo "setup: warning: mcap could not be installed; the MCAP interop test will report SKIPPED" >&2
fi

# (sed reads the whole output: `grep -q` would stop early and, under pipefail, fail the check.)
if [ "$(python3 -m pip show rerun-sdk 2>/dev/null | sed -n 's/^Version: //p')" != "0.41.0" ]; then
  echo "setup: installing the rerun CLI (rerun-sdk 0.41.0) from PyPI" >&2
  python3 -m pip install --quiet --disable-pip-version-check "rerun-sdk==0.41.0" ||
    echo "setup: warning: rerun-sdk could not be installed; the rerun interop test will report SKIPPED" >&2
fi
