#!/usr/bin/env bash
# squeal `arpack` vs SLEPc (Krylov-Schur, MUMPS shift-and-invert) on the same exported
# frictional operator.
#
#   benches/slepc_compare.sh [--mu MU] [--tol TOL] [--scene SCENE] [--ordering NAME]
#                            [--procs N] [--out DIR]
#
# 1. installs Debian's python3-slepc4py-real and python3-scipy when /usr/bin/python3 cannot
#    `import slepc4py, scipy` (apt-get, as root or through sudo);
# 2. `squeal export --mu MU --out DIR [SCENE]` (the operator at the sliding equilibrium);
# 3. `squeal stability --operator DIR --mu MU --eigen arpack --json DIR/squeal.json`;
# 4. benches/slepc_compare.py: squeal's band (the scene's study.band_hz), windows and
#    tolerance with SLEPc, DIR/slepc.json, and a side-by-side table
#    (DIR/comparison-slepc.txt).
# Defaults: MU 0.7, TOL 1e-12 (both solvers), the default scene (pin-on-disc), ORDERING auto
# (MUMPS ICNTL(7); also amd, amf, scotch, pord, metis, qamd: one missing from Debian's
# MUMPS falls back, and the one used is printed), N 1, DIR target/slepc-compare.
# --procs N > 1 runs SLEPc under `mpiexec -n N` (Debian's openmpi-bin, installed when
# missing), each process with cores / N BLAS threads; with one process the BLAS threads
# take every core.
# MUMPS's dense kernels use the system BLAS: scripts/setup.sh's OpenBLAS (the reference BLAS
# makes its factorization about 6x slower). Honours CARGO_TARGET_DIR (the default DIR lives
# under it).
set -euo pipefail

mu=0.7
tol=1e-12
scene=""
out=""
ordering=auto
procs=1
while [ $# -gt 0 ]; do
  case "$1" in
    --mu) mu="$2"; shift 2 ;;
    --tol) tol="$2"; shift 2 ;;
    --scene) scene="$2"; shift 2 ;;
    --ordering) ordering="$2"; shift 2 ;;
    --procs) procs="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "unknown argument: $1 (see --help)" >&2; exit 2 ;;
  esac
done

case "$procs" in
  ''|*[!0-9]*|0) echo "--procs: expected a number of MPI processes >= 1, got '$procs'" >&2; exit 2 ;;
esac

root="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
out="${out:-$target/slepc-compare}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"

# --- SLEPc from Debian -----------------------------------------------------------------
# Debian's petsc4py/slepc4py belong to the system interpreter, and find their libraries
# through /usr/lib/petsc and /usr/lib/slepc (set by the -dev packages) or PETSC_DIR and
# SLEPC_DIR, set here from the real-scalar builds when those links are absent.
py=/usr/bin/python3
petsc_env() {
  [ -e /usr/lib/petsc ] || export PETSC_DIR="${PETSC_DIR:-$(ls -d /usr/lib/petscdir/petsc*/*-real 2>/dev/null | tail -n1)}"
  [ -e /usr/lib/slepc ] || export SLEPC_DIR="${SLEPC_DIR:-$(ls -d /usr/lib/slepcdir/slepc*/*-real 2>/dev/null | tail -n1)}"
}
# Debian packages, as root or through sudo
apt_install() {
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  echo "installing $* (apt-get)" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "$@" >/dev/null
}
petsc_env
if ! "$py" -c "import slepc4py, petsc4py, scipy" >/dev/null 2>&1; then
  apt_install python3-slepc4py-real python3-scipy
  petsc_env
fi
launch=("$py")
if [ "$procs" -gt 1 ]; then
  command -v mpiexec >/dev/null 2>&1 || apt_install openmpi-bin
  threads=$(( $(nproc) / procs ))
  [ "$threads" -ge 1 ] || threads=1
  export OPENBLAS_NUM_THREADS="$threads" OMP_NUM_THREADS="$threads"
  root_ok=()
  [ "$(id -u)" -eq 0 ] && root_ok=(--allow-run-as-root)
  launch=(mpiexec "${root_ok[@]}" --oversubscribe -n "$procs" "$py")
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

# --- SLEPc on the same operator ----------------------------------------------------------
"${launch[@]}" "$root/benches/slepc_compare.py" "$out" --mu "$mu" --tol "$tol" --ordering "$ordering" \
  --squeal-json "$out/squeal.json" --out "$out/slepc.json" | tee "$out/comparison-slepc.txt"
