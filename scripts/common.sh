# Shared by scripts/demo.sh and scripts/test.sh: install what the package needs from Debian's
# archive, and build it as a standalone catkin package in the ignored folder .ws/ (build space
# .ws/build, devel space .ws/devel). No symbolic link back into the repository, so rosrun's
# search of the package folder meets no loop.
# Safe to run again: installs only what is missing, rebuilds incrementally.

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws="$repo/.ws"
mkdir -p "$ws"

# Debian 12 packages: ROS 1 (catkin, roscpp, messages, tf2, rostest), Eigen, gtest, and what the
# benchmarks and fuzzers use.
PACKAGES=(
  build-essential cmake catkin
  libroscpp-dev rosout ros-message-generation ros-message-runtime
  libstd-msgs-dev ros-std-msgs libgeometry-msgs-dev ros-geometry-msgs
  libtf2-dev libtf2-ros-dev libtf2-eigen-dev libeigen3-dev
  librostest-dev python3-rostest python3-roslaunch python3-rosmaster python3-rosservice
  rosbash python3-rostopic python3-rosnode python3-rosparam tf2-tools
  libnodelet-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev
  libvisualization-msgs-dev ros-visualization-msgs
  libdiagnostic-updater-dev libdiagnostic-msgs-dev ros-diagnostic-msgs
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  python3-rospy python3-genpy python3-geometry-msgs catkin-lint
  googletest libgtest-dev clang libclang-rt-14-dev
)

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

install_packages() {
  local missing=()
  for package in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
      missing+=("$package")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    echo "== all ${#PACKAGES[@]} Debian packages are installed"
    return 0
  fi
  echo "== installing ${#missing[@]} Debian packages: ${missing[*]}"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${PACKAGES[@]}" >/dev/null
}

# BUILD_TARGET: build only that target (default: all).
build_workspace() {
  echo "== building in $ws"
  # catkin writes the test environment (build/catkin_generated/setup_cached.sh) when it
  # configures, with only the devel folders that exist then: made first, so that a first build
  # puts the generated Python messages on the tests' PYTHONPATH (rospy tests need them).
  mkdir -p "$ws/devel/lib/python3/dist-packages" "$ws/devel/lib/pkgconfig"
  # /usr/bin/python3: a python3 earlier on PATH (pyenv) may lack catkin_pkg.
  cmake -S "$repo" -B "$ws/build" -DCATKIN_DEVEL_PREFIX="$ws/devel" -DPython3_EXECUTABLE=/usr/bin/python3 \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCOLLISION_RESPONSE_WERROR=ON "$@" &&
    cmake --build "$ws/build" --target "${BUILD_TARGET:-all}" -- -j2
}

source_workspace() {
  # setup.bash reads unset variables; relax -u while it runs.
  set +u
  # shellcheck disable=SC1091
  source "$ws/devel/setup.bash"
  set -u
  # A name every process can resolve, also on machines whose hostname does not resolve.
  export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
}

# A free TCP port for a private ROS master, so that the scripts never touch a running one.
free_port() {
  /usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])'
}

# A private ROS master on a free port (ROS_MASTER_URI exported), stopped with every process in
# `pids` when the script exits. usage: start_private_master LOG_FILE
pids=()
start_private_master() {
  local port
  port=$(free_port)
  export ROS_MASTER_URI="http://localhost:$port"
  trap 'for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done; wait 2>/dev/null || true' EXIT
  roscore -p "$port" >"$1" 2>&1 &
  pids+=($!)
  until rosparam list >/dev/null 2>&1; do sleep 0.2; done
}
