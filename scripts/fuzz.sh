#!/usr/bin/env bash
# libFuzzer on the core (clang, AddressSanitizer and UndefinedBehaviorSanitizer): the impact
# resolution and the time of impact, each checking its invariants (fuzz/*.cpp).
#   bash scripts/fuzz.sh [seconds per target, default 30]      e.g. bash scripts/fuzz.sh 600
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
mkdir -p "$out" "$results"
flags=(-std=c++17 -O1 -g -Wall -Wextra -fsanitize=fuzzer-no-link,address,undefined
  -fno-sanitize-recover=undefined -I "$repo/include" -isystem /usr/include/eigen3)
echo "== building the core with clang -fsanitize=fuzzer-no-link,address,undefined"
mkdir -p "$out/core"
objects=()
for source in "$repo"/src/core/*.cpp; do
  # The product's core: effect_selection_none.cpp is the benchmark's reference build instead.
  [ "$(basename "$source")" = effect_selection_none.cpp ] && continue
  object="$out/core/$(basename "$source" .cpp).o"
  objects+=("$object")
  [ "$object" -nt "$source" ] &&
    [ -z "$(find "$repo/include" "$repo/src/core" -name '*.h' -newer "$object" -print -quit)" ] ||
    clang++ "${flags[@]}" -c "$source" -o "$object" &
done
wait
status=0
for target in fuzz_impact fuzz_time_of_impact; do
  echo "== $target: building"
  clang++ "${flags[@]}" -fsanitize=fuzzer "$repo/fuzz/$target.cpp" "${objects[@]}" -o "$out/$target"
  mkdir -p "$out/corpus-$target"
  echo "== $target: running $seconds s"
  set +e
  (cd "$out" && ASAN_OPTIONS=detect_leaks=1 ./"$target" -max_total_time="$seconds" \
    -print_final_stats=1 "corpus-$target" "$repo/fuzz/regressions" >"$out/$target.log" 2>&1)
  rc=$?
  set -e
  runs=$(grep -E 'stat::number_of_executed_units' "$out/$target.log" | awk '{print $2}' | tail -1)
  echo "   $target: exit $rc, ${runs:-0} executions"
  if [ $rc -eq 0 ]; then
    printf '<testsuite name="fuzz"><testcase classname="fuzz" name="%s (%s s, %s executions)"/></testsuite>\n' \
      "$target" "$seconds" "${runs:-0}" >"$results/fuzz-$target.xml"
  else
    status=1
    detail=$(grep -E 'invariant broken|ERROR|SUMMARY|crash-' "$out/$target.log" | head -5 | sed 's/[<>&"]/_/g')
    printf '<testsuite name="fuzz"><testcase classname="fuzz" name="%s"><failure message="%s"/></testcase></testsuite>\n' \
      "$target" "$detail" >"$results/fuzz-$target.xml"
    tail -20 "$out/$target.log"
  fi
done
exit $status
