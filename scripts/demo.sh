#!/usr/bin/env bash
# The demo: install, build, start a private ROS master and the collision_response node, call its
# services on the seed's examples, print the answers, and stop everything it started.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_packages
build_workspace >"$ws/build.log" 2>&1 || { tail -40 "$ws/build.log"; echo "build failed (log: $ws/build.log)"; exit 1; }
source_workspace
export ROS_MASTER_URI="http://localhost:$(free_port)"

echo "== roslaunch collision_response collision_response.launch (private master at $ROS_MASTER_URI)"
# roslaunch starts the master and the node; stopping roslaunch stops both.
roslaunch collision_response collision_response.launch >"$ws/demo-node.log" 2>&1 &
launch_pid=$!
trap 'kill -INT $launch_pid 2>/dev/null; wait $launch_pid 2>/dev/null || true' EXIT

for _ in $(seq 100); do
  rosservice list 2>/dev/null | grep -q /collision_response/estimate_restitution && break
  sleep 0.2
done
rosrun collision_response seed_examples </dev/null
