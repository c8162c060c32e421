#!/usr/bin/env bash
# Scale: the core per update for 1k, 10k and 100k bodies beside Bullet, and piles of up to 1,000
# balls at rest in a box (lasting contact: one layer, a stack 10 high) with gravity on and off,
# beside Bullet (Google Benchmark); the node over ROS with 10,000 bodies at 100 Hz (CPU share,
# latency, memory over a long run); the collision service's round trip beside an empty service;
# the prediction service's round trip on the table-tennis serve beside an echo of the same bytes;
# the work of one hard message (an array of 10,000 distinct stamps, a cluster of 1,000 touching
# balls: the monitor's CPU, and the service's worst round trip meanwhile) and start-up from
# 1,000 to 30,000 bodies.
# Writes doc/performance.md.
#   bash scripts/performance.sh                    # the memory run lasts 10 minutes
#   MEMORY_SECONDS=60 bash scripts/performance.sh  # a shorter one
#   MEMORY_SECONDS=0 bash scripts/performance.sh   # none: the report keeps the last memory run
# The pile's section alone (about 2 minutes), into the existing doc/performance.md:
#   .ws/devel/lib/collision_response/bench_scale --benchmark_filter=Pile \
#     --benchmark_format=json --benchmark_out=.ws/pile.json
#   /usr/bin/python3 scripts/performance_report.py --pile-only .ws/pile.json doc/performance.md
# The prediction service's section alone, into the existing doc/performance.md, with a master,
# empty_service and a node on config/scenes/serve.yaml (`rosparam load config/scenes/serve.yaml
# /collision_response_predict`, then collision_response_node __name:=collision_response_predict)
# running:
#   .ws/devel/lib/collision_response/node_benchmark _mode:=predict \
#     _service:=/collision_response_predict/predict_impacts >.ws/performance/predict_1.json
#   /usr/bin/python3 scripts/performance_report.py --predict-only .ws/performance doc/performance.md
# The shapes' first contact (doc/model.md, "Finite obstacles"), after a run of this script:
#   .ws/devel/lib/collision_response/bench_scale --benchmark_filter=FirstContact
#   .ws/devel/lib/collision_response/bench_arm     # a ball against a seven-joint arm, beside
#                                                  # Bullet and FCL
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PACKAGES+=(libbenchmark-dev libbullet-dev libfcl-dev libmujoco-dev libstd-srvs-dev ros-std-srvs linux-perf)
install_packages
build_workspace >"$ws/build.log" 2>&1 || { tail -40 "$ws/build.log"; exit 1; }
cmake --build "$ws/build" --target bench_scale bench_arm node_benchmark empty_service -- -j2 \
  >>"$ws/build.log" 2>&1 || { tail -40 "$ws/build.log"; exit 1; }
source_workspace
bin="$ws/devel/lib/collision_response"
out="$ws/performance"
mkdir -p "$out"
# A run without the memory part (MEMORY_SECONDS=0) keeps the last memory run's table.
rm -f "$out"/scale.json "$out"/service*.json "$out"/predict*.json "$out"/load.json "$out"/burden_*.json \
  "$out"/startup.json
[ "${MEMORY_SECONDS:-600}" -gt 0 ] && rm -f "$out/memory.json"

echo "== core: 1k, 10k, 100k bodies, and Bullet on the same gas; a pile at rest, gravity on and off"
"$bin/bench_scale" --benchmark_format=json --benchmark_out="$out/scale.json" >"$out/scale.log" 2>&1

echo "== the node over ROS"
bodies="${BODIES:-10000}"
/usr/bin/python3 - "$bodies" "$out/gas.yaml" <<'PY'
import math, random, sys
count, path = int(sys.argv[1]), sys.argv[2]
side = math.ceil(count ** (1 / 3))
random.seed(5)
lines = ["scene:", "  fixed_frame: world", "  detection: continuous",
         "  materials: {elastic: {restitution: 1.0}}", "  bodies:"]
for i in range(count):
    x, y, z = 0.25 + 0.5 * (i % side), 0.25 + 0.5 * ((i // side) % side), 0.25 + 0.5 * (i // (side * side))
    v = [random.uniform(-2, 2) for _ in range(3)]
    lines.append(f"    - {{id: gas_{1000000 + i}, mass: 0.1, radius: 0.05, material: elastic, "
                 f"position: [{x}, {y}, {z}], velocity: [{v[0]:.6f}, {v[1]:.6f}, {v[2]:.6f}]}}")
lines.append("  obstacles:")
size = 0.5 * side
for i, (n, offset) in enumerate([("[1, 0, 0]", 0), ("[-1, 0, 0]", -size), ("[0, 1, 0]", 0),
                                 ("[0, -1, 0]", -size), ("[0, 0, 1]", 0), ("[0, 0, -1]", -size)]):
    lines.append(f"    - {{id: wall_{i}, type: plane, normal: {n}, offset: {offset}, material: elastic}}")
open(path, "w").write("\n".join(lines) + "\n")
PY
start_private_master "$out/roscore.log"
rosparam load "$out/gas.yaml" /collision_response
rosparam load "$out/gas.yaml" /node_benchmark
# The node's start-up with the gas: from its launch until its service is there.
startup_began=$(date +%s.%N)
"$bin/collision_response_node" >"$out/node.log" 2>&1 &
node_pid=$!
pids+=($node_pid)
until rosservice list 2>/dev/null | grep -q /collision_response/compute_collision; do sleep 0.05; done
startup_ended=$(date +%s.%N)
/usr/bin/python3 -c "import json, sys; print(json.dumps({'bodies': int(sys.argv[1]), 'seconds': float(sys.argv[3]) - float(sys.argv[2])}))" \
  "$bodies" "$startup_began" "$startup_ended" >"$out/startup_node.json"
# The service is measured on a second node that serves the services alone (the default scene),
# beside the empty service; the node with the 10,000 bodies is measured under load below.
rosparam load "$repo/config/scenes/default.yaml" /collision_response_services
"$bin/collision_response_node" __name:=collision_response_services >"$out/services_node.log" 2>&1 &
pids+=($!)
"$bin/empty_service" >"$out/empty.log" 2>&1 &
pids+=($!)
until rosservice list 2>/dev/null | grep -q /empty_service/empty &&
  rosservice list 2>/dev/null | grep -q /collision_response_services/compute_collision &&
  rosservice list 2>/dev/null | grep -q /collision_response/compute_collision; do sleep 0.2; done

echo "== service round trips (persistent clients, alternating; three rounds)"
for round in 1 2 3; do
  "$bin/node_benchmark" _mode:=service _calls:=5000 _service:=/collision_response_services/compute_collision \
    >"$out/service_$round.json"
done
# ~predict_impacts on a third node, serving the table-tennis serve (config/scenes/serve.yaml; its
# topics moved aside, so that the gas's states do not reach it), beside empty_service's
# ~echo_prediction, which answers the same bytes without physics. Stopped after its rounds.
rosparam load "$repo/config/scenes/serve.yaml" /collision_response_predict
"$bin/collision_response_node" __name:=collision_response_predict body_states:=/predict/body_states \
  impacts:=/predict/impacts contacts:=/predict/contacts >"$out/predict_node.log" 2>&1 &
predict_pid=$!
pids+=($predict_pid)
until rosservice list 2>/dev/null | grep -q /collision_response_predict/predict_impacts &&
  rosservice list 2>/dev/null | grep -q /empty_service/echo_prediction; do sleep 0.2; done
echo "== prediction round trips: the serve, beside an echo of the same bytes (three rounds)"
for round in 1 2 3; do
  "$bin/node_benchmark" _mode:=predict _calls:=2000 _service:=/collision_response_predict/predict_impacts \
    _pid:="$predict_pid" >"$out/predict_$round.json"
done
stop_process "$predict_pid"
echo "== ${bodies} bodies at 100 Hz for 20 s"
"$bin/node_benchmark" _mode:=load _rate:=100 _seconds:=20 _pid:="$node_pid" >"$out/load.json"
# Where the node's time goes: perf samples the node for 8 s of a second load run (not the
# measured one: sampling costs the node time).
echo "== where the time goes: perf on a second run of 12 s"
rm -f "$out/profile.txt"
( sleep 3 && perf record -g -o "$out/perf.data" -p "$node_pid" -- sleep 8 >"$out/perf.log" 2>&1 &&
  { perf report -i "$out/perf.data" --no-children --sort dso,sym -g none 2>/dev/null |
    grep -v '^#' | grep -v '^$' | head -15 >"$out/profile.txt" || true; } ) &
profiler=$!
"$bin/node_benchmark" _mode:=load _rate:=100 _seconds:=12 >/dev/null
wait "$profiler" || true
[ -s "$out/profile.txt" ] || echo "(no profile: perf could not sample here, see $out/perf.log)"
memory_seconds="${MEMORY_SECONDS:-600}"
if [ "$memory_seconds" -gt 0 ]; then
  echo "== memory: ${bodies} bodies at 100 Hz for ${memory_seconds} s"
  "$bin/node_benchmark" _mode:=load _rate:=100 _seconds:="$memory_seconds" _memory_every:=30 \
    _pid:="$node_pid" >"$out/memory.json"
fi
# Issue 13, item 9: the work of one hard message, and the service meanwhile. The gas node takes
# arrays of its 10,000 bodies whose stamps are 10 us apart; a second node a lattice of 1,000
# touching balls closing on its centre (one joint solve: its cost is the cluster solver's).
echo "== one hard message: 10,000 distinct stamps; a cluster of 1,000 touching balls"
"$bin/node_benchmark" _mode:=burden _kind:=stamps _messages:=5 _pid:="$node_pid" \
  _service:=/collision_response/compute_collision >"$out/burden_stamps.json"
/usr/bin/python3 - "$out/cluster.yaml" <<'PY'
import sys
n, r = 10, 0.05
lines = ["scene:", "  fixed_frame: world", "  detection: continuous",
         "  materials: {clay: {restitution: 0.5}}", "  bodies:"]
centre = (n - 1) * r
for i in range(n):
    for j in range(n):
        for k in range(n):
            p = (2 * r * i, 2 * r * j, 2 * r * k)
            v = tuple(-(x - centre) for x in p)  # 1 m/s per m towards the centre
            lines.append(f"    - {{id: ball_{i}{j}{k}, mass: 0.1, radius: {r}, material: clay, "
                         f"position: [{p[0]:.17g}, {p[1]:.17g}, {p[2]:.17g}], "
                         f"velocity: [{v[0]:.17g}, {v[1]:.17g}, {v[2]:.17g}]}}")
open(sys.argv[1], "w").write("\n".join(lines) + "\n")
PY
rosparam load "$out/cluster.yaml" /collision_response_cluster
"$bin/collision_response_node" __name:=collision_response_cluster body_states:=/cluster/body_states \
  impacts:=/cluster/impacts >"$out/cluster_node.log" 2>&1 &
cluster_pid=$!
pids+=($cluster_pid)
until rosservice list 2>/dev/null | grep -q /collision_response_cluster/compute_collision; do sleep 0.2; done
rosparam delete /node_benchmark/scene
rosparam load "$out/cluster.yaml" /node_benchmark
"$bin/node_benchmark" _mode:=burden _kind:=cluster _pid:="$cluster_pid" \
  _service:=/collision_response_cluster/compute_collision body_states:=/cluster/body_states \
  impacts:=/cluster/impacts >"$out/burden_cluster.json"
echo "== start-up: the loader and the monitor for 1,000 to 30,000 bodies"
"$bin/node_benchmark" _mode:=startup >"$out/startup.json"
/usr/bin/python3 "$repo/scripts/performance_report.py" "$out" "$repo/doc/performance.md"
cat "$repo/doc/performance.md"
