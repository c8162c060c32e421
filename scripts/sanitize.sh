#!/usr/bin/env bash
# The core's unit tests under AddressSanitizer and UndefinedBehaviorSanitizer, in the one clang
# sanitizer build (.ws/sanitizers, which the fuzzers of scripts/fuzz.sh share). The ROS layer is
# in that build only as far as the monitor's fuzzer drives it (the intake, the time line, the
# update cycle: fuzz_monitor's sources); its unit tests run in the main build: a third less to
# compile in the suite's longer lane. Results go beside the others
# (.ws/build/test_results/sanitized) for the test count.
#   bash scripts/sanitize.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_packages
results="$ws/build/test_results/sanitized"
# No result of an earlier run counts for this one.
rm -rf "$results"
mkdir -p "$results"
# The fuzzers are built with the tests (the same objects): scripts/fuzz.sh then only links. A
# build that fails is a failed case of the count, not a lane that says nothing.
if ! build_sanitized core_tests fuzz_impact fuzz_time_of_impact fuzz_monitor; then
  printf '<testsuite><testcase classname="sanitized" name="build"><failure message="the sanitizer build failed (see %s)"/></testcase></testsuite>\n' \
    "$sanitized/build.log" >"$results/sanitized-build.xml"
  exit 1
fi
# Every unit test but those that repeat one computation many times over: the trace (every scene
# of the package and the accuracy benchmark, 3.5 minutes under the sanitizers), the broad phase
# against every pair (1 minute), the calibration's coverage over 1,000 seeds each (the same fit
# 2,000 times) and its stuck bounce over 300 seeds (33 CPU-seconds), the table's edge scanned at
# 40 phases of an update at 100 Hz and 1 kHz (80 CPU-seconds: the edge's passage and leave run
# once each in LastingContact.*Edge*), and the cluster's friction on 2,000 random clusters (45
# CPU-seconds; solveCluster with friction runs in the other ClusterFriction and LargeCluster
# tests), the random lasting contacts of shaped bodies whose tipping is integrated (800 bodies:
# the tipping runs in ShapedPivot's closed-form tests), and the random slides into a room's
# corner (12 CPU-seconds: the law on several faces runs in ShapedFaces' closed-form tests). Their
# code runs in the other tests under the sanitizers, and their answers are checked in the main
# build.
declare -A filters=(
  [core_tests]="-Trace.*:Monitor.BroadphaseGivesTheSameImpactsAsEveryPair:Calibration.NinetyFivePercentIntervalsCoverTheTruth*:Calibration.AStuckBounceIsNotReadAsSliding:EdgeScan.*:ClusterFriction.EnergyNeverIncreases:ShapedPivot.Random*:ShapedLasting.Random*:ShapedFaces.Random*:ShapedCorner.Random*:TumblingContact.Fuzz*:SteppedClusters.APileSettlesInABox*"
)
# Each program in two shards side by side (gtest's GTEST_TOTAL_SHARDS): the two cores.
run_shard() {
  local test=$1 shard=$2 name="$1-$2"
  # The random throws at the finite shapes (core_tests) 1,000 a shape here rather than 20,000 (the
  # test's least; the turning and open shapes' 1,000 too): every path of the code runs, in a
  # twentieth of the time the sanitizers make it take. The random rigid impacts likewise: 10^5
  # here, 10^6 in the main build; and a tumbling body's contacts and a shaped body's throws 2 and
  # 1 a pair here against 6 and 2 there.
  (cd "$repo/test" && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    FINITE_SHAPE_THROWS="${FINITE_SHAPE_THROWS:-1000}" GTEST_TOTAL_SHARDS=2 GTEST_SHARD_INDEX="$shard" \
    COLLISION_RESPONSE_RANDOM_IMPACTS="${COLLISION_RESPONSE_RANDOM_IMPACTS:-100000}" \
    COLLISION_RESPONSE_TUMBLING_FUZZ="${COLLISION_RESPONSE_TUMBLING_FUZZ:-2}" \
    COLLISION_RESPONSE_SHAPED_THROWS="${COLLISION_RESPONSE_SHAPED_THROWS:-1}" \
    "$sanitized/devel/lib/collision_response/$test" --gtest_filter="${filters[$test]}" \
    --gtest_output="xml:$results/sanitized-$name.xml") >"$sanitized/$name.log" 2>&1 || {
    tail -30 "$sanitized/$name.log"
    return 1
  }
}
status=0
for test in core_tests; do
  echo "== $test under ASan and UBSan (two shards)"
  run_shard "$test" 0 &
  first=$!
  run_shard "$test" 1 || status=1
  wait "$first" || status=1
  for shard in 0 1; do
    # A sanitizer abort leaves no result file: say so in one the count reads.
    [ -f "$results/sanitized-$test-$shard.xml" ] || printf '<testsuite><testcase classname="sanitized" name="%s"><failure message="no result: the sanitizer stopped it (see %s)"/></testcase></testsuite>\n' \
      "$test shard $shard" "$sanitized/$test-$shard.log" >"$results/sanitized-$test-$shard.xml"
    grep -E '^\[  (PASSED|FAILED)' "$sanitized/$test-$shard.log" | sed "s/^/   shard $shard: /" || true
  done
done
exit $status
