#!/usr/bin/env python3
"""Turns scripts/performance.sh's output into doc/performance.md.

usage: performance_report.py OUT_DIR doc/performance.md
       performance_report.py --pile-only SCALE_JSON doc/performance.md   (the piles' sections
       alone, from a run of `bench_scale --benchmark_filter=Pile`: at rest, and dropped)
       performance_report.py --predict-only OUT_DIR doc/performance.md   (the prediction
       service's section alone, from OUT_DIR/predict*.json: `node_benchmark _mode:=predict`)
"""
import json
import pathlib
import platform
import sys


PILE_TITLE = "## A pile at rest (lasting contact)"


def read_scale(path):
    """Google Benchmark's rows by name (options such as /min_time cut off): (CPU s, row)."""
    scale = {}
    for row in json.loads(path.read_text())["benchmarks"]:
        unit = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[row["time_unit"]]
        scale[row["name"].split("/min_time")[0]] = (row["cpu_time"] * unit, row)
    return scale


def pile_section(scale):
    """BM_PileUpdate beside BM_BulletPileUpdate: piles of balls at rest in a box."""
    def name(kind, columns, rows, layers, gap, gravity=1):
        return (f"{kind}/columns:{columns}/rows:{rows}/layers:{layers}/gap_um:{gap}"
                f"/gravity:{gravity}")

    def ms(value):
        if value is None:
            return "n/a"
        return f"{value:.3g} s" if value >= 1 else f"{value * 1e3:.3g} ms"

    def label(columns, rows, layers, gap):
        spacing = "touching" if gap == 0 else f"{gap / 1000:g} mm apart"
        if layers == 1:
            return f"{columns * rows:,} balls, one layer {columns} x {rows}, {spacing}"
        return f"{columns * rows * layers:,} balls, a stack {columns} x {rows} x {layers}, {spacing}"

    cases = [(40, 25, 1, 1000), (40, 25, 1, 0), (10, 10, 10, 0), (5, 5, 1, 0), (10, 10, 1, 0),
             (15, 15, 1, 0)]
    cases = [c for c in cases if name("BM_PileUpdate", *c) in scale]
    if not cases:
        return []
    lines = [
        PILE_TITLE, "",
        "Balls (radius 0.05 m, 0.1 kg, e = 0.5, frictionless) at rest in a box (a floor and four "
        "walls touching the outer balls): one layer on the floor, its balls 1 mm apart or "
        "touching, or a stack of touching layers, each ball right on the one below. 100 Hz: "
        "every body's state each update from a source that follows the monitor "
        "(`core::Playback`, the scene player's and the accuracy benchmark's loop: it moves the "
        "bodies by the monitor's model, resting contact and stepped clusters included). Timed: "
        "the monitor's step alone (CPU time); the source's own time per update beside it. "
        "Gravity on: every ball has a lasting contact with the floor or the ball below; gravity "
        "off: the same balls at rest with no force. Bullet: the same pile, gravity on, one "
        "`stepSimulation` of 0.01 s per update, no sleeping. 'stepped bodies': ours' bodies in "
        "stepped clusters after the last update (`StepReport::stepped_bodies`); 'lasting "
        "contacts': those reported with a force, per update (stepped, the neighbours in a layer "
        "are reported too, with the solve's residue of a force). "
        "`bench_scale --benchmark_filter=Pile` (one run, on a 2-core machine shared with "
        "other builds: CPU times hold better than wall times, ratios within the run best).", "",
        "| pile | ours, gravity on | ours, gravity off | gravity on / off | source per update "
        "| lasting contacts | stepped bodies | Bullet | ours / Bullet |",
        "|---|---|---|---|---|---|---|---|---|"]
    for case in cases:
        on = scale.get(name("BM_PileUpdate", *case, 1))
        off = scale.get(name("BM_PileUpdate", *case, 0))
        bullet = scale.get(name("BM_BulletPileUpdate", *case, 1))
        lines.append(
            f"| {label(*case)} | {ms(on[0])} | {ms(off[0] if off else None)} | "
            f"{f'{on[0] / off[0]:.2f}' if off else 'n/a'} | {ms(on[1].get('source_ms', 0) / 1e3)} | "
            f"{on[1].get('contacts/update', 0):.0f} | {on[1].get('stepped_bodies', 0):.0f} | "
            f"{ms(bullet[0] if bullet else None)} | "
            f"{f'{on[0] / bullet[0]:.2f}' if bullet else 'n/a'} |")

    def drift(bench, case, gravity=1):
        row = scale.get(name(bench, *case, gravity))
        return None if row is None else row[1].get("drift_m", 0)
    lines += [
        "",
        "Drift (the farthest any centre moved from the lattice, from the run's last states), "
        "gravity on: " + "; ".join(
            f"{label(*case)}: ours {drift('BM_PileUpdate', case):.2g} m"
            + (f", Bullet {drift('BM_BulletPileUpdate', case):.2g} m"
               if drift("BM_BulletPileUpdate", case) is not None else "")
            for case in cases) + ".", ""]
    off = [scale[name("BM_PileUpdate", *c, 0)][0] for c in cases
           if name("BM_PileUpdate", *c, 0) in scale]
    fallbacks = [label(*c) for c in cases
                 if scale[name("BM_PileUpdate", *c, 1)][1].get("fallbacks/update", 0) > 0]
    stepped = [(c, scale[name("BM_PileUpdate", *c, 1)][1]) for c in cases]
    whole = [label(*c) for c, row in stepped if row.get("stepped_bodies", 0) == row["bodies"]]
    lines += [
        "With gravity on, a ball at rest can move g h^2 = 0.98 mm in a 10 ms sub-step (h), so "
        "balls up to twice that apart are near each other: every pile here whose balls are "
        "within 2 mm of their neighbours is one connected set, and from "
        "`Scene::stepped_cluster_min_bodies` (32) bodies a stepped cluster, advanced by "
        "gap-keeping sub-steps (doc/model.md, \"Lasting contact\"), the layer 1 mm apart included. "
        "Stepped whole in this run: " + ("; ".join(whole) if whole else "none") + ". "
        "Gravity off, nothing is stepped (stepping needs the steady force): the balls at rest, "
        "each touching or not, cost the exact model "
        + (f"{ms(min(off))} to {ms(max(off))} per update" if off else "n/a") + ". Sub-steps "
        "held still by a fallback (a solve that could not keep the gaps): "
        + ("; ".join(fallbacks) if fallbacks else "none") + ".", ""]
    return lines


SERVICE_TITLE = "## The collision service"
PREDICT_TITLE = "## The prediction service"


def predict_section(out):
    """node_benchmark's predict rounds (OUT_DIR/predict*.json): ~predict_impacts on the serve
    beside empty_service's ~echo_prediction, which answers the same bytes without physics."""
    rounds = [json.loads(path.read_text()) for path in sorted(out.glob("predict*.json"))]
    if not rounds:
        return []
    ratio_p50 = sorted(r["predict_p50"] / r["echo_p50"] for r in rounds)
    ratio_mean = sorted(r["predict_mean"] / r["echo_mean"] for r in rounds)
    # The round whose p50 ratio is the median stands for the run; every round is listed.
    run = sorted(rounds, key=lambda r: r["predict_p50"] / r["echo_p50"])[len(rounds) // 2]
    extra = run["predict_p50"] - run["echo_p50"]
    lines = [
        PREDICT_TITLE,
        "",
        f"{len(rounds)} rounds of {run['calls']:,} calls each, alternating, over persistent "
        "connections: `~predict_impacts` of a node on `config/scenes/serve.yaml` asked for the "
        "serve (the scene's ball from (-1.2, 0, 1.0) m at (3.75, 0.25, -2.25) m/s spinning at "
        f"150 rad/s about y, through air; horizon 1.2 s, at most 2 impacts: {run['impacts']} on "
        "the table), beside `~echo_prediction` of `empty_service`, which answers the same request "
        "with a response of the same size and no physics: the floor of a round trip carrying the "
        "same bytes. Ratios (prediction / echo) of the rounds, p50: "
        + ", ".join(f"{r:.3f}" for r in ratio_p50) + "; mean: "
        + ", ".join(f"{r:.3f}" for r in ratio_mean) + ". The median round:",
        "",
        "| service | mean | p50 | p99 | request | response |",
        "|---|---|---|---|---|---|",
        f"| `~predict_impacts` | {run['predict_mean'] * 1e6:.0f} us | "
        f"{run['predict_p50'] * 1e6:.0f} us | {run['predict_p99'] * 1e6:.0f} us | "
        f"{run['predict_request_bytes']} bytes | {run['predict_response_bytes']} bytes |",
        f"| echo of the same bytes | {run['echo_mean'] * 1e6:.0f} us | "
        f"{run['echo_p50'] * 1e6:.0f} us | {run['echo_p99'] * 1e6:.0f} us | "
        f"{run['echo_request_bytes']} bytes | {run['echo_response_bytes']} bytes |",
        f"| ratio | {run['predict_mean'] / run['echo_mean']:.3f} | "
        f"{run['predict_p50'] / run['echo_p50']:.3f} | | | |",
        "",
        "What the node adds is the prediction. In one process (one thread's CPU: 10,000 "
        "answers in five batches, the best batch), the core's prediction of the serve "
        "(`core::predictImpacts` on the node's scene, the drag and Magnus flight integrated to "
        f"each bounce) costs {run['in_process'] * 1e6:.0f} us an answer, and the node's whole "
        "answer (deserialising the request, `answerPredictImpacts`, serialising the answer) "
        f"{run['in_process_answer'] * 1e6:.0f} us"
        + (" (the same within this machine's noise: the messages cost little beside the "
           "prediction)" if abs(run["in_process_answer"] - run["in_process"])
           < 0.1 * run["in_process"] else "")
        + (f", {run['in_process_answer'] / extra * 100:.0f} % of the {extra * 1e6:.0f} us "
           "between the two round trips (p50)." if extra > 0 else
           f"; the two round trips' p50 differ by {extra * 1e6:.0f} us.")
        + (f" The node's main thread, which answers, spent {run['node_cpu_per_call'] * 1e6:.0f} "
           "us of CPU per call over the timed calls (`/proc/<pid>/task/<pid>/stat`)."
           if run.get("node_cpu_per_call") is not None else "")
        + " Where the node's extra CPU went (measured by hand once, on 2026-12-05, not by this "
        "script: `perf record -t` "
        "of the node's main thread): glibc gave the heap freed after each answer back to the "
        "kernel (`brk`, whose TLB flush reaches the CPUs of the node's other threads) and "
        "faulted it in again on the next; the same node started with "
        "`GLIBC_TUNABLES=glibc.malloc.trim_threshold=268435456` spent 180 to 305 us of its main "
        "thread's CPU per call instead of 325 to 435 us, and its p50 round trip was 314 to "
        "451 us instead of 491 to 606 us (three rounds of each, alternately)."
        + " Regenerate with the rest: `bash scripts/performance.sh`.",
        "",
    ]
    return lines


DROPPED_PILE_TITLE = "## A pile dropped into a box, with friction and spin (profile)"
IMPACT_TITLE = "## One impact of many bodies"
DROPPED_TITLE = "## Piles dropped into a box: what keeping up costs"

# Issue 26's targets: the monitor's CPU per simulated second of the pile with friction and spin
# at 100 Hz (s), by balls.
DROPPED_TARGETS = {8: 0.05, 100: 1.0, 1000: 5.0}


def dropped_rows(scale):
    """BM_DroppedPile and its peers' rows by (engine, balls, friction, rate): the row's counters."""
    rows = {}
    for name, (_, row) in scale.items():
        parts = name.split("/")
        if not parts[0].endswith("DroppedPile"):
            continue
        if row.get("error_occurred"):
            continue
        args = dict(part.split(":") for part in parts[1:] if ":" in part)
        engine = {"BM_DroppedPile": "ours", "BM_BulletDroppedPile": "Bullet",
                  "BM_MujocoDroppedPile": "MuJoCo"}[parts[0]]
        rows[(engine, int(args["balls"]), int(args["friction"]), int(args.get("rate", 100)))] = row
    return rows


def dropped_targets(scale):
    """The Targets table's rows for the dropped piles."""
    rows = dropped_rows(scale)
    lines = []
    for balls, target in DROPPED_TARGETS.items():
        ours = rows.get(("ours", balls, 1, 100))
        if ours is None:
            continue
        cpu = ours["cpu_per_simulated_s"]
        lines.append(f"| a pile of {balls:,} dropped with friction and spin, 100 Hz: the monitor "
                     f"at most {target:g} s of CPU per simulated second | {cpu:.3g} s (worst "
                     f"update {ours['worst_update_s']:.3g} s; the scene player's motion "
                     f"{ours['source_cpu_per_simulated_s']:.3g} s) | {'yes' if cpu <= target else 'no'} |")
    return lines


def dropped_section(scale):
    """BM_DroppedPile beside BM_BulletDroppedPile and BM_MujocoDroppedPile."""
    rows = dropped_rows(scale)
    if not rows:
        return []

    def cell(row, key, digits=3):
        return f"{row[key]:.{digits}g}" if row is not None and key in row else "not run"

    lines = [
        DROPPED_TITLE,
        "",
        "Issue 26's piles (`bench/dropped_pile.h`): balls of r = 0.05 m and 0.1 kg dropped from a "
        "loose lattice 0.12 m apart (each nudged by up to 5 mm) into a closed box, e = 0.5, "
        "`friction` and `spin` with mu = 0.5 (or frictionless), restitution threshold 0, their "
        "first simulated second. Ours at 100 Hz as the scene player plays it (`core::Playback` "
        "moves the bodies by the monitor's model, the monitor finds the impacts, the player applies "
        "them): the monitor's CPU per simulated second, its worst update, the player's share, and "
        "the bodies the exact work budget handed to stepping (doc/model.md, \"Lasting contact\"). "
        "Bullet 3 (single precision, `btSequentialImpulseConstraintSolver`, no sleeping, "
        "restitution and friction sqrt(0.5) on every body and wall, which Bullet multiplies) and "
        "MuJoCo 2.2 (condim 3, mu 0.5, its default soft contact: it has no coefficient of "
        "restitution) at 100 and 300 Hz, one step a period. Deepest: the deepest any ball went "
        "into another or a wall at the updates' instants. `bench_scale "
        "--benchmark_filter=DroppedPile` (one run).",
        "",
        "| pile | ours: CPU per simulated s | worst update | scene player per simulated s | "
        "deepest | stepped over the budget | Bullet 100 Hz: CPU / deepest | Bullet 300 Hz | "
        "MuJoCo 100 Hz | MuJoCo 300 Hz |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for balls, friction in ((8, 1), (27, 1), (100, 1), (1000, 1), (1000, 0)):
        ours = rows.get(("ours", balls, friction, 100))
        peers = []
        for engine in ("Bullet", "MuJoCo"):
            for rate in (100, 300):
                peer = rows.get((engine, balls, friction, rate))
                peers.append(f"{cell(peer, 'cpu_per_simulated_s')} s / "
                             f"{peer['deepest_m'] * 1e3:.1f} mm" if peer else "not run")
        label = f"{balls:,} balls, " + ("friction and spin" if friction else "frictionless")
        lines.append(
            f"| {label} | {cell(ours, 'cpu_per_simulated_s')} s | {cell(ours, 'worst_update_s')} s "
            f"| {cell(ours, 'source_cpu_per_simulated_s')} s | {cell(ours, 'deepest_m', 2)} m | "
            f"{cell(ours, 'fallbacks', 6)} | " + " | ".join(peers) + " |")
    lines += [
        "",
        "MuJoCo is not run on the piles of 1,000: Debian's MuJoCo 2.2 solves its contacts "
        "densely (njmax x njmax), and one simulated second of that pile with friction had not "
        "ended after 15 minutes of CPU.",
        "",
    ]
    return lines


def replace_dropped_targets(target, rows):
    """The dropped piles' rows of the Targets table of an existing doc/performance.md."""
    if not rows:
        return
    text = target.read_text().split("\n")
    kept = [line for line in text if not line.startswith("| a pile of ")]
    start = kept.index("## Targets")
    end = start + 1
    while end < len(kept) and not (kept[end] == "" and kept[end - 1].startswith("|")):
        end += 1
    target.write_text("\n".join(kept[:end] + rows + kept[end:]))


def replace_section(target, title, lines, after=None):
    """Writes a section into an existing doc/performance.md in place of the one of that title
    (else after the section titled `after`, or before the node's)."""
    if not lines:
        return
    text = target.read_text()
    if title in text:
        head, rest = text.split(title, 1)
        tail = rest[rest.index("\n## "):] if "\n## " in rest else ""
        text = head + "\n".join(lines) + "\n" + tail.lstrip("\n")
    elif after is not None and after in text:
        head, rest = text.split(after, 1)
        end = rest.index("\n## ") + 1 if "\n## " in rest else len(rest)
        text = (head + after + rest[:end].rstrip("\n") + "\n\n" + "\n".join(lines) + "\n"
                + rest[end:])
    else:
        head, tail = text.split("## The node over ROS", 1)
        text = head + "\n".join(lines) + "\n## The node over ROS" + tail
    target.write_text(text)


def main():
    if sys.argv[1] == "--pile-only":
        # Only the piles' benchmarks were run: their sections of the existing page.
        scale = read_scale(pathlib.Path(sys.argv[2]))
        target = pathlib.Path(sys.argv[3])
        if any(name.startswith("BM_PileUpdate") for name in scale):
            replace_section(target, PILE_TITLE, pile_section(scale))
        replace_section(target, DROPPED_TITLE, dropped_section(scale))
        replace_dropped_targets(target, dropped_targets(scale))
        return
    if sys.argv[1] == "--predict-only":
        # Only the prediction service's rounds were run: its section of the existing page.
        replace_section(pathlib.Path(sys.argv[3]), PREDICT_TITLE,
                        predict_section(pathlib.Path(sys.argv[2])), after=SERVICE_TITLE)
        return
    out, target = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    scale = read_scale(out / "scale.json")
    rounds = [json.loads(path.read_text()) for path in sorted(out.glob("service*.json"))]
    ratio_p50 = sorted(r["compute_p50"] / r["empty_p50"] for r in rounds)
    ratio_mean = sorted(r["compute_mean"] / r["empty_mean"] for r in rounds)
    # The round whose p50 ratio is the median stands for the run; every round is listed.
    service = sorted(rounds, key=lambda r: r["compute_p50"] / r["empty_p50"])[len(rounds) // 2]
    load = json.loads((out / "load.json").read_text())
    memory_path = out / "memory.json"
    memory = json.loads(memory_path.read_text()) if memory_path.exists() else None

    pair = scale["BM_PairResponse"][1]
    lines = [
        "# Performance",
        "",
        "Regenerate: `bash scripts/performance.sh` (about 15 minutes with the 10-minute memory",
        f"run; `MEMORY_SECONDS=60` for a shorter one). One {platform.machine()} machine of this",
        "project with 2 cores, shared: times move by tens of percent between runs, ratios less.",
        "",
        "## Targets",
        "",
        "| target | measured | met |",
        "|---|---|---|",
        f"| {load['bodies']:,} bodies at {load['rate']:g} Hz within one core (continuous) | "
        f"{load['cpu_share'] * 100:.0f} % of one core | {'yes' if load['cpu_share'] < 1 else 'no'} |",
        f"| `~compute_collision` within 1.05x of an empty service's round trip | "
        f"{service['compute_p50'] / service['empty_p50']:.3f}x (p50), "
        f"{service['compute_mean'] / service['empty_mean']:.3f}x (mean) | "
        f"{'yes' if service['compute_p50'] / service['empty_p50'] <= 1.05 else 'no'} (p50) |",
    ]
    gas_ratio = [(n, scale[f"BM_GasUpdate/{n}"][0] / scale[f"BM_BulletGasUpdate/{n}"][0])
                 for n in (1000, 10000, 100000)
                 if f"BM_GasUpdate/{n}" in scale and f"BM_BulletGasUpdate/{n}" in scale]
    if gas_ratio:
        lines.append("| less time per update than Bullet on the same gas | " +
                     ", ".join(f"{r:.2f}x at {n:,}" for n, r in gas_ratio) +
                     f" | {'yes' if all(r < 1 for _, r in gas_ratio) else 'no'} |")
    lines += dropped_targets(scale)
    lines += [
        "",
        "## Core (Google Benchmark)",
        "",
        f"- Pair responses (`resolveImpact`): {pair['items_per_second'] / 1e6:.0f} million per "
        "second on one core.",
        "",
        "A gas of spheres (radius 0.05 m, one per 0.5 m cube of a closed box, speeds to 2 m/s, "
        "e = 1), every body's state each update at 100 Hz, continuous detection; beside it "
        "Bullet 3 (Debian's, single precision: `btDbvtBroadphase`, sequential impulse solver, "
        "one `stepSimulation` of 0.01 s per update) on the same gas:",
        "",
        "| bodies | ours per update | impacts per update | Bullet per update | ours / Bullet |",
        "|---|---|---|---|---|",
    ]
    for n in (1000, 10000, 100000):
        ours = scale.get(f"BM_GasUpdate/{n}")
        bullet = scale.get(f"BM_BulletGasUpdate/{n}")
        if ours is None:
            continue
        ratio = f"{ours[0] / bullet[0]:.2f}" if bullet else "n/a"
        lines.append(f"| {n:,} | {ours[0] * 1e3:.2f} ms | {ours[1].get('impacts/update', 0):.0f} | "
                     f"{bullet[0] * 1e3:.2f} ms | {ratio} |" if bullet else
                     f"| {n:,} | {ours[0] * 1e3:.2f} ms | {ours[1].get('impacts/update', 0):.0f} | n/a | n/a |")
    lines += [""] + pile_section(scale) + dropped_section(scale)
    lines += [
        "## The node over ROS",
        "",
        f"{load['bodies']:,} bodies in one `BodyStateArray` at {load['rate']:g} Hz for "
        f"{load['seconds']:g} s (the driver applies the impacts it hears, as the scene player "
        "does), continuous detection:",
        "",
        "| measure | value |",
        "|---|---|",
        f"| CPU share of one core (the node's user + system time / wall time) | {load['cpu_share'] * 100:.0f} % |",
        f"| latency from publishing a state array to receiving its impacts, p50 | {load['latency_p50'] * 1e3:.2f} ms |",
        f"| latency, p99 | {load['latency_p99'] * 1e3:.2f} ms |",
        f"| the node's own arrival-to-publication latency (its `/diagnostics`), median of the 1 s means | {load.get('node_latency_median_of_means', float('nan')) * 1e3:.2f} ms |",
        f"| the node's own arrival-to-publication latency, worst | {load.get('node_latency_max', float('nan')) * 1e3:.2f} ms |",
        f"| impacts | {load['impacts']:,} over {load['updates']:,} updates |",
        "",
        "The first latency is the driver's round trip: both transports (the array of states is",
        "about 1.3 MB), the node, and the driver's own process, all on the same 2 cores; its p99",
        "is the scheduler's. The node's own figure runs from a message's arrival in its callback",
        "to the publication of the impacts it revealed.",
        "",
    ]
    profile = out / "profile.txt"
    if profile.exists() and profile.read_text().strip():
        lines += [
            "Where the node's time goes (`perf record` of the node for 8 s of a second run of the",
            "same load, so that sampling does not cost the measured run; the first fifteen",
            "functions by share of the node's samples):",
            "",
            "| share | library | function |",
            "|---|---|---|",
        ]
        for row in profile.read_text().splitlines():
            parts = row.split(None, 3)
            if len(parts) < 4:
                continue
            share, library, _, function = parts
            function = function.split("<")[0].split("(")[0].strip()
            lines.append(f"| {share} | {library} | `{function}` |")
        lines.append("")
    lines += [
        SERVICE_TITLE,
        "",
        f"{len(rounds)} rounds of {service['calls']:,} calls each, alternating, over persistent "
        "connections, against `std_srvs/Empty` served by a node of the same build "
        "(`empty_service`); the collision service from a node serving the services alone. "
        "Ratios (ours / empty) of the rounds, p50: " + ", ".join(f"{r:.3f}" for r in ratio_p50) +
        "; mean: " + ", ".join(f"{r:.3f}" for r in ratio_mean) + ". The median round:",
        "",
        "| service | mean | p50 | p99 |",
        "|---|---|---|---|",
        f"| `~compute_collision` | {service['compute_mean'] * 1e6:.0f} us | {service['compute_p50'] * 1e6:.0f} us | {service['compute_p99'] * 1e6:.0f} us |",
        f"| empty service | {service['empty_mean'] * 1e6:.0f} us | {service['empty_p50'] * 1e6:.0f} us | {service['empty_p99'] * 1e6:.0f} us |",
        f"| ratio | {service['compute_mean'] / service['empty_mean']:.3f} | {service['compute_p50'] / service['empty_p50']:.3f} | |",
        "",
    ]
    if "in_process" in service:
        extra = service["compute_p50"] - service["empty_p50"]
        lines += [
            "Where the difference goes: the node's own work per call, measured in one process "
            "(deserialising the request, validating and answering it, serialising the answer), "
            f"is {service['in_process'] * 1e6:.2f} us, {service['in_process'] / extra * 100:.0f} % "
            f"of the {extra * 1e6:.1f} us between the two round trips (p50). The rest is the "
            f"transport of a {service['request_bytes']}-byte request and a "
            f"{service['response_bytes']}-byte answer where the empty service moves none "
            "(roscpp reads and writes a body only when there is one), and it does not shrink "
            "with faster physics.",
            "",
        ]
    lines += predict_section(out)
    burden = {kind: json.loads((out / f"burden_{kind}.json").read_text())
              for kind in ("stamps", "cluster") if (out / f"burden_{kind}.json").exists()}
    startup_path, node_startup_path = out / "startup.json", out / "startup_node.json"
    if burden or startup_path.exists():
        lines += [
            "## One hard message, and the service meanwhile",
            "",
            "Issue 13's item 9: the work of one message that once had no bound. The node's main "
            "thread (the monitor's) is measured from `/proc/<pid>/task/<pid>/stat` until it is "
            "idle again; meanwhile another thread of the driver calls `~compute_collision` "
            "without pause (the services have a thread of their own) and keeps the worst round "
            "trip.",
            "",
            "| message | the monitor's CPU per message | service calls answered meanwhile | "
            "the service's worst round trip meanwhile |",
            "|---|---|---|---|",
        ]
        names = {"stamps": "{bodies:,} states in one array, their stamps 10 us apart "
                           "({messages} messages)",
                 "cluster": "a lattice of {bodies:,} touching balls closing on its centre "
                            "(one joint solve)"}
        for kind, row in burden.items():
            cpu = row["cpu_per_message"]
            cpu_text = f"{cpu * 1e3:.1f} ms" if cpu < 1 else f"{cpu:.2f} s"
            lines.append(f"| {names[kind].format(**row)} | {cpu_text} | {row['service_calls']:,}"
                         f" ({row['service_failures']} failed) | {row['service_worst'] * 1e3:.1f} ms |")
        lines += [
            "",
            "Before issue 13 the array of distinct stamps cost one full step per stamp (23 s for "
            "10,000) and blocked the service for as long (22.9 s); it is one step now. The "
            "cluster's figure is the cost of the joint solve of `src/core/solver/simultaneous.cpp` as "
            "main had it when this ran (issue 12 rewrites it and bounds it): the service no "
            "longer waits for it either way.",
            "",
        ]
        if startup_path.exists():
            rows = json.loads(startup_path.read_text())["startup"]
            lines += [
                "Start-up, the scene loader and the monitor's construction (the node's start-up "
                "without the parameter server's transfer), for gases of n bodies; the last "
                "column is the time per n log2 n, flat for O(n log n) (it grew with n^2: "
                "4.8 s at 10,000 and 42.8 s at 30,000 bodies before):",
                "",
                "| bodies | start-up | per n log2 n |",
                "|---|---|---|",
            ]
            import math
            for n, seconds in rows:
                lines.append(f"| {n:,} | {seconds * 1e3:.1f} ms | {seconds / (n * math.log2(n)) * 1e9:.1f} ns |")
            lines.append("")
        if node_startup_path.exists():
            node_startup = json.loads(node_startup_path.read_text())
            lines += [
                f"The node itself with the {node_startup['bodies']:,}-body gas, from its launch "
                f"to its service being listed (the scene fetched from the parameter server, "
                f"validated, the monitor built): {node_startup['seconds']:.2f} s.",
                "",
            ]
    if memory is None and target.exists():
        # No memory run this time: the last one's section is kept as it was.
        previous = target.read_text()
        if "## Memory" in previous:
            lines += previous[previous.index("## Memory"):].rstrip("\n").split("\n") + [""]
    if memory:
        samples = memory["memory"]
        lines += [
            "## Memory",
            "",
            f"The node's resident memory while it takes {memory['bodies']:,} bodies at "
            f"{memory['rate']:g} Hz for {memory['seconds']:g} s:",
            "",
            "| time (s) | resident (MB) |",
            "|---|---|",
        ] + [f"| {t:.0f} | {mb:.1f} |" for t, mb in samples] + [
            "",
            f"From the first sample to the last: {samples[-1][1] - samples[0][1]:+.1f} MB; over "
            f"the second half of the run: {samples[-1][1] - samples[len(samples) // 2][1]:+.1f} MB "
            f"(largest sample {max(mb for _, mb in samples):.1f} MB). What the node holds is "
            "bounded: `~queue_size` inputs and `~max_states` states waiting (behind the "
            "update in progress or for transforms; roscpp's subscriber queue, as long, is "
            "emptied at once by the intake's own thread), `~max_states` states per array, and "
            "a body without states for `~body_timeout` is "
            "forgotten. Memory freed after a backlog stays with the process (glibc's heap), "
            "so the resident size steps up while the node falls behind and stays flat after.",
            "",
        ]
    # The profile of a pile dropped into a box and the impact of many bodies are measured by hand
    # (bench/pile_run.cpp, bench/lattice_impact.cpp, the commands in their sections): kept as
    # they are.
    kept = ""
    for title in (DROPPED_PILE_TITLE, IMPACT_TITLE):
        if target.exists() and title in target.read_text():
            rest = target.read_text().split(title, 1)[1]
            section = title + (rest[:rest.index("\n## ")] if "\n## " in rest else rest)
            kept += "\n" + section.rstrip("\n") + "\n"
    target.write_text("\n".join(lines) + "\n" + kept)


if __name__ == "__main__":
    main()
