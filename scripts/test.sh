#!/usr/bin/env bash
# Every test, in two tiers; both install, build with warnings as errors, and end with one line
# "N passed, N failed".
#   bash scripts/test.sh           CI's: the gtest and rostest suites, the unit tests under ASan
#                                  and UBSan, catkin_lint, and the fuzzers briefly.
#   bash scripts/test.sh --quick   the unit tests that need no master only (core_tests, with the
#                                  trace, and ros_unit_tests): about a minute after the build.
# The full run keeps its two cores busy with two lanes side by side: the rostests (two at a time,
# each with its own master on a free port, as rostest starts them) and, at a lower priority, the
# sanitizer build and the fuzzers (side by side too), whose compiles fill the time the rostests
# spend waiting.
set -euo pipefail
quick=false
case "${1:-}" in
  --quick) quick=true ;;
  "") ;;
  *)
    echo "usage: bash scripts/test.sh [--quick]" >&2
    exit 2
    ;;
esac
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_packages
if ! build_package; then
  echo "0 passed, 1 failed"
  exit 1
fi
source_workspace
rm -rf "$ws/build/test_results"
results="$ws/build/test_results/collision_response"
mkdir -p "$results"
status=0

if $quick; then
  echo "== building and running the unit tests without a master (log: $ws/test.log)"
  if ! cmake --build "$ws/build" --target core_tests ros_unit_tests -- -j2 >"$ws/test.log" 2>&1; then
    tail -40 "$ws/test.log"
    echo "0 passed, 1 failed"
    exit 1
  fi
  for test in core_tests ros_unit_tests; do
    # As catkin runs them: from test/ (core_tests' working directory), results where catkin
    # puts them.
    log="$ws/test-$test.log"
    (cd "$repo/test" && "$ws/devel/lib/collision_response/$test" \
      --gtest_output="xml:$results/gtest-$test.xml") >"$log" 2>&1 || status=1
    grep -E '^\[ *FAILED *\]|^\[ *PASSED *\]' "$log" | sed "s/^/$test: /" || true
    [ -f "$results/gtest-$test.xml" ] || {
      tail -20 "$log"
      printf '<testsuite><testcase classname="%s" name="run"><failure message="no result: it stopped (see %s)"/></testcase></testsuite>\n' \
        "$test" "$log" >"$results/gtest-$test.xml"
    }
  done
  /usr/bin/python3 "$repo/scripts/count_results.py" "$ws/build/test_results" "$status"
  exit
fi

# The second lane: the unit tests again under AddressSanitizer and UndefinedBehaviorSanitizer
# (their own build), catkin_lint, and a short run of each fuzzer (bash scripts/fuzz.sh 600 for a
# long one). Its output is printed once it is done, after the first lane's. Their results join
# the count.
lane="$ws/second-lane.log"
(
  renice -n 10 -p "$BASHPID" >/dev/null
  # The fuzzers' build and run beside the sanitizer build and its tests (which run one
  # process at a time): together they keep both cores busy.
  bash "$repo/scripts/fuzz.sh" "${FUZZ_SECONDS:-30}" >"$ws/fuzz-lane.log" 2>&1 &
  fuzzers=$!
  bash "$repo/scripts/sanitize.sh" || true
  # catkin_lint on the package (warnings count as failures): one counted case.
  # Not in collision_response/: run_tests empties that folder when it starts.
  mkdir -p "$ws/build/test_results/lint"
  if lint=$(catkin_lint --strict "$repo" 2>&1); then
    printf '<testsuite><testcase classname="catkin_lint" name="package"/></testsuite>\n' \
      >"$ws/build/test_results/lint/catkin_lint.xml"
  else
    echo "$lint"
    printf '<testsuite><testcase classname="catkin_lint" name="package"><failure message="catkin_lint --strict reported problems (printed above)"/></testcase></testsuite>\n' \
      >"$ws/build/test_results/lint/catkin_lint.xml"
  fi
  wait "$fuzzers" || true
  cat "$ws/fuzz-lane.log"
) >"$lane" 2>&1 &
second_lane=$!
pids+=("$second_lane")

echo "== building and running the gtest and rostest suites, two at a time (log: $ws/test.log)"
echo "   beside them: the sanitizer build, catkin_lint and the fuzzers (log: $lane)"
cmake --build "$ws/build" --target run_tests -- -j2 >"$ws/test.log" 2>&1 || status=$?
grep -E '^\[ *(RUN|OK|FAILED|PASSED) *\]|FAILURE|ERROR|^\[(ROS)?TEST\]' "$ws/test.log" | grep -v -E '^\[ *(RUN|OK) ' || true
if [ "$status" -ne 0 ]; then
  tail -40 "$ws/test.log"
  echo "run_tests exited with status $status (log: $ws/test.log)"
fi
# The first lane is done: the second takes the cores at the usual priority from now on (its
# processes and those they start; raising a priority needs root, as CI is).
descendants() {
  local child
  for child in $(ps -o pid= --ppid "$1" 2>/dev/null); do
    echo "$child"
    descendants "$child"
  done
}
# shellcheck disable=SC2046  # one pid a word
renice -n 0 -p "$second_lane" $(descendants "$second_lane") >/dev/null 2>&1 || true
wait "$second_lane" || true
cat "$lane"
/usr/bin/python3 "$repo/scripts/count_results.py" "$ws/build/test_results" "$status"
