#!/usr/bin/env python3
"""The real cube tosses' report: doc/cube_tosses.md and doc/cube_tosses.png from what
bench/cube_tosses/main.cpp (cube_tosses_peers) wrote. Run by scripts/cube_tosses.sh:

    cube_tosses_report.py RESULTS.json TOSSES_DIR DOC_DIR [VERSIONS] [--ours OURS.json]

RESULTS.json: the benchmark's output; OURS.json: our model's (bench/cube_tosses/ours.cpp,
cube_tosses_ours), measured over the span its prediction covers and set beside each peer over
the same span, and at rest where its prediction reaches the recording's end, beside each peer
on the same tosses; TOSSES_DIR: the tosses (read again for the free flight's
floor, below); DOC_DIR: where the page and the plot go; VERSIONS: the peers' Debian packages, one
line of text. Besides the peers' figures it measures, from the recording alone, the part of the
error no contact model explains: each evaluation toss's free flight (its first samples, before
its lowest corner comes within 5 mm of the table) against the parabola from its first recorded
state under g = 9.81 m/s^2, which every engine follows until the first contact.
"""
import csv
import json
import math
import os
import sys
import textwrap

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

CLEARANCE = 0.005  # m: a flight's samples are this far above the table (test_cube_tosses.cpp)


def quantiles(values):
    """Median and 90th percentile (numpy's linear interpolation)."""
    a = np.asarray(values, dtype=float)
    return float(np.median(a)), float(np.percentile(a, 90))


def pair(values, digits):
    median, p90 = quantiles(values)
    return f"{median:.{digits}f} / {p90:.{digits}f}"


def read_toss(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return np.array([[float(x) for x in row] for row in rows[1:] if row])


def lowest_corner(row, half_width):
    """z of the cube's lowest corner: each body axis turned down by its half width."""
    w, x, y, z = row[4:8] / np.linalg.norm(row[4:8])
    # The third row of the rotation matrix (world z of each body axis).
    third = np.array([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)])
    return row[3] - half_width * np.abs(third).sum()


def quaternion_product(a, b):
    """Hamilton product of quaternions given as (w, x, y, z)."""
    w1, v1 = a[0], np.asarray(a[1:])
    w2, v2 = b[0], np.asarray(b[1:])
    return np.concatenate(([w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)))


def angle_deg(a, b):
    """The angle of the rotation from orientation a to orientation b, deg."""
    turn = quaternion_product(np.concatenate(([a[0]], -np.asarray(a[1:]))), b)
    return float(np.degrees(2 * math.atan2(np.linalg.norm(turn[1:]), abs(turn[0]))))


def free_motion(row, t, g):
    """The exact free motion of a cube (isotropic inertia: a constant angular velocity) from the
    recorded state `row` after t s: the centre's parabola and q0 (cos(|w| t / 2), sin(|w| t / 2)
    w / |w|), w in the body's frame (the data set's README)."""
    centre = row[1:4] + row[8:11] * t + 0.5 * g * t * t
    q0 = row[4:8] / np.linalg.norm(row[4:8])
    w = row[11:14]
    rate = np.linalg.norm(w)
    half = 0.5 * rate * t
    turn = np.concatenate(([math.cos(half)], math.sin(half) * w / rate)) if rate > 0 else \
        np.array([1.0, 0.0, 0.0, 0.0])
    return centre, quaternion_product(q0, turn)


def flight_samples(rows, half_width, table_top):
    """How many samples the toss flies free: before its lowest corner comes within CLEARANCE."""
    for k, row in enumerate(rows):
        if lowest_corner(row, half_width) < table_top + CLEARANCE:
            return k
    return len(rows)


def flight_floor(results, folder):
    """Each evaluation toss's free flight against the exact free motion from its first recorded
    state, at the flight's last sample: the centre's distance (widths), the orientation's angle
    (deg), and that sample's time (s). Also each engine's median toss in flight against the same
    exact motion: the largest difference of its errors from the exact motion's (widths, deg), a
    check of the engines' start (frames, conventions)."""
    width = results["width_m"]
    g = np.array([0.0, 0.0, -results["gravity"]])
    distance, angle, durations = [], [], []
    for name in results["evaluation"]:
        rows = read_toss(os.path.join(folder, name))
        last = max(flight_samples(rows, 0.5 * width, results["table_top_m"]) - 1, 0)
        t = rows[last, 0] - rows[0, 0]
        centre, orientation = free_motion(rows[0], t, g)
        distance.append(np.linalg.norm(centre - rows[last, 1:4]) / width)
        angle.append(angle_deg(orientation, rows[last, 4:8] / np.linalg.norm(rows[last, 4:8])))
        durations.append(t)
    check = []
    for p in results["peers"]:
        toss = p["median_toss"]
        rows = read_toss(os.path.join(folder, toss["name"]))
        n = flight_samples(rows, 0.5 * width, results["table_top_m"])
        worst_distance = worst_angle = 0.0
        for k in range(n):
            centre, orientation = free_motion(rows[0], rows[k, 0] - rows[0, 0], g)
            exact_distance = np.linalg.norm(centre - rows[k, 1:4]) / width
            exact_angle = angle_deg(orientation, rows[k, 4:8] / np.linalg.norm(rows[k, 4:8]))
            worst_distance = max(worst_distance, abs(toss["distance"][k] - exact_distance))
            worst_angle = max(worst_angle, abs(toss["angle"][k] - exact_angle))
        check.append((p["name"], n, worst_distance, worst_angle))
    return distance, angle, durations, check


def run_label(run):
    """How one of our runs is named on the page: the fit over our span, or a peer's pair."""
    pair_text = f"e {run['restitution']:.2f}, mu {run['friction']:.3f}"
    if run["label"] == "fitted":
        return f"fitted over its span, {pair_text}"
    if run["label"] == "given":
        return f"given {pair_text}"
    return f"at {run['label']}'s {pair_text}"


def predicted(run):
    """The tosses of a run our prediction answered (not refused)."""
    return [t for t in run["tosses"] if t["refused"] is None]


def plotted_runs(ours):
    """Our runs drawn: one per e (runs at the same e end at the same impacts: at e = 0, the
    first)."""
    seen, runs = set(), []
    for run in ours["runs"]:
        if run["restitution"] not in seen:
            seen.add(run["restitution"])
            runs.append(run)
    return runs


def median_run_toss(run):
    """The run's median toss by its mean centre error over its span."""
    tosses = sorted(predicted(run), key=lambda t: float(np.mean(t["distance"])))
    return tosses[len(tosses) // 2]


def over_span(series, covered):
    """A toss's errors (per sample) over the first `covered` samples: their mean and the last."""
    part = series[:covered]
    return float(np.mean(part)), part[-1]


def reached(run):
    """The tosses of a run whose prediction reaches the recording's end (the horizon)."""
    return [t for t in predicted(run) if t["reached"]]


def at_rest(run):
    """The tosses of a run whose prediction reaches the recording's end at rest (resting)."""
    return [t for t in predicted(run) if t["rested"]]


def reasons(run):
    """How a run's predictions end, (reason, count), the recording's end first, then by count."""
    counts = {reason: len(names) for reason, names in run["ends"].items()}
    return sorted(counts.items(), key=lambda rc: (not rc[0].startswith("reaches"), -rc[1], rc[0]))


def at_rest_row(tosses, distance, angle):
    """The figures over whole tosses: the centre's mean over the toss and at rest (widths), the
    angle's (deg), the tosses over 1 width at rest; `distance`, `angle`: each toss's series."""
    d = [distance(t) for t in tosses]
    a = [angle(t) for t in tosses]
    over = sum(1 for series in d if series[-1] > 1)
    return (f"{pair([float(np.mean(x)) for x in d], 3)} | {pair([x[-1] for x in d], 3)} | "
            f"{pair([float(np.mean(x)) for x in a], 1)} | {pair([x[-1] for x in a], 1)} | "
            f"{over} of {len(tosses)}")


def degenerate(ours, coarse):
    """Whether the fit over the span picks the shortest span: its pair's median span no longer
    than every coarse e's best pair's (the objective least where the span is shortest)."""
    fitted = ours["runs"][0]
    point = [g for g in ours["grid"]
             if g[0] == fitted["restitution"] and g[1] == fitted["friction"]][0]
    best = {}
    for g in coarse:
        if g[0] not in best or g[2] < best[g[0]][2]:
            best[g[0]] = g
    return point[3] <= min(g[3] for g in best.values()) + 1e-9, best


def ours_section(add, ours, results):
    """Our model's section: how far its prediction goes (to the recording's end, or the lasting
    contact not modelled yet that ends it), its error at rest where it reaches the end beside
    each peer's on the same tosses, its errors over the span it covers beside each peer's over
    the same samples, the fit over the span and whether it is degenerate, the checks, the
    refusals."""
    rate = results["sample_rate_hz"]
    peers = results["peers"]
    index = {name: i for i, name in enumerate(results["evaluation"])}
    fitted = ours["runs"][0]
    total = len(ours["evaluation"])
    add("## Ours, as far as our model goes today")
    add("")
    add("Our core alone (`cube_tosses_ours`, `bench/cube_tosses/ours.cpp`): `predictImpacts` "
        "(include/collision_response/core/prediction.h) given the cube as a body of shape box, "
        f"side {results['width_m']} m, {results['mass_kg']} kg, the uniform solid's inertia (the "
        f"shape's default), the table as the plane z = {results['table_top_m']} m, the effects "
        f"gravity (g = {results['gravity']} m/s^2) and friction, e and mu the pair's; each "
        "evaluation toss's first recorded state (the angular velocity turned into the world's "
        "frame), the horizon the toss's recorded duration, `sample_period` 1/148 s. Its "
        "prediction flies the cube exactly, finds each contact with the table certified, resolves "
        "each impact with rotation (one corner: Chatterjee and Ruina's law with e and mu; several "
        "corners at once: the same law over all of them), and where the contact lasts on the "
        "table's face goes on by that contact's closed forms (resting, sliding, rolling; "
        "doc/model.md, \"Prediction of a shaped body\"), or where the cube touches at one corner "
        "or along one edge, rocks or spins on a face, by its tipping motion, each corner sticking "
        "or sliding (Coulomb), integrated to 1e-9 (doc/model.md, \"Tipping over a corner or an "
        "edge\"). A lasting contact neither carries ends the prediction there, its message "
        "naming it. So ours is "
        "measured over the span its prediction covers, from the first sample to the last one "
        "before it ends, and each peer beside it over the same samples of the same toss, at the "
        "peer's own fitted e and mu (the table above); where the prediction reaches the "
        "recording's end resting on the table, its last sample is the error **at rest**, as "
        "the peers'.")
    add("")
    # How far the predictions go, per run.
    add("**How far the prediction goes**: per run, the evaluation tosses whose prediction "
        "reaches the recording's end (and the contact's state there: `resting`, `sliding`, "
        "`rolling`, or none, in flight), and the others by what ends them (the words of the "
        "prediction's message; `cube_tosses_ours --toss NAME --contact E MU` replays one).")
    add("")
    all_reasons = []
    for run in ours["runs"]:
        for reason, _ in reasons(run):
            if reason not in all_reasons:
                all_reasons.append(reason)
    all_reasons.sort(key=lambda r: (not r.startswith("reaches"),
                                    -len(fitted["ends"].get(r, [])), r))
    add("| how it ends | " + " | ".join(run_label(r) for r in ours["runs"]) + " |")
    add("|---|" + "---|" * len(ours["runs"]))
    for reason in all_reasons:
        add(f"| {reason} | " +
            " | ".join(str(len(r["ends"].get(reason, []))) for r in ours["runs"]) + " |")
    for label, chosen in (("to the recording's end", reached), ("at rest there", at_rest)):
        add(f"| **{label}, of {total}** | " +
            " | ".join(f"**{len(chosen(r))}** ({100 * len(chosen(r)) / total:.0f} %)"
                       for r in ours["runs"]) + " |")
    add("")
    # At rest, where the prediction reaches the end resting.
    if not any(at_rest(run) for run in ours["runs"]):
        add("**At rest**: not yet. In no run does any toss's prediction reach the recording's end "
            "at rest on the table (resting), so our error at rest cannot be given yet, nor the "
            "peers' beside it on the same tosses; a prediction that reaches the end still "
            "bouncing (in flight, at the high e of the grid below) is counted as reaching the "
            "end, not at rest. At the peers' fitted pairs the cube's first lasting contact "
            "touches the "
            "table at one corner or along one edge (a corner struck at low e keeps touching): "
            "the tipping that lastingOnFace does not carry yet. So the spans are still those of "
            "the first lasting contact, as before a box resting, sliding or rolling on a face "
            "was carried (their median fractions in the table \"Over the span\" below); a run "
            "whose predictions reach the end at rest would be reported here, beside the peers "
            "on the same tosses.")
        add("")
    else:
        add("**At rest**, over the tosses whose prediction reaches the recording's end at rest on "
            "the table (each run its own: the count in the third column), ours and each peer on "
            "the same tosses, the peer at its own fitted e and mu; median / 90th percentile. "
            "These tosses are whole, so the mean over the toss is the peers' measure too; they "
            "are the ones our model carries to rest, not a random share of the tosses (the "
            "others end at a contact it does not model yet, above), and the peers' figures on "
            "them differ from theirs over all tosses (the table at the top).")
        add("")
    if any(at_rest(run) for run in ours["runs"]):
        add("| run | engine | tosses | centre, mean over the toss (widths) | centre at rest "
            "(widths) | angle, mean over the toss (deg) | angle at rest (deg) | tosses over 1 "
            "width at rest |")
        add("|---|---|---|---|---|---|---|---|")
    for run in ours["runs"]:
        tosses = at_rest(run)
        if not tosses:
            continue
        add(f"| {run_label(run)} | **ours** | {len(tosses)} | " +
            at_rest_row(tosses, lambda t: t["distance"], lambda t: t["angle"]) + " |")
        for p in peers:
            add(f"| | {p['name']} | | " + at_rest_row(
                tosses, lambda t: p["distance_series"][index[t["name"]]],
                lambda t: p["angle_series"][index[t["name"]]]) + " |")
    if any(at_rest(run) for run in ours["runs"]):
        add("")
    # The fit over the span, and whether it is degenerate.
    coarse = ours["grid"][:len(results["coarse_restitutions"]) * len(results["coarse_frictions"])]
    is_degenerate, best = degenerate(ours, coarse)
    e0 = [g[2] for g in coarse if g[0] == min(best)]
    fit = fitted["fit"]
    by_e = "; ".join(f"e {e:g}: {g[2]:.4f} widths at mu {g[1]:g}, over {g[3]:.2f} of the samples, "
                     f"{100 * g[5]:.0f} % to the end, {100 * g[6]:.0f} % at rest there"
                     for e, g in sorted(best.items()))
    text = (f"- **The fit over the span.** e and mu fitted on the same {len(ours['fitting'])} "
            "fitting tosses by the same grid and the peers' objective (the mean over the tosses "
            "of each toss's mean centre error), each toss's mean taken over its span: e = "
            f"{fitted['restitution']:.2f}, mu = {fitted['friction']:.3f}, "
            f"{fit['mean_distance']:.4f} widths ({fit['grid_points']} points, "
            f"{fit['cpu_s']:.1f} s CPU; at most {ours['fit_refused']} fitting tosses refused at a "
            "point). At each e of the coarse grid, its best mu's objective, the span it covers "
            "(median fraction of the samples) and the shares of the fitting tosses it carries to "
            f"the end and to rest there: {by_e}. ")
    if is_degenerate:
        text += ("This fit is still degenerate: the span depends on e and mu, and the objective "
                 "is least where the span is shortest, which the fit picks. At e = "
                 f"{min(best):g} every mu gives {min(e0):.4f} to {max(e0):.4f} widths. The fair "
                 "comparison of the contact models is therefore ours at each peer's own fitted "
                 "pair, beside that peer over the same span or at rest on the same tosses (the "
                 "rows \"at Bullet's ...\" above and below).")
    else:
        text += ("The fit no longer picks the shortest span (the pair's median span is longer "
                 "than some e's best), but the span still depends on e and mu, so the objective "
                 "is not the peers' over the same samples: ours at each peer's own fitted pair, "
                 "beside that peer, remains the fair comparison.")
    text += (" Over a flight alone ours is the exact motion under g = 9.81 m/s^2; the peers' "
             "steps are off it by up to about 2e-3 widths (\"Check of the engines' start\" "
             "above), here towards the recording, whose flights fit g = 9.61 m/s^2.")
    add(text)
    add("")
    add("**Over the span**: median / 90th percentile over the evaluation tosses our prediction "
        "answered; every row of one run over that run's spans (toss by toss, the same samples). "
        "Span: the median fraction of the toss's recorded duration and of its samples. Ended: "
        "the spans ended before the recording's end (cut short at a lasting contact not modelled "
        "yet) / at the recording's end / refused. CPU: ours per toss (its span) and per second "
        "predicted; the peers' per second played over the whole toss (from the table above).")
    add("")
    add("| run | engine | span: duration / samples | ended: early / at the end / refused | "
        "centre, mean over the span (widths) | centre at the span's end (widths) | angle, mean "
        "over the span (deg) | angle at the span's end (deg) | CPU per toss (ms) / per s "
        "predicted (ms) |")
    add("|---|---|---|---|---|---|---|---|---|")
    breaches, refusals = [], []
    deepest, gained = float("inf"), -float("inf")
    for run in ours["runs"]:
        tosses = predicted(run)
        lasting = sum(1 for t in tosses if not t["reached"])
        refused = [t for t in run["tosses"] if t["refused"] is not None]
        refusals += [(run_label(run), t["name"], t["refused"]) for t in refused]
        breaches += [(run_label(run), name) for name in run["breaches"]]
        for t in tosses:
            deepest = min(deepest, t["deepest_m"])
            gained = max(gained, t["energy_gained_j"] / t["first_energy_j"])
        duration = [(t["end_s"] * rate) / (t["samples"] - 1) for t in tosses]
        samples = [t["covered"] / t["samples"] for t in tosses]
        spans = [over_span(t["distance"], t["covered"]) for t in tosses]
        angles = [over_span(t["angle"], t["covered"]) for t in tosses]
        cpu = [t["cpu_s"] for t in tosses]
        predicted_s = sum(t["end_s"] for t in tosses)
        add(f"| {run_label(run)} | **ours** | {np.median(duration):.2f} / "
            f"{np.median(samples):.2f} | {lasting} / {len(tosses) - lasting} / {len(refused)} | "
            f"{pair([m for m, _ in spans], 3)} | {pair([e for _, e in spans], 3)} | "
            f"{pair([m for m, _ in angles], 1)} | {pair([e for _, e in angles], 1)} | "
            f"{1000 * np.mean(cpu):.2f} / {1000 * sum(cpu) / predicted_s:.2f} |")
        for p in peers:
            d = [over_span(p["distance_series"][index[t["name"]]], t["covered"]) for t in tosses]
            a = [over_span(p["angle_series"][index[t["name"]]], t["covered"]) for t in tosses]
            add(f"| | {p['name']} | | | {pair([m for m, _ in d], 3)} | "
                f"{pair([e for _, e in d], 3)} | {pair([m for m, _ in a], 1)} | "
                f"{pair([e for _, e in a], 1)} | (whole toss) "
                f"{1000 * p['cpu_per_simulated_s']:.2f} |")
    add("")
    add(f"- **Checks of every sample** of every run above: no corner of the cube below the table "
        f"by more than {ours['inside_tolerance_m']:g} m (the least height of the lowest corner "
        f"over them all: {deepest:.2e} m), no energy (kinetic, rotational and potential) gained "
        f"above {ours['energy_tolerance']:g} of the first state's (the most: "
        f"{gained:.1e} of it): " +
        ("none breached." if not breaches else
         f"{len(breaches)} breached: " + ", ".join(f"{n} ({r})" for r, n in breaches) + "."))
    if refusals:
        add(f"- **Refused** ({len(refusals)}): " +
            "; ".join(f"{n} ({r}): {why}" for r, n, why in refusals) + ".")
    else:
        add("- **Refused**: none; every evaluation toss of every run was predicted.")
    add("")


def wrapped(line):
    """A paragraph or a list item wrapped at 100 columns; tables, headings, pictures and
    comments as they are."""
    if line.startswith(("|", "#", "<!--", "![")) or len(line) <= 100:
        return line
    indent = "  " if line.startswith("- ") else ""
    return textwrap.fill(line, 100, subsequent_indent=indent, break_long_words=False,
                         break_on_hyphens=False)


def main():
    args = sys.argv[1:]
    ours = None
    if "--ours" in args:
        at = args.index("--ours")
        if at + 1 >= len(args):
            sys.exit(__doc__)
        with open(args[at + 1]) as f:
            ours = json.load(f)
        del args[at:at + 2]
    if len(args) not in (3, 4):
        sys.exit(__doc__)
    results_path, folder, doc = args[:3]
    versions = args[3] if len(args) == 4 else ""
    with open(results_path) as f:
        results = json.load(f)
    if ours is not None and ours["evaluation"] != results["evaluation"]:
        sys.exit("ours and the peers were not measured on the same evaluation tosses")
    peers = results["peers"]
    fitting, evaluation = results["fitting"], results["evaluation"]
    width = results["width_m"]
    floor, floor_angle, flight_times, check = flight_floor(results, folder)

    lines = []
    add = lines.append
    add("# The real cube tosses: ours, Bullet, ODE and MuJoCo beside the recording")
    add("")
    add("Regenerate: `bash scripts/cube_tosses.sh` (it builds `cube_tosses_peers` and "
        "`cube_tosses_ours`, `bench/cube_tosses/`, runs them on the tosses in "
        "`../shared/data/cube_tosses`, or the folder given as its argument, and writes this page "
        "and `doc/cube_tosses.png` with `scripts/cube_tosses_report.py`; about 3 minutes on one "
        "core). The tosses are read where they are, never copied into the repository; without "
        "them the script says so and stops.")
    if versions:
        add("")
        add(f"Peers: {versions}.")
    add("")
    add("## The tosses and the model")
    add("")
    add(f"{results['tosses']} real tosses of a {1000 * width:g} mm acrylic cube "
        f"({results['mass_kg']} kg) thrown by hand onto a table and tracked at "
        f"{results['sample_rate_hz']:.0f} Hz: the real-world data set of ContactNets (Pfrommer, "
        "Halm and Posa, CoRL 2020), on which Acosta, Yang and Posa (IEEE RA-L 2022) compared "
        "Drake, MuJoCo and Bullet with reality. Every engine is given the same cube: a box of side "
        f"{width} m, {results['mass_kg']} kg, the uniform solid's inertia m w^2 / 6 = "
        f"{results['inertia_kg_m2']:.4g} kg m^2 (the data set's own authors fitted 8.1e-4 for "
        "their simulator; not used here), over a plane, the table's top, at z = "
        f"{results['table_top_m']} m, under g = {results['gravity']} m/s^2. Each toss starts "
        "from its first recorded state: the centre, the orientation, the velocity and the angular "
        "velocity (recorded in the cube's frame: turned into the world's for Bullet and ODE, given "
        "as it is to MuJoCo, whose free joint takes it in the body's frame). Each engine steps at "
        f"1/({results['sample_rate_hz']:.0f} x 7) s = {1000 * results['step_s']:.3f} ms (1036 Hz, "
        "so that every sample's instant ends a step) over the recorded duration, and its pose is "
        "taken at every sample.")
    add("")
    add(f"- **Fitting tosses** ({len(fitting)}): every {results['fit_stride']}th toss by file name "
        f"(`{fitting[0]}`, `{fitting[1]}`, ..., `{fitting[-1]}`). e and mu are fitted on them by a "
        "grid, coarse (e in " + ", ".join(f"{v:g}" for v in results["coarse_restitutions"]) +
        "; mu in " + ", ".join(f"{v:g}" for v in results["coarse_frictions"]) +
        f") then fine ({results['fine_steps']} steps of {results['fine_restitution_step']:g} in e "
        f"and {results['fine_friction_step']:g} in mu either side of the coarse best): the pair of "
        "least mean, over the fitting tosses, of each toss's mean centre error.")
    add(f"- **Evaluation tosses** ({len(evaluation)}): all the others, played at the fitted e "
        "and mu. Measured against the recording: the centre's distance as a fraction of the "
        "cube's width, and the angle of the rotation from the played orientation to the recorded "
        "one (deg; a cube that comes to rest on another face than the recorded one is off by 90 "
        "deg or more, though it looks the same), each the mean over the toss and at rest (the "
        "last sample, the cube still).")
    add("")
    add("## The figures")
    add("")
    add("Median / 90th percentile over the evaluation tosses. CPU per toss: this process's CPU "
        "time for one evaluation toss (its mean over them), one core, at the fitted e and mu; "
        "one run on a shared 2-core machine, where two runs' CPU times differ by up to a third.")
    add("")
    add("| engine | e | mu | centre, mean over the toss (widths) | centre at rest (widths) | "
        "angle, mean over the toss (deg) | angle at rest (deg) | tosses over 1 width at rest "
        "(mean over the toss) | CPU per toss (ms) |")
    add("|---|---|---|---|---|---|---|---|---|")
    if ours is None:
        add("| **ours** | (not run) | | not run: `cube_tosses_ours` gave no results | | | | | |")
    else:
        fitted = ours["runs"][0]
        whole = at_rest(fitted)
        cpu = 1000 * float(np.mean([t["cpu_s"] for t in predicted(fitted)]))
        head = (f"| **ours** | {fitted['restitution']:.2f} (fitted over its span, "
                f"[below](#ours-as-far-as-our-model-goes-today)) | {fitted['friction']:.3f} | ")
        if whole:
            add(head + f"only the {len(whole)} of {len(fitted['tosses'])} tosses its prediction "
                "carries to rest (the peers on them below): " +
                at_rest_row(whole, lambda t: t["distance"], lambda t: t["angle"]).replace(
                    f" of {len(whole)}", f" of {len(whole)} (ours)") + f" | {cpu:.2f} |")
        else:
            add(head + "over the span its prediction covers only, "
                "[below](#ours-as-far-as-our-model-goes-today) | not yet: no toss's prediction "
                "reaches rest (below) | below | not yet | not yet | " f"{cpu:.2f} |")
    for p in peers:
        e = f"{p['fit']['restitution']:.2f}" if p["fits_restitution"] else "(none)"
        over_rest = sum(1 for v in p["rest_distance"] if v > 1)
        over_mean = sum(1 for v in p["mean_distance"] if v > 1)
        add(f"| {p['name']} | {e} | {p['fit']['friction']:.3f} | {pair(p['mean_distance'], 3)} | "
            f"{pair(p['rest_distance'], 3)} | {pair(p['mean_angle'], 1)} | "
            f"{pair(p['rest_angle'], 1)} | {over_rest} ({over_mean}) of {len(p['rest_distance'])} "
            f"| {1000 * p['cpu_per_toss_s']:.2f} |")
    add("")
    add("Fit: the least mean error over the fitting tosses (widths), the grid's points, and the "
        "fit's CPU time:")
    add("")
    for p in peers:
        add(f"- {p['name']}: {p['fit']['mean_distance']:.3f} widths, {p['fit']['grid_points']} "
            f"points, {p['fit']['cpu_s']:.1f} s.")
    add("")
    add("## What no parameter explains")
    add("")
    floor_median, floor_p90 = quantiles(floor)
    angle_median, angle_p90 = quantiles(floor_angle)
    add("- **The free flight.** Before any contact every engine should follow the exact free "
        "motion from the first recorded state: the centre's parabola, and a constant angular "
        "velocity (a cube's inertia is isotropic). Against the recording, at the flight's last "
        "sample (the lowest corner still 5 mm above the table; "
        f"{1000 * float(np.median(flight_times)):.0f} ms after the start, median), that motion "
        f"is off by {floor_median:.3f} widths (median; 90th percentile {floor_p90:.3f}) and "
        f"{angle_median:.2f} deg (median; 90th percentile {angle_p90:.2f}): the recorded "
        "velocities are not exactly the recorded poses' rates (the rows are processed odometry), "
        "and the flights fit g = 9.61 m/s^2 at the stated 148 Hz "
        "(test/core/test_cube_tosses.cpp). No contact parameter removes this part; it grows "
        "with the time to the first contact.")
    add("- **Check of the engines' start.** In flight, each engine's median toss differs from "
        "that exact free motion's errors by at most " +
        "; ".join(f"{name} {d:.1e} widths and {a:.1e} deg over {n} samples"
                  for name, n, d, a in check) +
        ": the first states reach every engine in its own conventions (frames, quaternion "
        "order) as the recording gives them (the centre's part is the steps' discretisation of "
        "the parabola, about g dt t / 2: 0.5 mm at 0.1 s).")
    add("- **Each toss's own best.** Each evaluation toss played at every point of the coarse "
        "grid, keeping its least error: what the best single pair could do for that toss alone. "
        "The gap between this and the fitted figures is the spread of the tosses' parameters; "
        "what remains is what no (e, mu) of the model explains.")
    add("")
    add("| engine | centre, mean over the toss, own best (widths) | centre at rest, own best "
        "(widths) | tosses over 1 width at rest even at their own best | CPU of this search (s) |")
    add("|---|---|---|---|---|")
    for p in peers:
        stuck = sum(1 for v in p["own_best_rest_distance"] if v > 1)
        add(f"| {p['name']} | {pair(p['own_best_mean_distance'], 3)} | "
            f"{pair(p['own_best_rest_distance'], 3)} | {stuck} of "
            f"{len(p['own_best_rest_distance'])} | {p['own_best_cpu_s']:.1f} |")
    add("")
    add("## The settings")
    add("")
    for p in peers:
        add(f"- **{p['name']}**: {p['setting']}.")
    add("- MuJoCo has no coefficient of restitution: its contacts are soft, set by solref and "
        "solimp. \"e through solref\" is its closest setting to e, the direct solref whose "
        "unilateral spring-dashpot has restitution e (`bench/accuracy/spring_dashpot.h`, as the "
        "accuracy benchmark sets it), e and mu fitted; \"default contact\" keeps MuJoCo's soft "
        "contact, mu alone fitted. Acosta, Yang and Posa likewise tuned MuJoCo's contact stiffness "
        "and damping (solref) on these tosses, for want of an e.")
    add("")
    if ours is not None:
        ours_section(add, ours, results)
    add("## The median toss, over time")
    add("")
    add("![The centre's distance and the orientation's angle over the toss](cube_tosses.png)")
    add("")
    add("Each engine's median evaluation toss (by its mean centre error): " +
        "; ".join(f"{p['name']}: `{p['median_toss']['name']}`" for p in peers) +
        ("" if ours is None else
         "; ours (dashed, over its span: to the end where it reaches it; one run per e): each "
         "run's median toss by its mean "
         "centre error over its span, " +
         "; ".join(f"{run_label(r)}: `{median_run_toss(r)['name']}`"
                   for r in plotted_runs(ours))) + ".")
    add("")
    with open(os.path.join(doc, "cube_tosses.md"), "w") as f:
        f.write("\n".join(wrapped(line) for line in lines))

    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 5))
    for p in peers:
        toss = p["median_toss"]
        t = np.arange(len(toss["distance"])) / results["sample_rate_hz"]
        label = f"{p['name']} ({toss['name'].replace('.csv', '')})"
        left.plot(t, toss["distance"], label=label)
        right.plot(t, toss["angle"], label=label)
    if ours is not None:
        for r in plotted_runs(ours):
            toss = median_run_toss(r)
            t = np.arange(len(toss["distance"])) / results["sample_rate_hz"]
            label = f"ours, {run_label(r)} ({toss['name'].replace('.csv', '')}, its span)"
            left.plot(t, toss["distance"], "--", linewidth=2, label=label)
            right.plot(t, toss["angle"], "--", linewidth=2, label=label)
    left.set_xlabel("t (s)")
    left.set_ylabel("centre's distance (cube widths)")
    right.set_xlabel("t (s)")
    right.set_ylabel("orientation's angle (deg)")
    left.set_title("centre")
    right.set_title("orientation")
    handles, labels = left.get_legend_handles_labels()
    figure.legend(handles, labels, loc="lower center", ncol=2, fontsize=8)
    for axis in (left, right):
        axis.grid(True, alpha=0.3)
    figure.suptitle("Each engine's median cube toss against the recording")
    figure.tight_layout(rect=(0, 0.04 * ((len(labels) + 1) // 2) + 0.02, 1, 1))
    figure.savefig(os.path.join(doc, "cube_tosses.png"), dpi=80)


if __name__ == "__main__":
    main()
