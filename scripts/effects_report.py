#!/usr/bin/env python3
"""Turns the output of scripts/bench_effects.sh into doc/effects.md."""
import json
import pathlib
import platform
import sys


def medians(path):
    times = {}
    for row in json.loads(path.read_text())["benchmarks"]:
        if row.get("aggregate_name") == "median":
            scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3}[row["time_unit"]]
            name = row["run_name"].split("/")[0]  # without "/iterations:N"
            times[name] = (row["cpu_time"] * scale, row.get("impacts/update"))
    return times


def main():
    folder, target = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    times = medians(folder / "bench_effects.json")
    count = lambda build, work: int((folder / f"{build}-{work}.count").read_text().split()[0])
    impact_none = times["BM_ImpactNone"][0]
    update_none = times["BM_UpdateNone"][0]
    lines = [
        "# What each effect costs",
        "",
        "Regenerate: `bash scripts/bench_effects.sh` (Google Benchmark medians of 5 repetitions,",
        f"CPU time, on a {platform.machine()} machine of this project; and valgrind callgrind).",
        "",
        "## Per impact: a ball striking the floor obliquely with spin (`computeCollision`)",
        "",
        "| effects | CPU per impact | vs none |",
        "|---|---|---|",
    ]
    for label, name in [("none (the seed's model)", "BM_ImpactNone"),
                        ("friction", "BM_ImpactFriction"),
                        ("friction + spin", "BM_ImpactFrictionSpin")]:
        lines.append(f"| {label} | {times[name][0] * 1e9:.0f} ns | {times[name][0] / impact_none:.2f} |")
    lines += [
        "",
        "## Per state update: 100 balls in a closed box, every state at 100 Hz, continuous",
        "",
        "| effects | CPU per update | vs none | impacts per update |",
        "|---|---|---|---|",
    ]
    for label, name in [("none", "BM_UpdateNone"), ("gravity", "BM_UpdateGravity"),
                        ("friction", "BM_UpdateFriction"),
                        ("friction + spin", "BM_UpdateFrictionSpin"),
                        ("gravity + friction + spin", "BM_UpdateAll"),
                        ("gravity + drag", "BM_UpdateGravityDrag"),
                        ("gravity + spin + drag + magnus", "BM_UpdateGravityAir")]:
        cpu, impacts = times[name]
        lines.append(f"| {label} | {cpu * 1e6:.0f} us | {cpu / update_none:.2f} | {impacts:.2f} |")
    lines += [
        "",
        "Each figure is the mean over one run's first 200 updates (2 s), in each repetition. The",
        "effects change the motion, so each scene makes its own impacts: gravity makes the balls",
        "fall and bounce on the floor until they rest, friction takes energy out. Later the box",
        "costs more with every effect on: the balls gather and roll in contact, and each curved",
        "contact between two balls is integrated (doc/model.md, \"Lasting contact\"). Measured by hand",
        "on the same workload for 8 s: 11 s of CPU in all; an update took 0.1-2 ms up to 4 s,",
        "10-40 ms from 4.5 to 7.5 s, and the worst 0.75 s (at 7.06 s, 132 impacts).",
        "",
        "## An effect that is off, against a build without the effects",
        "",
        "The same workloads with every effect off, counted in instructions (deterministic), in the",
        "core as built and in the core built with `src/core/impact/effect_selection_none.cpp` instead of",
        "`effect_selection.cpp` (a build in which no scene or request can turn an effect on):",
        "",
        "| workload | this build, effects off | build without effects | ratio |",
        "|---|---|---|---|",
    ]
    for label, work in [("100,000 impacts (`computeCollision`)", "impacts"),
                        ("200 state updates of the box", "updates")]:
        on, bare = count("effects_instructions", work), count("effects_instructions_noeffects", work)
        lines.append(f"| {label} | {on:,} | {bare:,} | {on / bare:.4f} |")
    lines.append("")
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text("\n".join(lines))


if __name__ == "__main__":
    main()
