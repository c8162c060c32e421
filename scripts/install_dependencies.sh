#!/usr/bin/env bash
# Installs the package's Debian dependencies: every <*depend> of package.xml (build, run and
# test), each turned into the Debian packages that provide it (ROS 1 comes from Debian: a ROS
# package `foo_msgs` is its headers `libfoo-msgs-dev`, its definitions `ros-foo-msgs` and its
# Python module `python3-foo-msgs`). The list is read from package.xml each time, so the two
# cannot drift: a dependency with no Debian name below stops the script and names it.
#   bash scripts/install_dependencies.sh           # apt-get update, apt-get install -y (sudo if not root)
#   bash scripts/install_dependencies.sh --print   # only print the Debian packages
# Safe to run again: installs nothing when everything is there. scripts/common.sh reads the same
# list for the repository's own scripts.

# ROS package key (as package.xml names it) -> the Debian packages that provide it on Debian 12.
declare -A DEBIAN_PACKAGES=(
  [catkin]="catkin build-essential cmake"
  [roscpp]="libroscpp-dev"
  [rospy]="python3-rospy"
  [rosout]="rosout"
  [roslaunch]="python3-roslaunch python3-rosmaster"
  [rosbash]="rosbash"
  [rostopic]="python3-rostopic"
  [rosservice]="python3-rosservice"
  [rosnode]="python3-rosnode"
  [rosparam]="python3-rosparam"
  [nodelet]="libnodelet-dev libnodeletlib-dev libnodeletlib-tools"
  [pluginlib]="pluginlib-dev"
  [message_generation]="ros-message-generation"
  [message_runtime]="ros-message-runtime python3-genpy"
  [std_msgs]="libstd-msgs-dev ros-std-msgs python3-std-msgs"
  [geometry_msgs]="libgeometry-msgs-dev ros-geometry-msgs python3-geometry-msgs"
  [visualization_msgs]="libvisualization-msgs-dev ros-visualization-msgs python3-visualization-msgs"
  [diagnostic_msgs]="libdiagnostic-msgs-dev ros-diagnostic-msgs python3-diagnostic-msgs"
  [diagnostic_updater]="libdiagnostic-updater-dev"
  [dynamic_reconfigure]="libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure"
  [tf2]="libtf2-dev"
  [tf2_ros]="libtf2-ros-dev python3-tf2-ros tf2-tools"
  [tf2_eigen]="libtf2-eigen-dev"
  [tf2_geometry_msgs]="libtf2-geometry-msgs-dev python3-tf2-geometry-msgs"
  [tf2_msgs]="libtf2-msgs-dev python3-tf2-msgs"
  [tf2_py]="python3-tf2"
  [eigen]="libeigen3-dev"
  [urdf]="liburdf-dev"
  [tinyxml2]="libtinyxml2-dev"
  [roslib]="libroslib-dev"
  [geometric_shapes]="libgeometric-shapes-dev"
  [libqhull]="libqhull-dev"
  [robot_state_publisher]="ros-robot-state-publisher"
  [sensor_msgs]="libsensor-msgs-dev ros-sensor-msgs python3-sensor-msgs"
  [rosbag]="python3-rosbag"
  [python3-yaml]="python3-yaml"
  [boost]="libboost-dev"
  [rostest]="librostest-dev python3-rostest python3-rosmaster"
  [rosunit]="python3-rosunit"
  [gtest]="googletest libgtest-dev"
)

# Every dependency key of package.xml, once each, in order. One tag a line, without attributes
# (a condition or version would need a real parser: refused by name rather than misread).
package_dependency_keys() {
  local package_xml=$1 line key
  declare -A seen=()
  while IFS= read -r line; do
    if [[ $line =~ ^[[:space:]]*\<((build_|build_export_|exec_|test_|buildtool_)?depend)\>([^<]+)\</(build_|build_export_|exec_|test_|buildtool_)?depend\>[[:space:]]*$ ]]; then
      key=${BASH_REMATCH[3]}
      [ -n "${seen[$key]:-}" ] || { seen[$key]=1; echo "$key"; }
    elif [[ $line =~ \<(build_|build_export_|exec_|test_|buildtool_)?depend[[:space:]\>] ]]; then
      echo "$package_xml: cannot read this dependency (one tag a line, no attributes): $line" >&2
      return 1
    fi
  done <"$package_xml"
}

# The Debian packages for every dependency of package.xml, one a line.
package_debian_packages() {
  local package_xml=$1 keys key status=0
  keys=$(package_dependency_keys "$package_xml") || return 1
  for key in $keys; do
    if [ -z "${DEBIAN_PACKAGES[$key]:-}" ]; then
      echo "$package_xml: dependency '$key' has no Debian package in scripts/install_dependencies.sh" >&2
      status=1
      continue
    fi
    printf '%s\n' ${DEBIAN_PACKAGES[$key]}
  done | awk '!seen[$0]++'
  return $status
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  set -euo pipefail
  package_xml="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/package.xml"
  mapfile -t packages < <(package_debian_packages "$package_xml")
  # The list is complete only when every key had its packages (a failure above said which).
  package_debian_packages "$package_xml" >/dev/null
  if [ "${1:-}" = "--print" ]; then
    printf '%s\n' "${packages[@]}"
    exit 0
  fi
  missing=()
  for package in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
      missing+=("$package")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    echo "== the ${#packages[@]} Debian packages of package.xml's dependencies are installed"
    exit 0
  fi
  sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  echo "== installing ${#missing[@]} of the ${#packages[@]} Debian packages of package.xml's dependencies: ${missing[*]}"
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
  echo "== installed"
fi
