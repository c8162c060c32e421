#!/usr/bin/env bash
# The demo: install, build, start a private ROS master, the collision_response node and the
# scene player on a scene (default: the billiards break; any scene of config/scenes/ by name),
# print each impact as one line, and stop everything it started.
#   bash scripts/demo.sh [scene] [duration_s]     e.g. bash scripts/demo.sh cradle 2
#   RVIZ=1 bash scripts/demo.sh billiards_break 30  also installs rviz and opens it on the markers
# Exits 0 only when the scene played and at least one impact was printed; otherwise it says
# what failed and where the log is, and exits 1.
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
build_package
source_workspace

log="$ws/demo.log"
printed="$ws/demo.out"
# Our own master first, on a port that is ours (start_private_master checks, and tries another
# port if one was taken in the meantime); roslaunch then uses it and starts no other.
start_private_master "$ws/roscore.log"
rviz_arg=false
[ "$rviz" = 1 ] && rviz_arg=true
echo "== roslaunch collision_response demo.launch scene:=$scene duration:=$duration rviz:=$rviz_arg"
echo "   (a private master at $ROS_MASTER_URI; the scene's file: config/scenes/$scene.yaml)"
# roslaunch starts the node, the player and the printer, and stops them all when the player has
# played the scene. Only the printer's and player's lines are shown; the rest is in the log.
roslaunch collision_response demo.launch scene:="$scene" duration:="$duration" rviz:="$rviz_arg" \
  >"$log" 2>&1 &
launch_pid=$!
pids+=("$launch_pid")
tail -n +1 --pid="$launch_pid" -f "$log" | grep --line-buffered -E '^(impact|restitution|done)' |
  tee "$printed" || true
launch_status=0
wait "$launch_pid" || launch_status=$?

# What went wrong, if anything: roslaunch's own failure, a node that died (a bad scene stops
# the node at once), or a scene played without a single impact.
plain_log() { sed 's/\x1b\[[0-9;]*m//g; s/\x1b\]2;[^\x07]*\x07//g' "$log"; }
problems=()
[ "$launch_status" -eq 0 ] || problems+=("roslaunch exited with status $launch_status")
died=$(plain_log | grep -m1 'process has died' || true)
[ -z "$died" ] || problems+=("a node died: $died")
impacts=$(grep -c '^impact' "$printed" || true)
[ "$impacts" -gt 0 ] ||
  problems+=("no impact was printed (do the scene's bodies meet within $duration s?)")
if [ ${#problems[@]} -gt 0 ]; then
  echo "== demo failed:"
  printf '   %s\n' "${problems[@]}"
  plain_log | grep -E 'FATAL|ERROR' | head -5 || true
  echo "   (full log: $log; the master's: $ws/roscore.log)"
  exit 1
fi
