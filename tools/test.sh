#!/usr/bin/env bash
# The README's test command: set up the machine, run the whole test suite, and close with one
# summary line over all test binaries ("tests: N passed, M failed").
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
status=0
cargo test --workspace --locked --no-fail-fast 2>&1 | tee "$log" || status=$?
awk '/^test result:/ { passed += $4; failed += $6 } END { printf "tests: %d passed, %d failed\n", passed, failed }' "$log"
exit "$status"
