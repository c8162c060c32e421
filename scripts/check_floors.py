#!/usr/bin/env python3
"""Checks that no include of the core runs up a floor.

usage: check_floors.py [REPOSITORY]   (default: the folder above this script's)

The core's rooms (src/core/<room>/) stand on floors, listed below from the bottom up. A file of a
room includes another room's private header by room (`#include "solver/contact_forces.h"`); it
may include its own room's and those of the floors below, never a room on a floor above nor a
sibling room on its own floor (impact/ and contact/ each call the solvers below them, not each
other). The public headers (include/collision_response/core/) include no private header. A room
that is not listed is an error too: a new room is given its floor here. Tests, benchmarks and
fuzzers may reach any room and are not looked at.

Prints each include that breaks this (file:line: include: why) and exits 1 when there is one,
else prints how many includes it checked and exits 0.
"""
import pathlib
import re
import sys

# Bottom to top; rooms on one floor are siblings.
FLOORS = [
    ("geometry",),           # shapes, narrow phase, time of impact, ballistic and air motion
    ("solver",),             # solves over plain bodies and contacts: impulses, forces, sub-steps
    ("model",),              # the monitor's world and its motion models, candidate pairs
    ("impact", "contact"),   # the instant's resolver and the laws; lasting contact
    ("monitor",),            # the step, its schedule, playback and prediction
    ("scene", "calibration"),  # reading and checking a scene; fitting its coefficients
]
FLOOR_OF = {room: floor for floor, rooms in enumerate(FLOORS) for room in rooms}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
SUFFIXES = {".h", ".hpp", ".cpp"}


def includes_of(path):
    """(line number, included path) of each quoted include of `path`."""
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        match = INCLUDE.match(line)
        if match:
            yield number, match.group(1)


def main():
    default = pathlib.Path(__file__).resolve().parent.parent
    repository = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else default
    core = repository / "src" / "core"
    problems = []
    checked = 0
    for path in sorted(p for p in core.rglob("*") if p.suffix in SUFFIXES):
        room = path.relative_to(core).parts[0]
        where = path.relative_to(repository)
        if room not in FLOOR_OF:
            problems.append(f"{where}: room '{room}' has no floor in scripts/check_floors.py")
            continue
        for number, included in includes_of(path):
            target = included.split("/")[0]
            if target == "collision_response" or "/" not in included:
                continue  # a public header, or a header beside the file
            checked += 1
            if target not in FLOOR_OF:
                problems.append(f"{where}:{number}: {included}: room '{target}' has no floor")
            elif FLOOR_OF[target] > FLOOR_OF[room]:
                problems.append(f"{where}:{number}: {included}: {room}/ includes {target}/, "
                                f"a floor up")
            elif FLOOR_OF[target] == FLOOR_OF[room] and target != room:
                problems.append(f"{where}:{number}: {included}: {room}/ includes its sibling "
                                f"{target}/ on its floor")
    public = repository / "include" / "collision_response" / "core"
    for path in sorted(p for p in public.rglob("*") if p.suffix in SUFFIXES):
        for number, included in includes_of(path):
            checked += 1
            if included.split("/")[0] in FLOOR_OF:
                problems.append(f"{path.relative_to(repository)}:{number}: {included}: a public "
                                f"header includes a private one")
    for problem in problems:
        print(problem)
    if problems:
        return 1
    print(f"{checked} includes checked: none runs up a floor")
    return 0


if __name__ == "__main__":
    sys.exit(main())
