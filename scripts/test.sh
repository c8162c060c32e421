#!/usr/bin/env bash
# Every test: install, build with warnings as errors, run the gtest and rostest suites, the unit
# tests under ASan and UBSan, and the fuzzers briefly; end with one line "N passed, N failed".
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_packages
if ! build_package; then
  echo "0 passed, 1 failed"
  exit 1
fi
source_workspace
rm -rf "$ws/build/test_results"
status=0
echo "== building and running the tests (about 10 minutes on 2 cores; log: $ws/test.log)"
cmake --build "$ws/build" --target run_tests -- -j2 >"$ws/test.log" 2>&1 || status=$?
grep -E '^\[ *(RUN|OK|FAILED|PASSED) *\]|FAILURE|ERROR|^\[(ROS)?TEST\]' "$ws/test.log" | grep -v -E '^\[ *(RUN|OK) ' || true
if [ "$status" -ne 0 ]; then
  tail -40 "$ws/test.log"
  echo "run_tests exited with status $status (log: $ws/test.log)"
fi
# The unit tests again under AddressSanitizer and UndefinedBehaviorSanitizer, and a short run
# of each fuzzer (bash scripts/fuzz.sh 600 for a long one). Their results join the count.
bash "$repo/scripts/sanitize.sh" || true
# catkin_lint on the package (warnings count as failures): one counted case.
mkdir -p "$ws/build/test_results/collision_response"
if lint=$(catkin_lint --strict "$repo" 2>&1); then
  printf '<testsuite><testcase classname="catkin_lint" name="package"/></testsuite>\n' \
    >"$ws/build/test_results/collision_response/catkin_lint.xml"
else
  echo "$lint"
  printf '<testsuite><testcase classname="catkin_lint" name="package"><failure message="catkin_lint --strict reported problems (printed above)"/></testcase></testsuite>\n' \
    >"$ws/build/test_results/collision_response/catkin_lint.xml"
fi
bash "$repo/scripts/fuzz.sh" "${FUZZ_SECONDS:-30}" || true
/usr/bin/python3 "$repo/scripts/count_results.py" "$ws/build/test_results" "$status"
