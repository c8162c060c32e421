#!/usr/bin/env python3
"""Turns the accuracy benchmark's output (scripts/accuracy.sh) into doc/accuracy.md and the
data and gnuplot script of doc/accuracy.png.

usage: accuracy_report.py OUT_DIR DOC_DIR
"""
import json
import math
import pathlib
import platform
import subprocess
import sys

ENGINES = [("ours", "continuous"), ("ours", "discrete"), ("bullet", "default"),
           ("bullet", "bouncing"), ("ode", "default")]
LABEL = {("ours", "continuous"): "ours, continuous", ("ours", "discrete"): "ours, discrete",
         ("bullet", "default"): "Bullet, defaults", ("bullet", "bouncing"): "Bullet, bouncing settings",
         ("ode", "default"): "ODE"}
FLOOR = 1e-17  # exact answers (error 0) are plotted here


def fmt(value, digits=2):
    if value is None:
        return "n/a"
    if value == 0:
        return "0"
    return f"{value:.{digits}g}" if abs(value) >= 1e-3 and abs(value) < 1e4 else f"{value:.{digits}e}"


def package_version(name):
    try:
        return subprocess.run(["dpkg-query", "-W", "-f=${Version}", name], capture_output=True,
                              text=True, check=False).stdout or "?"
    except OSError:
        return "?"


def main():
    out, doc = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    errors = json.loads((out / "errors.json").read_text())
    timing = {}
    for row in json.loads((out / "timing.json").read_text())["benchmarks"]:
        scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[row["time_unit"]]
        # Google Benchmark appends the run's options ("/min_time:0.200") to the name.
        name = row["name"].split("/min_time:")[0]
        timing[name] = row["cpu_time"] * scale
    runs = errors["runs"]
    for run in runs:
        run["cpu"] = timing.get(run["name"])  # s per run of the scene
    durations = {"drop_test": 2.5, "cradle": 0.1, "billiards_break": 1.0, "tunnelling": 0.1,
                 "sphere_gas": 2.0}

    def find(scene, engine, variant, rate, effects="none"):
        for run in runs:
            if (run["scene"], run["engine"], run["variant"], run["rate"], run["effects"]) == (
                    scene, engine, variant, rate, effects):
                return run
        return None

    lines = [
        "# What accuracy costs in time",
        "",
        "Regenerate: `bash scripts/accuracy.sh` (about two minutes on 2 cores). Errors are",
        "against exact answers (closed forms; for the break, our continuous detection, whose",
        "instants do not depend on the rate); CPU time is Google Benchmark's, per run of the",
        f"scene, on a {platform.machine()} machine of this project. Bullet "
        f"{package_version('libbullet-dev')} (Debian's, single precision) and ODE "
        f"{package_version('libode-dev')} from Debian, in the same run on the same scenes.",
        "",
        "Settings: **ours** is the core's `ImpactMonitor` fed at the state rate by a source that",
        "applies its responses (the scene player's loop, `core::Playback`), continuous or discrete",
        "detection. **Bullet, defaults**: `btDiscreteDynamicsWorld`, `btDbvtBroadphase`, sequential",
        "impulse solver, spheres and static planes, friction 0, one step per state at the rate.",
        "**Bullet, bouncing settings** (what its maintainers recommend for bouncing): restitution",
        "velocity threshold 0, no warm starting, split impulse, CCD on (motion threshold one",
        "radius, swept sphere half a radius). **ODE**: `dWorldStep`, contact joints with",
        "`dContactBounce`, bounce = e, bounce_vel = 0, mu = 0, default ERP and CFM. Bullet",
        "multiplies restitutions: each body's is set so that every product is the scene's",
        "coefficient.",
        "",
    ]

    def table(scene, title, columns, note=""):
        lines.extend([f"## {title}", ""])
        if note:
            lines.extend([note, ""])
        header = ["setting", "rate (Hz)"] + [c[0] for c in columns] + ["CPU per update", "CPU per run"]
        lines.append("| " + " | ".join(header) + " |")
        lines.append("|" + "---|" * len(header))
        for engine, variant in ENGINES:
            for rate in (10, 30, 60, 100, 300, 1000):
                run = find(scene, engine, variant, rate)
                if run is None:
                    continue
                cpu = run["cpu"]
                per_update = None if cpu is None else cpu / max(run["updates"], 1)
                cells = [LABEL[(engine, variant)], str(rate)] + [c[1](run) for c in columns] + [
                    "n/a" if per_update is None else f"{per_update * 1e6:.3g} us",
                    "n/a" if cpu is None else f"{cpu * 1e3:.3g} ms"]
                lines.append("| " + " | ".join(cells) + " |")
        for run in runs:
            if run["scene"] == scene and run["effects"] != "none":
                cpu = run["cpu"]
                lines.append("| " + " | ".join(
                    [f"ours, continuous, {run['effects']} on", str(int(run["rate"]))] +
                    [c[1](run) for c in columns] +
                    ["n/a" if cpu is None else f"{cpu / max(run['updates'], 1) * 1e6:.3g} us",
                     "n/a" if cpu is None else f"{cpu * 1e3:.3g} ms"]) + " |")
        lines.append("")

    table("drop_test", "Drop test: nine balls of the seed's table dropped 1 m onto concrete",
          [("e from the first apex (rel.)", lambda r: fmt(r["restitution"])),
           ("apex after 3 bounces (rel.)", lambda r: fmt(r["apex"])),
           ("instant of the first impact (s)", lambda r: fmt(r["instant"]))],
          "e = sqrt(h'/h) with h' the apex of the parabola through the three samples around the "
          "top of the first flight (exact for samples on a parabola); n/a: fewer than three samples "
          "in the flight. The instant: ours reports it; the others' is the first sample after it.")
    table("cradle", "Newton's cradle: five touching balls, e = 1",
          [("worst velocity after (m/s)", lambda r: fmt(r["velocity"])),
           ("energy drift (rel.)", lambda r: fmt(r["energy_drift"])),
           ("momentum drift (rel.)", lambda r: fmt(r["momentum_drift"])),
           ("instant (s)", lambda r: fmt(r["instant"]))],
          "The textbook answer: the first four balls at rest, the last at 1 m/s.")
    table("billiards_break", "Billiards break: the cue ball at 6 m/s into a rack of fifteen",
          [("velocity RMS after 1 s (m/s)", lambda r: fmt(r["velocity"])),
           ("instant of the first impact (s)", lambda r: fmt(r["instant"])),
           ("impacts", lambda r: str(r["impacts"]) if r["engine"] == "ours" else "n/a")])
    table("tunnelling", "Tunnelling: a 0.02 m ball at 50 m/s against a 0.01 m post",
          [("missed", lambda r: "yes" if r["missed"] else "no"),
           ("instant (s)", lambda r: fmt(r["instant"])),
           ("velocity after (m/s)", lambda r: fmt(r["velocity"]))])
    table("sphere_gas", "Sphere gas: 64 elastic balls in a closed box for 2 s",
          [("energy drift (rel.)", lambda r: fmt(r["energy_drift"])),
           ("impacts", lambda r: str(r["impacts"]) if r["engine"] == "ours" else "n/a")])

    k = errors["kernels"]
    kernel_time = {name: timing.get(f"kernel/{name}") for name in
                   ("impact/double", "impact/float", "time_of_impact/double", "time_of_impact/float")}
    lines += [
        "## Float against double (the core's kernels)",
        "",
        "Worst error against long double over 100,000 random cases, and CPU time per call:",
        "",
        "| kernel | double: error | float: error | double: CPU | float: CPU |",
        "|---|---|---|---|---|",
        f"| impact velocity (m/s, speeds ~1) | {fmt(k['impact_velocity_error']['double'])} | "
        f"{fmt(k['impact_velocity_error']['float'])} | {kernel_time['impact/double'] * 1e9:.3g} ns | "
        f"{kernel_time['impact/float'] * 1e9:.3g} ns |",
        f"| time of impact (s, times ~1) | {fmt(k['time_of_impact_error']['double'])} | "
        f"{fmt(k['time_of_impact_error']['float'])} | {kernel_time['time_of_impact/double'] * 1e9:.3g} ns | "
        f"{kernel_time['time_of_impact/float'] * 1e9:.3g} ns |",
        "",
        "The monitor runs in double only: float saves little CPU here and costs 9 digits.",
        "",
    ]

    # Key ratios.
    def cpu(scene, engine, variant, rate):
        run = find(scene, engine, variant, rate)
        return None if run is None or run["cpu"] is None else run["cpu"]

    key = ["## Key ratios", ""]
    for rate in (30, 100, 1000):
        c, d = cpu("drop_test", "ours", "continuous", rate), cpu("drop_test", "ours", "discrete", rate)
        if c and d:
            key.append(f"- Drop test at {rate} Hz: continuous costs {c / d:.2f}x discrete "
                       f"({c * 1e3:.3g} ms vs {d * 1e3:.3g} ms per run); e error "
                       f"{fmt(find('drop_test', 'ours', 'continuous', rate)['restitution'])} vs "
                       f"{fmt(find('drop_test', 'ours', 'discrete', rate)['restitution'])}.")
    ode60 = cpu("drop_test", "ode", "default", 60)
    for rate in (30, 60, 100):
        c = cpu("drop_test", "ours", "continuous", rate)
        if c and ode60:
            key.append(f"- Our continuous drop test at {rate} Hz against ODE at 60 Hz: "
                       f"{c / ode60:.2f}x the CPU; e error "
                       f"{fmt(find('drop_test', 'ours', 'continuous', rate)['restitution'])} vs "
                       f"{fmt(find('drop_test', 'ode', 'default', 60)['restitution'])}.")
    for scene in ("drop_test", "sphere_gas", "billiards_break"):
        c = cpu(scene, "ours", "continuous", 100)
        for engine, variant in (("bullet", "default"), ("bullet", "bouncing"), ("ode", "default")):
            p = cpu(scene, engine, variant, 100)
            if c and p:
                key.append(f"- {scene} at 100 Hz: ours (continuous) {c * 1e3:.3g} ms, "
                           f"{LABEL[(engine, variant)]} {p * 1e3:.3g} ms ({c / p:.2f}x).")
    settings_end = lines.index("coefficient.") + 2
    lines[settings_end:settings_end] = key + [""]
    (doc / "accuracy.md").write_text("\n".join(lines) + "\n")

    # The plot: error against CPU time per simulated second, four panels.
    panels = [("drop_test", "restitution", "drop test: error of e from the first bounce"),
              ("drop_test", "instant", "drop test: error of the instant of impact (s)"),
              ("sphere_gas", "energy_drift", "sphere gas: energy drift over 2 s"),
              ("billiards_break", "velocity", "billiards break: velocity RMS error (m/s)")]
    data = out / "accuracy.dat"
    with data.open("w") as f:
        for scene, metric, _ in panels:
            for engine, variant in ENGINES:
                f.write(f"# {scene} {metric} {engine} {variant}\n")
                for rate in (10, 30, 60, 100, 300, 1000):
                    run = find(scene, engine, variant, rate)
                    if run is None or run["cpu"] is None or run[metric] is None:
                        continue
                    value = max(run[metric], FLOOR)
                    f.write(f"{run['cpu'] / durations[scene] * 1e3} {value} {rate}\n")
                f.write("\n\n")
    script = [
        "set terminal pngcairo size 1700,1000 font 'sans,10'",
        f"set output '{doc / 'accuracy.png'}'",
        "set multiplot layout 2,2 title 'Error against CPU time (log-log); points at 10, 30, 60, "
        "100, 300, 1000 Hz; exact answers drawn at 1e-17'",
        "set logscale xy",
        "set format y '10^{%L}'",
        "set xlabel 'CPU ms per simulated second'",
        "set key outside right top",
        "set grid",
    ]
    styles = ["lc rgb '#1b9e77' pt 7", "lc rgb '#7570b3' pt 5", "lc rgb '#d95f02' pt 9",
              "lc rgb '#e7298a' pt 11", "lc rgb '#66a61e' pt 13"]
    index = 0
    for scene, metric, title in panels:
        script.append(f"set title '{title}'")
        plots = []
        for (engine, variant), style in zip(ENGINES, styles):
            plots.append(f"'{data}' index {index} using 1:2 with linespoints {style} "
                         f"title '{LABEL[(engine, variant)]}'")
            index += 1
        script.append("plot " + ", \\\n     ".join(plots))
    script.append("unset multiplot")
    (out / "accuracy.gnuplot").write_text("\n".join(script) + "\n")


if __name__ == "__main__":
    main()
