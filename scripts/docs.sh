#!/usr/bin/env bash
# The API documentation: the public headers of the core (include/collision_response/core/) and
# of the ROS layer (include/collision_response/ros/), and a page per message and service (msg/,
# srv/), as HTML in the ignored .ws/docs/html (open .ws/docs/html/index.html). Doxygen with the
# repository's Doxyfile; ROS's documentation jobs run rosdoc_lite with rosdoc.yaml instead, which
# Debian does not package.
# Installs Debian's doxygen if it is missing (nothing of ROS is needed). Prints Doxygen's warnings
# and their number (they do not fail the run), and fails when the documentation misses a part:
# an input the Doxyfile names that is not there, a header or a message without its page.
#   usage: bash scripts/docs.sh
set -euo pipefail
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

PACKAGES=(doxygen)
install_packages

cd "$repo"
docs="$ws/docs"
# From scratch, so that no page of a removed header or message stays behind.
rm -rf "$docs"
mkdir -p "$docs"
warnings="$docs/warnings.log"
started=$SECONDS
echo "== doxygen $(doxygen --version) (Doxyfile): the headers, the messages and services"
doxygen Doxyfile 2>"$warnings" >/dev/null
# Doxygen repeats a warning for each place a comment is shown: each is printed once.
sort -u -o "$warnings" "$warnings"
count=$(grep -c 'warning:' "$warnings" || true)
if [ "$count" -gt 0 ]; then
  cat "$warnings"
fi
echo "== $count Doxygen warnings (listed in $warnings) in $((SECONDS - started)) s"

missing=()
if grep -q 'is not a readable file or directory' "$warnings"; then
  missing+=("an INPUT of the Doxyfile (above)")
fi
html="$docs/html"
[ -f "$html/index.html" ] || missing+=("$html/index.html")
# A header's page: its name with each _ doubled, then _8h.html (Doxygen's escaping).
for header in include/collision_response/core/*.h include/collision_response/ros/*.h; do
  name=$(basename "$header" .h)
  [ -f "$html/${name//_/__}_8h.html" ] || missing+=("the page of $header")
done
# A message's or service's page: the label scripts/doxygen_message_page.sh gives it.
for definition in msg/*.msg srv/*.srv; do
  kind=${definition%%/*}
  name=$(basename "$definition")
  [ -f "$html/${kind}_${name%.*}.html" ] || missing+=("the page of $definition")
done
if [ ${#missing[@]} -gt 0 ]; then
  printf 'missing: %s\n' "${missing[@]}"
  exit 1
fi
echo "== the API documentation: $html/index.html"
