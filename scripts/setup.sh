#!/usr/bin/env bash
# Installs what squeal needs on a fresh Debian machine that has only Rust:
# ARPACK-NG (libarpack2-dev), an optimized BLAS/LAPACK for it (OpenBLAS,
# libopenblas0-pthread, which Debian then selects over the reference BLAS) and pkg-config.
# Idempotent; uses sudo when not root.
set -euo pipefail
need=()
pkg-config --exists arpack 2>/dev/null || need+=(libarpack2-dev)
[ -e /usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3 ] \
  || ls /usr/lib/*/openblas-pthread/libblas.so.3 >/dev/null 2>&1 || need+=(libopenblas0-pthread)
command -v pkg-config >/dev/null 2>&1 || need+=(pkg-config)
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing ${need[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
fi
