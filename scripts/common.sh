# Shared by scripts/demo.sh and scripts/test.sh: install what the package needs from Debian's
# archive, and build it as a standalone catkin package in the ignored folder .ws/ (build space
# .ws/build, devel space .ws/devel). No symbolic link back into the repository, so rosrun's
# search of the package folder meets no loop.
# Safe to run again: installs only what is missing, rebuilds incrementally.

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws="$repo/.ws"
mkdir -p "$ws"

# Debian 12 packages: the package's own dependencies, read from package.xml
# (scripts/install_dependencies.sh, the command the README gives for one's own workspace), and
# the tools the scripts use beyond them (ROS's command-line tools are dependencies of the
# package): catkin_lint, and clang with its sanitizer and fuzzer runtimes. Tried on Debian 12
# (bookworm) and Debian 13 (trixie).
source "$repo/scripts/install_dependencies.sh"
mapfile -t PACKAGES < <(package_debian_packages "$repo/package.xml")
package_debian_packages "$repo/package.xml" >/dev/null || exit 1
# libclang-rt-dev: clang's runtimes for its default version, by the name every release has
# (Debian 12's clang 14, Debian 13's clang 19); llvm: its llvm-symbolizer, which turns the
# sanitizers' reports into files and lines.
PACKAGES+=(
  catkin-lint clang libclang-rt-dev llvm
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
  local started=$SECONDS
  as_root apt-get update -qq
  # Without the packages they only recommend (llvm's development files, rosdep, manual pages):
  # 397 packages rather than 464 on a fresh Debian 12, none of them used here.
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    "${PACKAGES[@]}" >/dev/null
  echo "== installed in $((SECONDS - started)) s"
}

# BUILD_TARGET: build only that target (default: all).
build_workspace() {
  # catkin writes the test environment (build/catkin_generated/setup_cached.sh) when it
  # configures, with only the devel folders that exist then: made first, so that a first build
  # puts the generated Python messages on the tests' PYTHONPATH (rospy tests need them).
  mkdir -p "$ws/devel/lib/python3/dist-packages" "$ws/devel/lib/pkgconfig"
  echo "== configuring with cmake (build space $ws/build, devel space $ws/devel)"
  # /usr/bin/python3: a python3 earlier on PATH (pyenv) may lack catkin_pkg.
  # -O2 without debug information: the code of RelWithDebInfo (the package's default), in two
  # thirds of its compile time (a heavy file: 25 s with -g, 18 s without). Debugging:
  # configure your own build, or add -DCMAKE_CXX_FLAGS=-g here.
  cmake -S "$repo" -B "$ws/build" -DCATKIN_DEVEL_PREFIX="$ws/devel" -DPython3_EXECUTABLE=/usr/bin/python3 \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" \
    -DCOLLISION_RESPONSE_WERROR=ON "$@" || return
  echo "== compiling (2 jobs)"
  cmake --build "$ws/build" --target "${BUILD_TARGET:-all}" -- -j2
}

# build_workspace with its whole output in .ws/build.log, saying on the terminal what it does:
# the log's place, each stage, and the progress every tenth of the way (a first build takes
# about 2 minutes on 2 cores, a rebuild seconds). On failure, the log's last lines.
build_package() {
  local log="$ws/build.log" status=0 started=$SECONDS
  # The pipeline's status is build_workspace's, also where the caller has no pipefail.
  local -
  set -o pipefail
  echo "== building collision_response in $ws (first build about 2 minutes on 2 cores; log: $log)"
  build_workspace "$@" 2>&1 | tee "$log" | awk '
    /^== / { print "  " substr($0, 4); fflush(); next }
    match($0, /^\[ *[0-9]+%\]/) {
      percent = substr($0, 2, RLENGTH - 3) + 0
      if (percent >= shown + 10) { shown = percent - percent % 10; print "  " $0; fflush() }
    }' || status=$?
  if [ "$status" -ne 0 ]; then
    tail -40 "$log"
    echo "build failed (log: $log)"
    return 1
  fi
  echo "== built in $((SECONDS - started)) s"
}

# The one clang build with AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer's
# instrumentation, in .ws/sanitizers: the same objects serve the unit tests of
# scripts/sanitize.sh and the fuzzers of scripts/fuzz.sh. Output in .ws/sanitizers/build.log.
#   usage: build_sanitized TARGET...
sanitized="$ws/sanitizers"
build_sanitized() {
  # -O1 -g1: line tables only, what the sanitizers' reports need (file and line), and a quarter
  # less compile time than -g. COLLISION_RESPONSE_UNITY: the core in unity groups (a fifth less
  # to compile) and core_tests without libFuzzer's counters (CMakeLists.txt's last part).
  local flags="-O1 -g1 -fsanitize=fuzzer-no-link,address,undefined"
  flags+=" -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
  local link="-fsanitize=address,undefined"
  mkdir -p "$sanitized"
  # The build before this one had two sanitizer builds (g++ for the tests, clang for the
  # fuzzers' objects): their folders go.
  rm -rf "$ws/sanitize" "$ws/fuzz/core" "$ws/fuzz/ros"
  echo "== building ${*} with clang -fsanitize=fuzzer-no-link,address,undefined in $sanitized (log: $sanitized/build.log)"
  {
    CC=clang CXX=clang++ cmake -S "$repo" -B "$sanitized/build" -DCATKIN_DEVEL_PREFIX="$sanitized/devel" \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
      -DCMAKE_BUILD_TYPE=None -DCATKIN_ENABLE_TESTING=ON -DCOLLISION_RESPONSE_FUZZERS=ON \
      -DCOLLISION_RESPONSE_UNITY=ON \
      -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$link" \
      -DCMAKE_SHARED_LINKER_FLAGS="$link" &&
      cmake --build "$sanitized/build" --target "$@" -- -j2
  } >>"$sanitized/build.log" 2>&1 || {
    tail -30 "$sanitized/build.log"
    echo "the sanitizer build failed (log: $sanitized/build.log)"
    return 1
  }
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

# The process id of the master that answers at ROS_MASTER_URI within 1 s (nothing if none).
master_pid() {
  /usr/bin/python3 -c 'import os, socket, xmlrpc.client
socket.setdefaulttimeout(1.0)
try:
    print(xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"]).getPid("/")[2])
except Exception:
    pass' 2>/dev/null
}

# Stops one process: SIGINT (ROS's clean shutdown), SIGTERM after 5 s, SIGKILL after 10 s.
stop_process() {
  local signal
  for signal in INT TERM KILL; do
    kill -"$signal" "$1" 2>/dev/null || return 0
    for _ in $(seq 50); do
      kill -0 "$1" 2>/dev/null || { wait "$1" 2>/dev/null || true; return 0; }
      sleep 0.1
    done
  done
}

# Every process in `pids` is stopped when the script exits, the last started first.
pids=()
stop_started() {
  local i
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do stop_process "${pids[i]}"; done
}
trap stop_started EXIT

# A private ROS master on a free port (ROS_MASTER_URI exported), stopped when the script exits.
# The port is free when free_port looks, but another process (another master, any server) can
# take it before roscore binds it: then roscore fails, or a master that is not ours answers.
# So the master is ours only when the one answering is the child of our roscore; otherwise
# another port is tried.   usage: start_private_master LOG_FILE
start_private_master() {
  local log=$1 attempt port roscore_pid answering deadline
  for attempt in 1 2 3 4 5; do
    port=$(free_port)
    export ROS_MASTER_URI="http://localhost:$port"
    roscore -p "$port" >"$log" 2>&1 &
    roscore_pid=$!
    deadline=$((SECONDS + 20))
    while [ "$SECONDS" -lt "$deadline" ]; do
      kill -0 "$roscore_pid" 2>/dev/null || break
      answering=$(master_pid)
      if [ -n "$answering" ]; then
        # /proc/PID/stat: "pid (name) state ppid ..."
        if [ "$(cut -d' ' -f4 "/proc/$answering/stat" 2>/dev/null)" = "$roscore_pid" ]; then
          pids+=("$roscore_pid")
          return 0
        fi
        break # someone else's master on this port
      fi
      sleep 0.1
    done
    stop_process "$roscore_pid"
    echo "== port $port was taken before the master could bind it (attempt $attempt of 5); another port"
  done
  echo "could not start a ROS master (last log: $log):"
  tail -5 "$log"
  return 1
}
