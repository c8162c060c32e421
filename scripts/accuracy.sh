#!/usr/bin/env bash
# What accuracy costs in time: every scene of bench/accuracy at every setting (our continuous
# and discrete detection, effects on and off, and every body stepped where a scene asks for it;
# Bullet with its defaults and with its recommended bouncing settings; ODE; MuJoCo with its
# default contact and with restitution through solref; DART; Box2D on the planar scenes; lasting
# contact under gravity: a ball into a corner, off a fixed sphere, a stack of three, piles of 27
# to 1,000 balls settling in a box), errors against references computed outside the code under
# test and CPU time (Google Benchmark). Writes doc/accuracy.md, doc/accuracy.png and the
# accuracy section of doc/measurements.md (between its markers).
# Then what a prediction's accuracy costs (bench/bench_prediction.cpp): a topspin serve through
# air predicted at integrator tolerances 1e-6 to 1e-12, and stepped by Bullet and ODE at 240 to
# 10,000 Hz, its second bounce and its crossing of a plane against the 40-digit reference
# bench/accuracy/reference/serve_reference.txt; and a gravity-only query of 10 bounces. Writes
# doc/prediction.md and doc/prediction.png.
#   bash scripts/accuracy.sh                # about 15 minutes on 2 cores, most of it ours'
#                                           # 1,000-ball pile
#   bash scripts/accuracy.sh --prediction   # the prediction's part alone: its run about 20 s
# The references are recomputed on every run (about ten seconds) from the scenes' inputs as the
# benchmark builds them, so that a changed scene is never measured against a stale answer; they
# are also checked in (bench/accuracy/reference/), so that any change of an answer shows in review.
# The serve's reference is only read (rerun serve_reference.py beside it when its model changes).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
prediction_only=false
case "${1:-}" in
  "") ;;
  --prediction) prediction_only=true ;;
  *) echo "usage: bash scripts/accuracy.sh [--prediction]" >&2; exit 2 ;;
esac
if [ "$prediction_only" = true ]; then
  PACKAGES+=(libbenchmark-dev libbullet-dev libode-dev pkg-config python3-matplotlib)
else
  PACKAGES+=(libbenchmark-dev libbullet-dev libode-dev pkg-config libmujoco-dev libdart-dev
    libbox2d-dev python3-mpmath python3-matplotlib)
fi
install_packages
# What a prediction's accuracy costs: the prediction's benchmark (and the core it links) only.
prediction() {
  BUILD_TARGET=bench_prediction build_workspace >"$ws/build-prediction.log" 2>&1 ||
    { tail -40 "$ws/build-prediction.log"; exit 1; }
  local out="$ws/prediction"
  mkdir -p "$out"
  echo "== the serve predicted at each tolerance, Bullet and ODE at each rate (errors, CPU time)"
  "$ws/devel/lib/collision_response/bench_prediction" --benchmark_format=json \
    --benchmark_out="$out/prediction.json" >"$out/benchmark.log" 2>&1 ||
    { tail -20 "$out/benchmark.log"; exit 1; }
  /usr/bin/python3 "$repo/scripts/prediction_report.py" "$out/prediction.json" "$repo/doc"
  echo "== wrote doc/prediction.md and doc/prediction.png"
}
if [ "$prediction_only" = true ]; then
  prediction
  exit 0
fi
# Only the benchmark (and the core it links): the node, the messages and the tests are not needed.
BUILD_TARGET=accuracy_benchmark build_workspace >"$ws/build.log" 2>&1 ||
  { tail -40 "$ws/build.log"; exit 1; }
bin="$ws/devel/lib/collision_response/accuracy_benchmark"
reference="$repo/bench/accuracy/reference"
out="$ws/accuracy"
mkdir -p "$out"
echo "== the references (bench/accuracy/reference/make_references.py, 50-digit mpmath)"
"$bin" --export-scenes "$reference/scenes.txt"
/usr/bin/python3 "$reference/make_references.py" "$reference/scenes.txt" "$reference/references.txt"
echo "== every scene at every setting (errors, then CPU time; the long runs once each)"
"$bin" "$reference/references.txt" "$out/errors.json" \
  --benchmark_format=json --benchmark_out="$out/timing.json" >"$out/benchmark.log" 2>&1 ||
  { tail -20 "$out/benchmark.log"; exit 1; }
/usr/bin/python3 "$repo/scripts/accuracy_report.py" "$out" "$repo/doc" "$repo/doc/measurements.md"
echo "== wrote doc/accuracy.md, doc/accuracy.png and the accuracy section of doc/measurements.md"
prediction
