#!/usr/bin/env bash
# How the cost of squeal's workloads grows with the model: each workload on the three
# embedded sizes of the rig (pin-on-disc-coarse, pin-on-disc, pin-on-disc-paper), its
# wall time and peak memory, and the exponent p of the power law t ~ DOFs^p fitted to
# the three points (least squares in log-log).
#
#   benches/scaling.sh [--out DIR] [--mu MU] [--validate DIR] [--table-only]
#
# Workloads: `squeal stability SCENE --mu MU` at full order (arpack) and through each
# basis `cms`, `enriched`, `residue` (one contact set, model build and equilibrium
# included). With --validate DIR, `squeal validate` is read from the `time_s` and
# `peak_rss_mb` of DIR/<scene>/report.json (written by `squeal validate SCENE --out
# DIR/<scene>`; the main job is too long to run here). Writes DIR/runs.tsv (one line per
# run) and DIR/table.md (the table of benches/README.md); --table-only rewrites the table
# from DIR/runs.tsv. Defaults: MU 0.3, DIR target/scaling.
# Honours CARGO_TARGET_DIR. Run it on an otherwise idle machine.
set -euo pipefail

mu=0.3
out=""
validate=""
table_only=0
while [ $# -gt 0 ]; do
  case "$1" in
    --mu) mu="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --validate) validate="$2"; shift 2 ;;
    --table-only) table_only=1; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "unknown argument: $1 (see --help)" >&2; exit 2 ;;
  esac
done

root="$(cd "$(dirname "$0")/.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
out="${out:-$target/scaling}"
mkdir -p "$out"
cd "$root"
runs="$out/runs.tsv"
if [ "$table_only" = 0 ]; then
  cargo build --release -p squeal-cli
  squeal="$target/release/squeal"
  [ -x /usr/bin/time ] || { echo "/usr/bin/time not found: apt-get install -y time" >&2; exit 1; }

  scenes=(pin-on-disc-coarse pin-on-disc pin-on-disc-paper)
  printf 'workload\tscene\tdofs\ttime_s\tpeak_rss_mb\n' > "$runs"

  dofs_of() {
    "$squeal" scene list | awk -v s="$1" '$1 == s { print $2 }'
  }

  for scene in "${scenes[@]}"; do
    n=$(dofs_of "$scene")
    [ -n "$n" ] || { echo "scene $scene not found by \`squeal scene list\`" >&2; exit 1; }
    for basis in none cms enriched residue; do
      name="stability-$basis"
      log="$out/$name-$scene.log"
      /usr/bin/time -f '%e %M' -o "$out/time.txt" \
        "$squeal" stability "$scene" --mu "$mu" --basis "$basis" \
        --json "$out/$name-$scene.json" > "$log" 2>&1
      read -r t kb < "$out/time.txt"
      printf '%s\t%s\t%s\t%s\t%.0f\n' "$name" "$scene" "$n" "$t" "$(echo "$kb / 1024" | bc -l)" >> "$runs"
      echo "$name $scene ($n DOFs): $t s, $((kb / 1024)) MB"
    done
    if [ -n "$validate" ] && [ -f "$validate/$scene/report.json" ]; then
      python3 -c 'import json, sys
r = json.load(open(sys.argv[1]))
print("validate\t%s\t%s\t%.1f\t%.0f" % (sys.argv[2], sys.argv[3], r["time_s"], r["peak_rss_mb"]))' \
        "$validate/$scene/report.json" "$scene" "$n" >> "$runs"
    fi
  done
fi

# the table: one row per workload, the fitted exponent of t ~ n^p over its sizes
awk -F'\t' '
  NR == 1 { next }
  {
    w = $1; k = ++count[w]; n[w, k] = $3; t[w, k] = $4; m[w, k] = $5
    if (!(w in seen)) { seen[w] = 1; order[++nw] = w }
  }
  END {
    printf "| workload | coarse | default | paper preset | p, all sizes | p, default to paper |\n"
    printf "|---|---|---|---|---|---|\n"
    for (i = 1; i <= nw; i++) {
      w = order[i]; sx = sy = sxx = sxy = 0; c = count[w]; row = ""
      for (k = 1; k <= c; k++) {
        x = log(n[w, k]); y = log(t[w, k])
        sx += x; sy += y; sxx += x * x; sxy += x * y
        row = row sprintf(" %.1f s, %s MB (%d DOFs) |", t[w, k], m[w, k], n[w, k])
      }
      for (k = c + 1; k <= 3; k++) row = row " not run |"
      p = (c >= 2) ? sprintf("%.2f", (c * sxy - sx * sy) / (c * sxx - sx * sx)) : "-"
      q = (c >= 3) ? sprintf("%.2f", log(t[w, c] / t[w, c - 1]) / log(n[w, c] / n[w, c - 1])) : "-"
      printf "| `%s` |%s %s | %s |\n", w, row, p, q
    }
  }' "$runs" > "$out/table.md"
cat "$out/table.md"
