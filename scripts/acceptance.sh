#!/usr/bin/env bash
# The bases' acceptance on the default scene (slow, 10-25 minutes; run it alone on the machine):
# `enriched` and `residue` against full-order `arpack` at mu = 0.3, 0.36 and 0.7, with the
# table of sizes, times, errors, backward errors and speed-ups (tests/bases.rs).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release --test bases -- --ignored --nocapture "$@"
