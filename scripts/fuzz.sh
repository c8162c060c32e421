#!/usr/bin/env bash
# libFuzzer (clang, AddressSanitizer and UndefinedBehaviorSanitizer) on the impact resolution,
# the time of impact, and the monitor's update cycle (the ROS layer's intake, time line and the
# core's step, driven by fuzzed scenes, states and stamps, under an allocation cap), each
# checking its invariants (fuzz/*.cpp).
#   bash scripts/fuzz.sh [seconds per target, default 30]      e.g. bash scripts/fuzz.sh 600
# The three targets run side by side, each for that long.
# Writes a JUnit result per target under .ws/build/test_results/fuzz (read by the test count);
# the corpora grow in .ws/fuzz and are kept between runs; fuzz/regressions holds the inputs
# that once broke an invariant, run first every time.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
seconds="${1:-30}"
PACKAGES+=(clang libclang-rt-14-dev)
install_packages
out="$ws/fuzz"
results="$ws/build/test_results/fuzz"
# fuzz/regressions may hold no input yet (git keeps no empty folder): libFuzzer stops on a
# corpus folder that does not exist.
mkdir -p "$out" "$results" "$repo/fuzz/regressions"
# The monitor's target needs the generated message headers of a built workspace.
[ -f "$ws/devel/include/collision_response/BodyState.h" ] || build_workspace >"$ws/fuzz-build.log" 2>&1
# -g1: line tables only, enough for the sanitizers' reports; a quarter less compile time than -g.
flags=(-std=c++17 -O1 -g1 -Wall -Wextra -fsanitize=fuzzer-no-link,address,undefined
  -fno-sanitize-recover=undefined -I "$repo/include" -I "$repo/src/core" -isystem /usr/include/eigen3
  -isystem "$ws/devel/include" -isystem /usr/include/xmlrpcpp)
echo "== building the core with clang -fsanitize=fuzzer-no-link,address,undefined"
mkdir -p "$out/core"
objects=()
# At most two compiles at a time: under ASan a heavy file takes over a gigabyte, and the full
# suite runs this beside the sanitizer build.
two_at_a_time() { while [ "$(jobs -rp | wc -l)" -ge 2 ]; do wait -n || true; done; }
for source in "$repo"/src/core/*/*.cpp; do
  # The product's core: effect_selection_none.cpp is the benchmark's reference build instead.
  [ "$(basename "$source")" = effect_selection_none.cpp ] && continue
  object="$out/core/$(basename "$source" .cpp).o"
  objects+=("$object")
  two_at_a_time
  [ "$object" -nt "$source" ] &&
    [ -z "$(find "$repo/include" "$repo/src/core" -name '*.h' -newer "$object" -print -quit)" ] ||
    clang++ "${flags[@]}" -c "$source" -o "$object" &
done
# The pure part of the ROS layer that the monitor's target drives (no node, no master).
mkdir -p "$out/ros"
for name in conversions frame_motion monitor_cycle state_intake time_line; do
  source="$repo/src/ros/$name.cpp"
  object="$out/ros/$name.o"
  two_at_a_time
  [ "$object" -nt "$source" ] && [ -z "$(find "$repo/include" -newer "$object" -print -quit)" ] ||
    clang++ "${flags[@]}" -c "$source" -o "$object" &
done
wait
# Each target built, then all three run side by side (each one process, for `seconds`).
targets=(fuzz_impact fuzz_time_of_impact fuzz_monitor)
declare -A limits
for target in "${targets[@]}"; do
  echo "== $target: building"
  extra=()
  limits[$target]=""
  if [ "$target" = fuzz_monitor ]; then
    extra=("$out"/ros/*.o -ltf2 -lrostime -lcpp_common -lconsole_bridge -lxmlrpcpp)
    # Bounded work per message: no single allocation of 256 MB, no 2 GB of memory, no input
    # slower than 120 s (under the sanitizers; the target also caps what one message
    # allocates, kAllocationCap).
    limits[$target]="-malloc_limit_mb=256 -rss_limit_mb=2048 -timeout=120"
  fi
  clang++ "${flags[@]}" -fsanitize=fuzzer "$repo/fuzz/$target.cpp" "${objects[@]}" "${extra[@]}" \
    -o "$out/$target" &
done
wait
declare -A runners
for target in "${targets[@]}"; do
  mkdir -p "$out/corpus-$target"
  echo "== $target: running $seconds s"
  # shellcheck disable=SC2086  # the limits are separate words
  (cd "$out" && ASAN_OPTIONS=detect_leaks=1 ./"$target" -max_total_time="$seconds" ${limits[$target]} \
    -print_final_stats=1 "corpus-$target" "$repo/fuzz/regressions" >"$out/$target.log" 2>&1) &
  runners[$target]=$!
done
status=0
for target in "${targets[@]}"; do
  rc=0
  wait "${runners[$target]}" || rc=$?
  runs=$(grep -E 'stat::number_of_executed_units' "$out/$target.log" | awk '{print $2}' | tail -1 || true)
  echo "   $target: exit $rc, ${runs:-0} executions"
  if [ $rc -eq 0 ]; then
    printf '<testsuite name="fuzz"><testcase classname="fuzz" name="%s (%s s, %s executions)"/></testsuite>\n' \
      "$target" "$seconds" "${runs:-0}" >"$results/fuzz-$target.xml"
  else
    status=1
    detail=$(grep -E 'invariant broken|ERROR|SUMMARY|crash-|No such' "$out/$target.log" | head -5 | sed 's/[<>&"]/_/g' || true)
    printf '<testsuite name="fuzz"><testcase classname="fuzz" name="%s"><failure message="%s"/></testcase></testsuite>\n' \
      "$target" "$detail" >"$results/fuzz-$target.xml"
    tail -20 "$out/$target.log"
  fi
done
exit $status
