#!/usr/bin/env bash
# What accuracy costs in time: every scene of bench/accuracy at every setting (our continuous
# and discrete detection at 10..1000 Hz, effects on and off; Bullet with its defaults and with
# its recommended bouncing settings; ODE), errors against exact answers and CPU time (Google
# Benchmark), written to doc/accuracy.md and doc/accuracy.png.
#   bash scripts/accuracy.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PACKAGES+=(libbenchmark-dev libbullet-dev libode-dev pkg-config gnuplot-nox)
install_packages
build_workspace >"$ws/build.log" 2>&1 || { tail -40 "$ws/build.log"; exit 1; }
cmake --build "$ws/build" --target accuracy_benchmark -- -j2 >>"$ws/build.log" 2>&1 ||
  { tail -40 "$ws/build.log"; exit 1; }
out="$ws/accuracy"
mkdir -p "$out"
echo "== running every scene at every setting (errors, then CPU time)"
"$ws/devel/lib/collision_response/accuracy_benchmark" "$out/errors.json" \
  --benchmark_format=json --benchmark_out="$out/timing.json" >"$out/benchmark.log" 2>&1
/usr/bin/python3 "$repo/scripts/accuracy_report.py" "$out" "$repo/doc"
gnuplot "$out/accuracy.gnuplot"
echo "== wrote doc/accuracy.md and doc/accuracy.png"
