#!/usr/bin/env python3
"""Turns the prediction benchmark's output (bench/bench_prediction.cpp, run by
`bash scripts/accuracy.sh --prediction`) into doc/prediction.md and the plot doc/prediction.png.

usage: prediction_report.py PREDICTION_JSON DOC_DIR

PREDICTION_JSON is Google Benchmark's JSON (--benchmark_format=json --benchmark_out=...): every
row carries its errors against the serve's 40-digit reference and its CPU per query as counters.
With --benchmark_repetitions the medians are used.
"""
import json
import math
import pathlib
import platform
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TOLERANCES = ["1e-6", "1e-8", "1e-9", "1e-10", "1e-12"]
RATES = ["240", "1000", "10000"]
PEERS = [("bullet", "Bullet", "BM_BulletServe", "libbullet-dev"),
         ("ode", "ODE", "BM_OdeServe", "libode-dev")]
COLOUR = {"ours": "#1b9e77", "bullet": "#d95f02", "ode": "#7570b3"}
BUDGET_US = 100.0  # the budget for the 1 s drag and Magnus query at tolerance 1e-9
FLOOR = 1e-17  # errors of exactly 0 are drawn on this line
COMMAND = "bash scripts/accuracy.sh --prediction"


def rows(path):
    """name -> the row: the medians when repeated, else the single run."""
    data = json.loads(pathlib.Path(path).read_text())
    single, medians = {}, {}
    for row in data["benchmarks"]:
        name = row.get("run_name", row["name"])
        if row.get("aggregate_name") == "median":
            medians[name] = row
        elif row.get("run_type", "iteration") == "iteration":
            single.setdefault(name, row)
    single.update(medians)
    return single, data.get("context", {})


def fmt(value, digits=2):
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    if value == 0:
        return "0"
    if abs(value) >= 1e4 or abs(value) < 1e-2:
        return f"{value:.{digits - 1}e}"
    return f"{value:.{digits}g}"


def cpu(value):
    return "n/a" if value is None else f"{value:.3g}" if value < 100 else f"{value:.0f}"


def version(package):
    try:
        return subprocess.run(["dpkg-query", "-W", "-f=${Version}", package], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def processor():
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.machine()


def skipped(row):
    return row is None or row.get("error_occurred", False)


def table_row(engine, setting, row, bounces_only=None):
    if skipped(row):
        why = "not built" if row is None else "skipped: " + row.get("error_message", "")
        return f"| {engine} | {setting} | {why} | | | | | |"
    bounces_cpu = "" if bounces_only is None else cpu(
        None if skipped(bounces_only) else bounces_only.get("us_per_query"))
    return (f"| {engine} | {setting} | {fmt(row.get('bounce2_time_error'))} "
            f"| {fmt(row.get('bounce2_position_error'))} "
            f"| {fmt(row.get('bounce2_velocity_error'))} "
            f"| {fmt(row.get('crossing_position_error'))} "
            f"| {cpu(row.get('us_per_query'))} | {bounces_cpu} |")


def plot(table, path):
    """Error at the second bounce (centre, instant) against CPU per query, log-log."""
    figure, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    series = [("ours", "ours (1 s query with the plane's crossing)", "BM_PredictServe", TOLERANCES,
               "-", "o"),
              ("ours", "ours, bounces only (no plane)", "BM_PredictServeBounces", TOLERANCES, ":",
               "o")]
    series += [(key, f"{label}, stepped to the 2nd bounce", prefix, RATES, "-", "s")
               for key, label, prefix, _ in PEERS]
    for axis, metric, unit in zip(axes, ["bounce2_position_error", "bounce2_time_error"],
                                  ["centre (m)", "instant (s)"]):
        for key, label, prefix, settings, style, marker in series:
            points = []
            for setting in settings:
                row = table.get(f"{prefix}/{setting}")
                if skipped(row) or row.get(metric) is None:
                    continue
                points.append((row["us_per_query"], max(row[metric], FLOOR), setting))
            if not points:
                continue
            axis.plot([p[0] for p in points], [p[1] for p in points], style, marker=marker,
                      color=COLOUR[key], label=label, markerfacecolor="white" if style == ":" else
                      COLOUR[key])
            if style == "-":
                for x, y, setting in points:
                    text = setting if key == "ours" else f"{setting} Hz"
                    axis.annotate(text, (x, y), textcoords="offset points", xytext=(4, 4),
                                  fontsize=7, color=COLOUR[key])
        axis.axvline(BUDGET_US, color="grey", linewidth=0.8, linestyle="--")
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel("CPU per query (us)")
        axis.set_ylabel(f"error of the second bounce's {unit}")
        axis.grid(True, which="major", linewidth=0.4, alpha=0.6)
    handles, labels = axes[0].get_legend_handles_labels()
    figure.legend(handles, labels, fontsize=8, loc="lower center", ncol=len(labels))
    figure.suptitle("A topspin serve (drag and Magnus) against its 40-digit reference: error at "
                    "the second bounce against CPU (dashed: 100 us)", fontsize=9)
    figure.tight_layout(rect=(0, 0.07, 1, 1))
    figure.savefig(path, dpi=80)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    table, context = rows(sys.argv[1])
    doc = pathlib.Path(sys.argv[2])
    ten = table.get("BM_PredictGravityTenBounces")
    query = table.get("BM_PredictServe/1e-9")
    bounces = table.get("BM_PredictServeBounces/1e-9")
    damping = next((row["damping_rate"] for row in table.values()
                    if not skipped(row) and "damping_rate" in row), None)
    versions = ", ".join(f"{label} {version(package)}" for _, label, _, package in PEERS
                         if version(package))
    lines = [
        "# What a prediction's accuracy costs",
        "",
        f"Regenerate: `{COMMAND}` (it builds `bench_prediction`, runs it with",
        "`--benchmark_format=json` and writes this page and `doc/prediction.png` with",
        "`scripts/prediction_report.py`). CPU per query: this thread's CPU time per query, each",
        f"benchmark repeated for at least 0.5 s, on this project's machine ({processor()}, "
        f"{context.get('num_cpus', '?')} cores), every engine in the same run"
        + (f"; {versions}, Debian's." if versions else "."),
        "",
        "## The serve",
        "",
        "A table-tennis serve with topspin (`bench/accuracy/reference/serve_reference.py`, whose",
        "header gives the model): m = 2.7 g, r = 20 mm, C_d = 0.5, C_L = 0.2, rho = 1.2 kg/m^3,",
        "g = 9.81 m/s^2, from (-1.2, 0, 1.0) m at (3.75, 0.25, -2.25) m/s spinning at (0, 150, 0)",
        "rad/s; frictionless bounces with e = 0.9 on the table's top (z = 0.76 m). The reference",
        "is independent of the code under test: mpmath's Taylor-series integrator at 40 digits,",
        "each event solved to the working precision (`serve_reference.txt`, written to 20",
        "digits).",
        "Errors: the second bounce's instant, the ball's centre there and its velocity just after",
        "it, and the centre where it crosses the plane x = 1.6 m behind the table (after the",
        "second bounce); each the distance to the reference's.",
        "",
        "- **ours**: `predictImpacts` with gravity, spin, drag and Magnus, the table a `box` and a",
        "  floor plane, over a 1 s horizon with the crossing of x = 1.6 asked for, at each",
        "  `flight_integration_tolerance` (Dormand-Prince with dense output). The query's CPU is",
        "  shown with the crossing (the whole query) and without it (the same query, bounces",
        "  only): without samples, the crossing is looked for every",
        "  20 ms (`kCrossingSearchPeriod`) and then bisected on the body's motion in that piece",
        "  (doc/model.md, \"Prediction\").",
        "- **Bullet** and **ODE** (`bench/bench_prediction.cpp`, set up as their accuracy",
        "  harness sets them up: `bench/accuracy/bullet.cpp` with its bouncing settings,",
        "  `bench/accuracy/ode.cpp`): the ball against a static box and plane, restitution 0.9,",
        "  no friction, stepped at 240, 1,000 and 10,000 Hz from the same state to the second",
        "  time the vertical velocity turns from negative to positive; the step's end is the",
        "  bounce's instant and its state the bounce's (as the accuracy harness measures the",
        "  peers); the crossing is interpolated linearly between the two steps around it (stepped",
        "  on past the bounce, untimed). Their CPU per query is one whole serve to the second",
        "  bounce, the world built and torn down (0.58 s of flight, against ours' 1 s).",
        "  Neither has quadratic drag or a Magnus force. Drag's nearest stand-in is linear",
        "  damping, a drag -c v, with c = k v_mean matching the quadratic drag k |v| v at the",
        "  serve's mean speed (k = rho C_d A / 2m = 0.1396 1/m; v_mean the time average of |v| up",
        "  to the second bounce)" + (f": c = {damping:.4g} 1/s" if damping else "") + ", set as",
        "  Bullet's damping 1 - exp(-c) (it scales the velocity by (1 - d)^dt each step) and",
        "  ODE's 1 - exp(-c dt) (it scales it by 1 - d each step). The Magnus force has no",
        "  stand-in: the peers fly the serve without its topspin's downward force (about a tenth",
        "  of gravity), so their error has a floor that no rate lowers.",
        "",
        "| engine | setting | 2nd bounce: instant (s) | centre (m) | velocity after (m/s) "
        "| crossing of x = 1.6: centre (m) | CPU per query (us) | CPU without the crossing (us) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for tolerance in TOLERANCES:
        lines.append(table_row("ours", f"tolerance {tolerance}",
                               table.get(f"BM_PredictServe/{tolerance}"),
                               table.get(f"BM_PredictServeBounces/{tolerance}")))
    for _, label, prefix, _ in PEERS:
        for rate in RATES:
            lines.append(table_row(label, f"{int(rate):,} Hz", table.get(f"{prefix}/{rate}")))
    lines += ["", "![error at the second bounce against CPU per query](prediction.png)", ""]

    notes = []
    budget = []
    for row, what in [(ten, "10 bounces under gravity only (`BM_PredictGravityTenBounces`"),
                      (query, "the 1 s drag and Magnus query at tolerance 1e-9, with the plane's "
                              "crossing (`BM_PredictServe/1e-9`"),
                      (bounces, "the same query without the crossing "
                                "(`BM_PredictServeBounces/1e-9`")]:
        if not skipped(row):
            verdict = "within" if row["us_per_query"] <= BUDGET_US else "over"
            budget.append(f"{row['us_per_query']:.0f} us for {what}, {verdict})")
    if budget:
        notes.append(f"The core's budget for a 1 s query through air is {BUDGET_US:.0f} us: "
                     + "; ".join(budget) + ".")
    peer_rows = [table[f"{prefix}/{rate}"] for _, _, prefix, _ in PEERS for rate in RATES
                 if not skipped(table.get(f"{prefix}/{rate}"))]
    if not skipped(query) and peer_rows:
        ours = query["bounce2_position_error"]
        best = min(row["bounce2_position_error"] for row in peer_rows)
        notes.append(f"At tolerance 1e-9 our second bounce's centre is off by {fmt(ours)} m; the "
                     f"best peer setting's by {fmt(best)} m ({best / ours:.1e} times as much).")
    restitutions = [f"{label} {int(rate):,} Hz: "
                    f"{fmt(table[f'{prefix}/{rate}'].get('bounce1_restitution'), 3)}"
                    for _, label, prefix, _ in PEERS for rate in RATES
                    if not skipped(table.get(f"{prefix}/{rate}"))]
    if restitutions:
        notes.append("The peers' first bounce as stepped (vertical velocity after over before; "
                     "0.9 in the model): " + "; ".join(restitutions) + ". Bullet's rebound "
                     "depends on where its step finds the contact: found before the touch (within "
                     "its contact threshold) it is a speculative contact, and the gap left over "
                     "the step is taken off the rebound, the more the finer the step (where no "
                     "bounce is left, its \"second bounce\" is a flicker of the vertical velocity "
                     "as the ball lands); found after the touch, a shallow penetration is pushed "
                     "out through the velocity (0.2 of the depth per step), adding to it.")
    if not skipped(ten):
        notes.append("Gravity only, 10 bounces on a floor (`BM_PredictGravityTenBounces`: thrown "
                     "level at 0.5 m/s from 1 m, e = 0.9, no crossing asked for): the 10th "
                     f"bounce's instant is {fmt(ten['bounce10_time_error'])} s from its closed "
                     "form.")
    for note in notes:
        lines += [note, ""]
    doc.mkdir(parents=True, exist_ok=True)
    (doc / "prediction.md").write_text("\n".join(lines))
    plot(table, doc / "prediction.png")


if __name__ == "__main__":
    main()
