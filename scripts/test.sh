#!/usr/bin/env bash
# The project's test command (README, .ci/run): set-up, then every test of the workspace
# in release mode (the FE and eigen tests are numerical and want optimized code).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo test --workspace --release --no-fail-fast "$@"
