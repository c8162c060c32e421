#!/usr/bin/env bash
# Every test, in tiers; each installs, builds with warnings as errors, and ends with one line
# "N passed, N failed".
#   bash scripts/test.sh           CI's: the gtest and rostest suites, the unit tests under ASan
#                                  and UBSan, each fuzzer's saved inputs replayed, catkin_lint.
#   bash scripts/test.sh --quick   the unit tests that need no master only (core_tests, with the
#                                  trace, and ros_unit_tests). The first run after the demo's build
#                                  compiles these two test programs first (about 1.5 minutes on 2
#                                  cores); then 36 s.
#   bash scripts/test.sh --long    the full run, with each fuzzer fuzzing for FUZZ_SECONDS
#                                  (default 600) instead of replaying: a nightly run.
# The full run keeps its two cores busy with two lanes side by side: the gtests and rostests (two
# at a time, each with its own master on a free port, as rostest starts them) and, at a lower
# priority, the one clang sanitizer build, the sanitized unit tests, the fuzzers and catkin_lint.
# It prints each test program as it ends, and a line at least every minute.
set -euo pipefail
mode=full
case "${1:-}" in
  --quick) mode=quick ;;
  --long) mode=long ;;
  "") ;;
  *)
    echo "usage: bash scripts/test.sh [--quick | --long]" >&2
    exit 2
    ;;
esac
started=$SECONDS
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

if [ "$mode" = quick ]; then
  echo "== building the unit tests without a master (the first time after the demo's build: about"
  echo "   1.5 minutes, the demo builds no test program; log: $ws/test.log), then running them (36 s)"
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

# The second lane: the one clang build with the sanitizers, the unit tests under them, the
# fuzzers (replaying their saved inputs; fuzzing with --long) and catkin_lint. Its results join
# the count.
lane="$ws/second-lane.log"
# Each lane writes its end into a file of its own, which the progress below waits for (a process
# id that ended can be another process's a moment later).
rm -f "$ws/first-lane.status" "$ws/second-lane.status"
(
  trap 'echo "$?" >"$ws/second-lane.status"' EXIT
  renice -n 10 -p "$BASHPID" >/dev/null
  bash "$repo/scripts/sanitize.sh" || true
  if [ "$mode" = long ]; then
    bash "$repo/scripts/fuzz.sh" "${FUZZ_SECONDS:-600}" || true
  else
    bash "$repo/scripts/fuzz.sh" --replay || true
  fi
  # catkin_lint on the package (warnings count as failures): one counted case.
  # Not in collision_response/: run_tests empties that folder when it starts.
  echo "== catkin_lint --strict"
  mkdir -p "$ws/build/test_results/lint"
  if lint=$(catkin_lint --strict "$repo" 2>&1); then
    printf '<testsuite><testcase classname="catkin_lint" name="package"/></testsuite>\n' \
      >"$ws/build/test_results/lint/catkin_lint.xml"
  else
    echo "$lint"
    printf '<testsuite><testcase classname="catkin_lint" name="package"><failure message="catkin_lint --strict reported problems (printed above)"/></testcase></testsuite>\n' \
      >"$ws/build/test_results/lint/catkin_lint.xml"
  fi
  # Every launch file's arguments have a doc (roslaunch --ros-args lists them): one counted case.
  echo "== every launch argument documented"
  undocumented=""
  for launch in "$repo"/launch/*.launch; do
    args=$(roslaunch --ros-args "$launch" 2>&1) || undocumented+="$(basename "$launch"): $args; "
    if grep -q undocumented <<<"$args"; then
      undocumented+="$(basename "$launch"): $(grep undocumented <<<"$args" | tr -s ' ' | tr '\n' ' ')"
    fi
  done
  if [ -z "$undocumented" ]; then
    printf '<testsuite><testcase classname="launch" name="every argument documented"/></testsuite>\n' \
      >"$ws/build/test_results/lint/launch_arguments.xml"
  else
    echo "$undocumented"
    printf '<testsuite><testcase classname="launch" name="every argument documented"><failure message="%s"/></testcase></testsuite>\n' \
      "$(sed 's/[<>&"]/_/g' <<<"$undocumented")" >"$ws/build/test_results/lint/launch_arguments.xml"
  fi
  # Every link to a Markdown file and its heading resolves (the README's to doc/model.md's
  # sections among them): one counted case.
  echo "== every link to a Markdown heading resolves"
  if links=$(/usr/bin/python3 "$repo/scripts/check_links.py" "$repo" 2>&1); then
    echo "$links"
    printf '<testsuite><testcase classname="docs" name="every link resolves"/></testsuite>\n' \
      >"$ws/build/test_results/lint/links.xml"
  else
    echo "$links"
    printf '<testsuite><testcase classname="docs" name="every link resolves"><failure message="%s"/></testcase></testsuite>\n' \
      "$(sed 's/[<>&"]/_/g' <<<"$links" | tr '\n' ' ')" >"$ws/build/test_results/lint/links.xml"
  fi
  # No include of the core runs up a floor (src/core's rooms: scripts/check_floors.py): one
  # counted case.
  echo "== no include of the core runs up a floor"
  if floors=$(/usr/bin/python3 "$repo/scripts/check_floors.py" "$repo" 2>&1); then
    echo "$floors"
    printf '<testsuite><testcase classname="core" name="no include runs up a floor"/></testsuite>\n' \
      >"$ws/build/test_results/lint/floors.xml"
  else
    echo "$floors"
    printf '<testsuite><testcase classname="core" name="no include runs up a floor"><failure message="%s"/></testcase></testsuite>\n' \
      "$(sed 's/[<>&"]/_/g' <<<"$floors" | tr '\n' ' ')" >"$ws/build/test_results/lint/floors.xml"
  fi
  # The API documentation builds, every header and message with its page, without a warning of
  # Doxygen (scripts/docs.sh): one counted case.
  echo "== the API documentation (bash scripts/docs.sh)"
  if docs=$(bash "$repo/scripts/docs.sh" 2>&1) && grep -q '^== 0 Doxygen warnings' <<<"$docs"; then
    printf '<testsuite><testcase classname="docs" name="API documentation"/></testsuite>\n' \
      >"$ws/build/test_results/lint/api_docs.xml"
  else
    echo "$docs"
    printf '<testsuite><testcase classname="docs" name="API documentation"><failure message="%s"/></testcase></testsuite>\n' \
      "$(grep -E 'warning|missing' <<<"$docs" | head -5 | sed 's/[<>&"]/_/g' | tr '\n' ' ')" \
      >"$ws/build/test_results/lint/api_docs.xml"
  fi
  echo "== second lane done"
) >"$lane" 2>&1 &
second_lane=$!
pids+=("$second_lane")

# Each of the two lanes' logs, as it grows: a line for each test program that ends (catkin's
# "verify result" of its result file) and each stage of the second lane; and a line at least
# every minute saying what still runs.   usage: show_progress STATUS_FILE  (until it is written)
first_shown=0 second_shown=0 tests_done=0 stage="its build"
show_progress() {
  local done_file=$1 lines quiet_since=$SECONDS printed name
  while [ ! -s "$done_file" ]; do
    sleep 5
    printed=false
    if [ -f "$ws/test.log" ]; then
      lines=$(wc -l <"$ws/test.log")
      while IFS= read -r line; do
        case "$line" in
          *'verify result'*)
            tests_done=$((tests_done + 1))
            name=${line##*/}
            echo "   [$(elapsed)] ended: ${name%.xml*}"
            printed=true
            ;;
          *'FAILURES: '[1-9]* | *'ERRORS: '[1-9]* | *'[  FAILED  ]'*)
            echo "   [$(elapsed)] $line"
            printed=true
            ;;
        esac
      done < <([ "$lines" -gt "$first_shown" ] && sed -n "$((first_shown + 1)),${lines}p" "$ws/test.log")
      first_shown=$lines
    fi
    if [ -f "$lane" ]; then
      lines=$(wc -l <"$lane")
      while IFS= read -r line; do
        echo "   [$(elapsed)] second lane: ${line#== }"
        [[ $line != '== '* ]] || stage=${line#== }
        printed=true
      done < <([ "$lines" -gt "$second_shown" ] && sed -n "$((second_shown + 1)),${lines}p" "$lane" | grep -E '^== |^ *\[  (PASSED|FAILED)|^ *fuzz_[a-z_]*: exit' | grep -v 'Debian packages are installed' || true)
      second_shown=$lines
    fi
    if $printed; then
      quiet_since=$SECONDS
    elif [ $((SECONDS - quiet_since)) -ge 55 ]; then
      echo "   [$(elapsed)] still running: $tests_done test programs of the first lane ended; the second lane: ${stage:0:60}"
      quiet_since=$SECONDS
    fi
  done
}
elapsed() {
  local seconds=$((SECONDS - started))
  printf '%d:%02d' $((seconds / 60)) $((seconds % 60))
}

echo "== building and running the gtest and rostest suites, two at a time (log: $ws/test.log)"
echo "   beside them: the sanitizer build, its tests, the fuzzers and catkin_lint (log: $lane)"
(
  trap 'echo "$?" >"$ws/first-lane.status"' EXIT
  cmake --build "$ws/build" --target run_tests -- -j2 >"$ws/test.log" 2>&1
) &
first_lane=$!
pids+=("$first_lane")
show_progress "$ws/first-lane.status"
wait "$first_lane" || true
status=$(cat "$ws/first-lane.status")
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
echo "== the first lane is done ($(elapsed)); the second lane goes on"
show_progress "$ws/second-lane.status"
wait "$second_lane" || true
echo "== the second lane's whole log ($lane):"
sed 's/^/   /' "$lane"
echo "== $(elapsed) in all (minutes:seconds)"
/usr/bin/python3 "$repo/scripts/count_results.py" "$ws/build/test_results" "$status"
