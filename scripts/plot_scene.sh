#!/usr/bin/env bash
# A picture of a scene: plays it with the node (demo.launch), records the states and impacts with
# rosbag, and draws the paths, obstacles, speeds and impacts from the bag with matplotlib.
#   bash scripts/plot_scene.sh [scene] [duration_s]         -> .ws/plots/<scene>.png (and .bag)
#   bash scripts/plot_scene.sh --doc [scene] [duration_s]   -> doc/<scene>.png, the README's picture
#   bash scripts/plot_scene.sh [--doc] --predict serve 1.5   -> the same, played by predict_demo.launch:
#                                                               the predicted path drawn beside the played
# A scene with a robot (`robot:`, config/scenes/paddle_arm.yaml) is played by paddle_arm.launch,
# which publishes its URDF and joints; the others by demo.launch.
# Without --doc nothing tracked is written: the picture goes beside the bag in the ignored .ws/.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
to_doc=0
predict=0
while [ "${1:-}" = "--doc" ] || [ "${1:-}" = "--predict" ]; do
  [ "$1" = "--doc" ] && to_doc=1
  [ "$1" = "--predict" ] && predict=1
  shift
done
scene="${1:-billiards_break}"
duration="${2:-3}"
[ -f "$repo/config/scenes/$scene.yaml" ] || { echo "no scene '$scene' in config/scenes/"; exit 2; }
PACKAGES+=(python3-rosbag python3-matplotlib python3-yaml)
install_packages
build_package
source_workspace
out="$ws/plots"
mkdir -p "$out"
picture="$out/$scene.png"
[ "$to_doc" = 0 ] || picture="$repo/doc/$scene.png"
start_private_master "$out/roscore.log"
rm -f "$out/$scene.bag"
rosbag record -O "$out/$scene.bag" /body_states /impacts /predicted_path >"$out/rosbag.log" 2>&1 &
recorder=$!
pids+=("$recorder")
echo "== scene $scene for $duration s with the node, recorded by rosbag"
# The player waits a second so that the recorder is connected before the first state.
if [ "$predict" = 1 ]; then
  roslaunch collision_response predict_demo.launch scene:="$scene" duration:="$duration" \
    >"$out/demo.log" 2>&1
elif grep -q '^  robot:' "$repo/config/scenes/$scene.yaml"; then
  roslaunch collision_response paddle_arm.launch scene_file:="$repo/config/scenes/$scene.yaml" \
    duration:="$duration" >"$out/demo.log" 2>&1
else
  roslaunch collision_response demo.launch scene:="$scene" duration:="$duration" start_delay:=1.0 \
    report_restitution:=false >"$out/demo.log" 2>&1
fi
stop_process "$recorder"
rosbag info "$out/$scene.bag" | grep -E '^(duration|messages|topics)|^ +/' || true
/usr/bin/python3 "$repo/scripts/plot_bag.py" "$out/$scene.bag" "$picture" "$scene" \
  --scene "$repo/config/scenes/$scene.yaml"
echo "== wrote ${picture#"$repo/"} (bag: ${out#"$repo/"}/$scene.bag)"
