#!/usr/bin/env bash
# A picture of a scene: plays it with the node (demo.launch), records the states and impacts with
# rosbag, and draws the trajectories and impacts from the bag with matplotlib.
#   bash scripts/plot_scene.sh [scene] [duration_s]    -> doc/<scene>.png and .ws/plots/<scene>.bag
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
scene="${1:-billiards_break}"
duration="${2:-3}"
[ -f "$repo/config/scenes/$scene.yaml" ] || { echo "no scene '$scene' in config/scenes/"; exit 2; }
PACKAGES+=(python3-rosbag python3-matplotlib)
install_packages
build_workspace >"$ws/build.log" 2>&1 || { tail -40 "$ws/build.log"; echo "build failed (log: $ws/build.log)"; exit 1; }
source_workspace
out="$ws/plots"
mkdir -p "$out"
start_private_master "$out/roscore.log"
rm -f "$out/$scene.bag"
rosbag record -O "$out/$scene.bag" /body_states /impacts >"$out/rosbag.log" 2>&1 &
recorder=$!
pids+=($recorder)
echo "== roslaunch collision_response demo.launch scene:=$scene duration:=$duration, recorded by rosbag"
# The player waits a second so that the recorder is connected before the first state.
roslaunch collision_response demo.launch scene:="$scene" duration:="$duration" start_delay:=1.0 \
  report_restitution:=false >"$out/demo.log" 2>&1
kill -INT "$recorder"
wait "$recorder" 2>/dev/null || true
rosbag info "$out/$scene.bag" | grep -E '^(duration|messages|topics)|^ +/' || true
/usr/bin/python3 "$repo/scripts/plot_bag.py" "$out/$scene.bag" "$repo/doc/$scene.png" "$scene"
echo "== wrote doc/$scene.png (bag: $out/$scene.bag)"
