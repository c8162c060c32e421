#!/usr/bin/env bash
# A tumbling box's first contact beside Bullet's convex cast and FCL's continuous collision
# (issue 42, step 9; bench/tumbling_contact_peers.cpp): four motions whose first contact is known
# in closed form, over a 10 ms and a 1 ms step, each engine's error of the instant and its CPU per
# query. Installs libbullet-dev and libfcl-dev (each peer is otherwise skipped with a message),
# builds the one target and prints the Markdown table of doc/performance.md, "First contact of a
# tumbling body". A few seconds once built.
#   bash scripts/tumbling_contact_peers.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
case "${1:-}" in
  -h | --help) sed -n '2,8p' "${BASH_SOURCE[0]}"; exit 0 ;;
esac
PACKAGES+=(libbenchmark-dev libbullet-dev libfcl-dev)
install_packages
BUILD_TARGET=tumbling_contact_peers build_workspace >"$ws/build-tumbling-peers.log" 2>&1 ||
  { tail -40 "$ws/build-tumbling-peers.log"; exit 1; }
echo "== $(dpkg-query -W -f='${Package} ${Version}, ' libbullet-dev libfcl-dev 2>/dev/null |
  sed 's/, $//')"
"$ws/devel/lib/collision_response/tumbling_contact_peers"
