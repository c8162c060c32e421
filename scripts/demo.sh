#!/usr/bin/env bash
# The demo: install, build, start a private ROS master, the collision_response node and the
# scene player on a scene (default: the billiards break; any scene of config/scenes/ by name),
# print each impact as one line, and stop everything it started.
#   bash scripts/demo.sh [scene] [duration_s]     e.g. bash scripts/demo.sh cradle 2
#   RVIZ=1 bash scripts/demo.sh billiards_break 30  also installs rviz and opens it on the markers
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
scene="${1:-billiards_break}"
duration="${2:-3}"
[ -f "$repo/config/scenes/$scene.yaml" ] || {
  echo "no scene '$scene'; scenes: $(cd "$repo/config/scenes" && ls *.yaml | sed 's/\.yaml//' | tr '\n' ' ')"
  exit 2
}
rviz="${RVIZ:-0}"
[ "$rviz" = 1 ] && PACKAGES+=(rviz)
install_packages
build_workspace >"$ws/build.log" 2>&1 || { tail -40 "$ws/build.log"; echo "build failed (log: $ws/build.log)"; exit 1; }
source_workspace
export ROS_MASTER_URI="http://localhost:$(free_port)"

rviz_arg=false
[ "$rviz" = 1 ] && rviz_arg=true
echo "== roslaunch collision_response demo.launch scene:=$scene duration:=$duration rviz:=$rviz_arg"
echo "   (a private master at $ROS_MASTER_URI; the scene's file: config/scenes/$scene.yaml)"
# roslaunch starts the master, the node, the player and the printer, and stops them all when
# the player has played the scene. Only the printer's lines are shown; the rest is in the log.
roslaunch collision_response demo.launch scene:="$scene" duration:="$duration" rviz:="$rviz_arg" \
  >"$ws/demo.log" 2>&1 &
launch_pid=$!
trap 'kill -INT $launch_pid 2>/dev/null || true' EXIT
tail -n +1 --pid=$launch_pid -f "$ws/demo.log" | grep --line-buffered -E '^(impact|restitution|done)' || true
wait $launch_pid 2>/dev/null || true
if grep -q -E 'FATAL|ERROR' "$ws/demo.log"; then
  echo "== errors from the nodes (full log: $ws/demo.log):"
  grep -E 'FATAL|ERROR' "$ws/demo.log" | head -5
fi
