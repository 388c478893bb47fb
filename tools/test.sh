#!/usr/bin/env bash
# The README's test command: set up the machine, then run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cargo test --workspace --locked
