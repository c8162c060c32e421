#!/usr/bin/env bash
# libFuzzer (clang, AddressSanitizer and UndefinedBehaviorSanitizer) on the impact resolution,
# the time of impact, and the monitor's update cycle (the ROS layer's intake, time line and the
# core's step, driven by fuzzed scenes, states and stamps, under an allocation cap), each
# checking its invariants (fuzz/*.cpp). Built in the one clang sanitizer build (.ws/sanitizers)
# that scripts/sanitize.sh shares.
#   bash scripts/fuzz.sh [SECONDS]   each target for SECONDS (default 600), the three side by side
#   bash scripts/fuzz.sh --replay    each target runs every input it has (fuzz/regressions, the
#                                    corpus kept in .ws/fuzz) once, and stops: the full test
#                                    suite's check, a few seconds
# A short fuzzing run finds little (the monitor's target makes a few executions a second under
# the sanitizers): the suite replays, and a long run fuzzes (bash scripts/test.sh --long).
# Writes a JUnit result per target under .ws/build/test_results/fuzz (read by the test count);
# the corpora grow in .ws/fuzz and are kept between runs; fuzz/regressions holds the inputs
# that once broke an invariant, run first every time.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
replay=false
seconds=600
case "${1:-}" in
  --replay) replay=true ;;
  "") ;;
  *[!0-9]* | 0)
    echo "usage: bash scripts/fuzz.sh [SECONDS | --replay]" >&2
    exit 2
    ;;
  *) seconds=$1 ;;
esac
install_packages
out="$ws/fuzz"
results="$ws/build/test_results/fuzz"
# fuzz/regressions may hold no input yet (git keeps no empty folder): libFuzzer stops on a
# corpus folder that does not exist.
mkdir -p "$out" "$results" "$repo/fuzz/regressions"
targets=(fuzz_impact fuzz_time_of_impact fuzz_monitor)
build_sanitized "${targets[@]}"
declare -A runners
for target in "${targets[@]}"; do
  mkdir -p "$out/corpus-$target"
  limits=()
  if [ "$target" = fuzz_monitor ]; then
    # Bounded work per message: no single allocation of 256 MB, no 2 GB of memory, no input
    # slower than 120 s (under the sanitizers; the target also caps what one message
    # allocates, kAllocationCap).
    limits=(-malloc_limit_mb=256 -rss_limit_mb=2048 -timeout=120)
  fi
  if $replay; then
    echo "== $target: every input of fuzz/regressions and of its corpus, once"
    run=(-runs=0)
  else
    echo "== $target: fuzzing $seconds s"
    run=(-max_total_time="$seconds")
  fi
  (cd "$out" && ASAN_OPTIONS=detect_leaks=1 "$sanitized/devel/lib/collision_response/$target" \
    "${run[@]}" "${limits[@]}" -print_final_stats=1 "corpus-$target" "$repo/fuzz/regressions" \
    >"$out/$target.log" 2>&1) &
  runners[$target]=$!
done
status=0
for target in "${targets[@]}"; do
  rc=0
  wait "${runners[$target]}" || rc=$?
  runs=$(grep -E 'stat::number_of_executed_units' "$out/$target.log" | awk '{print $2}' | tail -1 || true)
  echo "   $target: exit $rc, ${runs:-0} executions"
  if $replay; then what="replay"; else what="$seconds s"; fi
  if [ $rc -eq 0 ]; then
    printf '<testsuite name="fuzz"><testcase classname="fuzz" name="%s (%s, %s executions)"/></testsuite>\n' \
      "$target" "$what" "${runs:-0}" >"$results/fuzz-$target.xml"
  else
    status=1
    detail=$(grep -E 'invariant broken|ERROR|SUMMARY|crash-|No such' "$out/$target.log" | head -5 | sed 's/[<>&"]/_/g' || true)
    printf '<testsuite name="fuzz"><testcase classname="fuzz" name="%s"><failure message="%s"/></testcase></testsuite>\n' \
      "$target" "$detail" >"$results/fuzz-$target.xml"
    tail -20 "$out/$target.log"
  fi
done
exit $status
