#!/usr/bin/env bash
# What each effect costs: Google Benchmark CPU time per impact and per state update, effects on
# versus off; and instructions (valgrind callgrind, free of timing noise) of the same workload
# with every effect off, in this build and in the core built so that no effect can run
# (effect_selection_none.cpp instead of effect_selection.cpp).
# Writes doc/effects.md.
#   bash scripts/bench_effects.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PACKAGES+=(libbenchmark-dev valgrind)
install_packages
build_workspace >"$ws/build.log" 2>&1 || { tail -40 "$ws/build.log"; exit 1; }
cmake --build "$ws/build" --target bench_effects effects_instructions \
  effects_instructions_noeffects -- -j2 >>"$ws/build.log" 2>&1
bin="$ws/devel/lib/collision_response"
out="$ws/bench"
mkdir -p "$out"
echo "== Google Benchmark (5 repetitions, medians)"
"$bin/bench_effects" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_format=json --benchmark_out="$out/bench_effects.json" >/dev/null
echo "== instruction counts (callgrind)"
for build in effects_instructions effects_instructions_noeffects; do
  for workload in impacts updates; do
    valgrind --tool=callgrind --callgrind-out-file="$out/$build-$workload.callgrind" \
      "$bin/$build" "$workload" >/dev/null 2>"$out/$build-$workload.log"
    grep -E 'Collected' "$out/$build-$workload.log" | awk '{print $NF}' >"$out/$build-$workload.count"
  done
done
/usr/bin/python3 "$repo/scripts/effects_report.py" "$out" "$repo/doc/effects.md"
cat "$repo/doc/effects.md"
