#!/usr/bin/env bash
# The real cube tosses replayed by the peer engines (issue 42, step 8): Bullet, ODE and MuJoCo
# (each when installed), started from each toss's first recorded state, their e and mu fitted on
# every 4th toss and measured on the others against the recording (bench/cube_tosses/); then our
# core's prediction of the same tosses, over the span it covers (through a lasting contact it
# models, to the recording's end, where the error at rest is taken; it ends at one it does not
# model yet, saying which), fitted the same way and also run at each peer's fitted pair. Writes
# doc/cube_tosses.md and doc/cube_tosses.png.
#   bash scripts/cube_tosses.sh [TOSSES_DIR]   # about 3 minutes on one core
# TOSSES_DIR: the tosses' folder (default: ../shared/data/cube_tosses beside the project's root,
# or COLLISION_RESPONSE_CUBE_TOSSES). They are read where they are, never copied; missing, the
# script says so and stops.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
case "${1:-}" in
  -h | --help) sed -n '2,12p' "${BASH_SOURCE[0]}"; exit 0 ;;
esac
tosses="${1:-${COLLISION_RESPONSE_CUBE_TOSSES:-$repo/../shared/data/cube_tosses}}"
if [ ! -d "$tosses" ]; then
  echo "skipped: no cube tosses at $tosses (give their folder as the argument)" >&2
  exit 0
fi
tosses=$(cd "$tosses" && pwd)
PACKAGES+=(libbullet-dev libode-dev libmujoco-dev pkg-config python3-numpy python3-matplotlib)
install_packages
for target in cube_tosses_peers cube_tosses_ours; do
  BUILD_TARGET=$target build_workspace >"$ws/build-cube-tosses.log" 2>&1 ||
    { tail -40 "$ws/build-cube-tosses.log"; exit 1; }
done
out="$ws/cube_tosses"
mkdir -p "$out"
echo "== the tosses in $tosses: each peer fitted on every 4th, measured on the others"
"$ws/devel/lib/collision_response/cube_tosses_peers" --tosses "$tosses" \
  --out "$out/results.json" 2>"$out/run.log" || { tail -20 "$out/run.log"; exit 1; }
grep -v '^   e .*widths$' "$out/run.log" || true
echo "== ours: fitted over the span its prediction covers, and at each peer's fitted e and mu"
mapfile -t at < <(/usr/bin/python3 -c '
import json, sys
for p in json.load(open(sys.argv[1]))["peers"]:
    if p["fits_restitution"]:
        print("--at", p["name"], p["fit"]["restitution"], p["fit"]["friction"], sep="\n")
' "$out/results.json")
"$ws/devel/lib/collision_response/cube_tosses_ours" --tosses "$tosses" --out "$out/ours.json" \
  "${at[@]}" 2>"$out/ours.log" || { tail -20 "$out/ours.log"; exit 1; }
grep -v '^   e .*at rest there$' "$out/ours.log" || true
versions=$(dpkg-query -W -f='${Package} ${Version}, ' libbullet-dev libode-dev libmujoco-dev \
  2>/dev/null | sed 's/, $//')
/usr/bin/python3 "$repo/scripts/cube_tosses_report.py" "$out/results.json" "$tosses" \
  "$repo/doc" "Debian's $versions" --ours "$out/ours.json"
echo "== wrote doc/cube_tosses.md and doc/cube_tosses.png"
