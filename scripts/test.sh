#!/usr/bin/env bash
# The project's test command (README, .ci/run): set-up, then every test of the workspace
# in release mode (the FE and eigen tests are numerical and want optimized code).
# The tests on the 4018-DOF parametric operators regenerate them with numpy and scipy
# (benches/parametric_operator.py): Debian's python3-scipy is installed when no Python
# on the machine has them.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
has_scipy() { "$1" -c "import numpy, scipy" >/dev/null 2>&1; }
if [ -z "${SQUEAL_PYTHON:-}" ] && ! has_scipy python3 && ! has_scipy /usr/bin/python3; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "test: installing python3-scipy (the parametric operators' generator)" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq python3-scipy >/dev/null
fi
cargo test --workspace --release --no-fail-fast "$@"
