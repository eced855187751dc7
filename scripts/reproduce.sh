#!/usr/bin/env bash
# Regenerates one result of the README: `bash scripts/reproduce.sh NAME`, from the
# repository root, after `bash scripts/setup.sh`. Each writes into out/NAME (a run that is
# interrupted continues with the same command: the long ones resume). Times are for the
# 2-core machine the figures of docs/results.md were measured on.
#
#   validate        the main job: Table 2, the rig, equilibria, Figure 5, bases vs full order
#   calibrate-rig   the pin assembly fitted to the paper's datum, pin modes and couplings (~2 h)
#   calibrate-disc  the disc fitted to Table 2
#   macro           macroscopic zones at mu 0.36 and 0.43: centred a-sweep (b = 14.2 mm) and
#                   off-centre zones
#   meso-c2         mesoscopic plateaus in the coupling-2 region (0.2 mm grid), 70 % of the
#                   patches in contact
#   meso-c2-f0.5    the same with 50 % of the patches in contact, 60 layouts per size
#   meso-c1         mesoscopic plateaus in the coupling-1 region (0.5 mm grid)
#   fraction        the unstable share against the fraction of patches in contact, both
#                   couplings, one patch size each (1 mm and 2 mm), 10 layouts per fraction
#   bench           every basis x eigen solver at mu 0.3 and 0.7 against full order
#   stress          the stress set (cases built to break methods)
#   brake           the brake-like 4018-DOF operator (indefinite symmetric stiffness, a
#                   weakly unstable mode): every basis with its [modal] pair and with the
#                   pair squeal builds, and the sweep of W (needs Python with numpy, scipy)
#
# Extra arguments are passed to the command (e.g. `--jobs 1`, `--shard 1/2`; for `brake`,
# to its two benches).
set -euo pipefail
cd "$(dirname "$0")/.."
name=${1:-}
shift || true
cargo build --release -p squeal-cli
squeal=target/release/squeal
resume=()
case "$name" in
  validate)
    [ -d out/validate ] && resume=(--resume)
    $squeal validate --out out/validate "${resume[@]}" "$@" ;;
  calibrate-rig)
    $squeal calibrate examples/calibrate/rig.toml --out out/calibrate-rig "$@" ;;
  calibrate-disc)
    $squeal calibrate examples/calibrate/disc.toml --out out/calibrate-disc "$@" ;;
  macro)
    [ -d out/macro-centred ] && resume=(--resume)
    $squeal sweep macro pin-on-disc --x0 centred --y0 centred --a 0.004:0.02:0.002 \
      --b 0.0142 --mu 0.36,0.43 --basis cms --basis-opt projection=pairs --jobs 2 \
      --out out/macro-centred "${resume[@]}" "$@"
    resume=()
    [ -d out/macro-grid ] && resume=(--resume)
    $squeal sweep macro pin-on-disc --x0 0:0.016:0.004 --y0 centred --a 0.004:0.02:0.004 \
      --b 0.004:0.02:0.004 --mu 0.36,0.43 --basis cms --basis-opt projection=pairs --jobs 2 \
      --out out/macro-grid \
      "${resume[@]}" "$@" ;;
  meso-c2)
    [ -d out/meso-c2 ] && resume=(--resume)
    $squeal sweep meso scenes/pin-on-disc-meso.toml --coupling 2 --basis cms --jobs 2 \
      --out out/meso-c2 "${resume[@]}" "$@" ;;
  meso-c2-f0.5)
    [ -d out/meso-c2-f0.5 ] && resume=(--resume)
    $squeal sweep meso scenes/pin-on-disc-meso.toml --coupling 2 --basis cms --jobs 2 \
      --fraction 0.5 --layouts 60 --out out/meso-c2-f0.5 "${resume[@]}" "$@" ;;
  meso-c1)
    [ -d out/meso-c1 ] && resume=(--resume)
    $squeal sweep meso scenes/pin-on-disc-meso-c1.toml --coupling 1 --basis cms --jobs 2 \
      --out out/meso-c1 "${resume[@]}" "$@" ;;
  fraction)
    # 0.7 is the meso studies' fraction: their first 10 layouts of 1 mm (coupling 2) and
    # 2 mm (coupling 1) are these layouts at 0.7 (the layouts are nested across fractions)
    for f in 0.3 0.4 0.5 0.6 0.8; do
      for c in 2 1; do
        if [ $c = 2 ]; then scene=scenes/pin-on-disc-meso.toml; patch=0.001
        else scene=scenes/pin-on-disc-meso-c1.toml; patch=0.002; fi
        resume=()
        [ -d out/fraction-c$c/f$f ] && resume=(--resume)
        $squeal sweep meso $scene --coupling $c --patch $patch --layouts 10 --fraction $f \
          --basis cms --no-charts --out out/fraction-c$c/f$f "${resume[@]}" "$@"
      done
    done ;;
  bench)
    $squeal bench pin-on-disc --mu 0.3,0.7 --out out/bench "$@" ;;
  stress)
    $squeal bench pin-on-disc --stress --vary none --out out/stress "$@" ;;
  brake)
    py=${SQUEAL_PYTHON:-python3}
    "$py" -c "import numpy, scipy" 2>/dev/null || py=/usr/bin/python3
    mkdir -p out/brake
    "$py" benches/parametric_operator.py brake out/brake/operator
    "$py" benches/parametric_operator.py brake out/brake/operator-sym --no-modal
    $squeal stability --operator out/brake/operator --param W=60 --mu 0 --band 0:500 \
      --json out/brake/stability-w60.json
    for op in operator operator-sym; do
      $squeal bench --operator out/brake/$op --param W=60 --mu 0,0.3 --band 0:500 \
        --out out/brake/bench-$op "$@"
    done
    resume=()
    [ -d out/brake/sweep-w ] && resume=(--resume)
    $squeal sweep param --operator out/brake/operator-sym --param W --from 45 --to 100 \
      --step 5 --mu 0 --band 100:300 --out out/brake/sweep-w "${resume[@]}" ;;
  *)
    sed -n '2,24p' "$0"
    exit 2 ;;
esac
