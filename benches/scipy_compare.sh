#!/usr/bin/env bash
# squeal `arpack` vs SciPy `eigs` on the same exported frictional operator.
#
#   benches/scipy_compare.sh [--mu MU] [--tol TOL] [--scene SCENE] [--out DIR]
#
# 1. creates a venv under target/scipy-venv (python3 -m venv; pip install numpy scipy);
# 2. `squeal export --mu MU --out DIR [SCENE]` (the operator at the sliding equilibrium);
# 3. `squeal stability --operator DIR --mu MU --eigen arpack --json DIR/squeal.json`;
# 4. benches/scipy_compare.py: squeal's band (the scene's study.band_hz) with
#    scipy.sparse.linalg.eigs shift-invert, DIR/scipy.json, and a side-by-side table.
# Defaults: MU 0.7, TOL 1e-12 (both solvers), the default scene (pin-on-disc),
# DIR target/scipy-compare.
# Honours CARGO_TARGET_DIR (the venv and the default DIR live under it).
set -euo pipefail

mu=0.7
tol=1e-12
scene=""
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --mu) mu="$2"; shift 2 ;;
    --tol) tol="$2"; shift 2 ;;
    --scene) scene="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "unknown argument: $1 (see --help)" >&2; exit 2 ;;
  esac
done

root="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
out="${out:-$target/scipy-compare}"
venv="$target/scipy-venv"
mkdir -p "$out"
out="$(cd "$out" && pwd)"

# --- Python environment ---------------------------------------------------------------
if ! command -v python3 >/dev/null 2>&1; then
  echo "python3 not found: apt-get install -y python3 python3-venv" >&2
  exit 1
fi
if [ ! -x "$venv/bin/python" ]; then
  if ! python3 -m venv --help >/dev/null 2>&1 || ! python3 -m venv "$venv"; then
    rm -rf "$venv"
    echo "python3 -m venv is not available: apt-get install -y python3-venv" >&2
    exit 1
  fi
fi
if ! "$venv/bin/python" -c "import numpy, scipy" >/dev/null 2>&1; then
  "$venv/bin/python" -m pip install --quiet --upgrade pip
  "$venv/bin/python" -m pip install --quiet numpy scipy
fi

# --- squeal: export and full-order solve ----------------------------------------------
cd "$root"
cargo build --release --quiet -p squeal-cli
squeal="$target/release/squeal"
# shellcheck disable=SC2086 # an empty scene means the default one
"$squeal" export ${scene:+"$scene"} --mu "$mu" --out "$out"
echo "squeal stability --operator $out --mu $mu --tol $tol --eigen arpack ..." >&2
"$squeal" stability --operator "$out" --mu "$mu" --tol "$tol" --eigen arpack --json "$out/squeal.json" \
  >"$out/squeal-stability.txt"

# --- SciPy on the same operator --------------------------------------------------------
# single-threaded BLAS would be SciPy's usual setting for splu (SuperLU is serial anyway)
"$venv/bin/python" "$root/benches/scipy_compare.py" "$out" --mu "$mu" --tol "$tol" \
  --squeal-json "$out/squeal.json" --out "$out/scipy.json" | tee "$out/comparison.txt"
