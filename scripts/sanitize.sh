#!/usr/bin/env bash
# The unit tests (core and ROS layer, no master) built with AddressSanitizer and
# UndefinedBehaviorSanitizer, in their own build folder .ws/sanitize. Results go beside the
# others (.ws/build/test_results/sanitized) for the test count.
#   bash scripts/sanitize.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_packages
build="$ws/sanitize"
results="$ws/build/test_results/sanitized"
mkdir -p "$build" "$results"
echo "== building the unit tests with -fsanitize=address,undefined in $build"
# -g1: line tables only, what the sanitizers' reports need (file and line), and a quarter less
# compile time than -g (the full suite's second lane waits on this build).
flags="-O1 -g1 -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S "$repo" -B "$build/build" -DCATKIN_DEVEL_PREFIX="$build/devel" \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=None -DCATKIN_ENABLE_TESTING=ON \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >"$build/build.log" 2>&1
cmake --build "$build/build" --target core_tests ros_unit_tests -- -j2 >>"$build/build.log" 2>&1 ||
  { tail -30 "$build/build.log"; exit 1; }
status=0
for test in core_tests ros_unit_tests; do
  echo "== $test under ASan and UBSan"
  # The random throws at the finite shapes (core_tests) 2,000 a shape here rather than 20,000:
  # every path of the code runs, in a tenth of the time the sanitizers make it take.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    FINITE_SHAPE_THROWS="${FINITE_SHAPE_THROWS:-2000}" \
    "$build/devel/lib/collision_response/$test" --gtest_output="xml:$results/sanitized-$test.xml" \
    >"$build/$test.log" 2>&1 || { status=1; tail -30 "$build/$test.log"; }
  # A sanitizer abort leaves no result file: say so in one the count reads.
  [ -f "$results/sanitized-$test.xml" ] || printf '<testsuite><testcase classname="sanitized" name="%s"><failure message="no result: the sanitizer stopped it (see %s)"/></testcase></testsuite>\n' \
    "$test" "$build/$test.log" >"$results/sanitized-$test.xml"
  grep -E '^\[  (PASSED|FAILED)' "$build/$test.log" || true
done
exit $status
