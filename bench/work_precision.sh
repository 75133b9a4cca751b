#!/usr/bin/env bash
# Regenerates the whole work-precision report: builds the harness, runs it
# (bench/work_precision.json: every scene, integrator x linear solver x step or
# tolerance, then the scaling run), and plots the CSV files to PNG.
#
#   bench/work_precision.sh [CONFIG.json [OUT_DIR]]     (defaults below)
#
# Output in OUT_DIR: work_precision.csv, scaling.csv, work_precision_*.png,
# scaling.png, summary.md, work_precision.log. About 5 minutes today on the
# 2-core machine; one thread per run.
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-bench/work_precision.json}
out=${2:-bench/results}
build=${BUILD_DIR:-build}
mkdir -p "$out"
cmake -S . -B "$build" > /dev/null
cmake --build "$build" -j2 --target work_precision
echo "work_precision: running $config (progress in $out/work_precision.log)"
"$build/bin/work_precision" --config "$config" --out "$out" 2> "$out/work_precision.log"
# Debian's interpreter, where python3-matplotlib is installed.
python=/usr/bin/python3
[ -x "$python" ] || python=python3
"$python" bench/plot_work_precision.py "$out"
