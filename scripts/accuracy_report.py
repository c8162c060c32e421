#!/usr/bin/env python3
"""Turns the accuracy benchmark's output (scripts/accuracy.sh) into doc/accuracy.md, the plot
doc/accuracy.png and the accuracy section of `doc/measurements.md` (between its accuracy markers).

usage: accuracy_report.py OUT_DIR DOC_DIR PAGE (doc/measurements.md: the section between its accuracy markers)

OUT_DIR holds errors.json (the benchmark's measured errors) and timing.json (Google Benchmark's
CPU times). What is measured and how each reference is made: bench/accuracy/ (measure.cpp and
reference/make_references.py). The scenes' tables, the plot's panels and the key ratios all
follow SCENES below: a new scene needs one entry there.
"""
import json
import math
import pathlib
import platform
import subprocess
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

# --- the engines, as the report names them -------------------------------------------------------

ENGINES = [("ours", "continuous"), ("ours", "discrete"), ("ours", "stepped"), ("bullet", "default"),
           ("bullet", "bouncing"), ("ode", "default"), ("mujoco", "default"),
           ("mujoco", "restitution"), ("dart", "default"), ("box2d", "default")]
LABEL = {("ours", "continuous"): "ours, continuous", ("ours", "discrete"): "ours, discrete",
         ("ours", "stepped"): "ours, stepped (every body)",
         ("bullet", "default"): "Bullet, defaults",
         ("bullet", "bouncing"): "Bullet, bouncing settings", ("ode", "default"): "ODE",
         ("mujoco", "default"): "MuJoCo, default contact",
         ("mujoco", "restitution"): "MuJoCo, restitution (solref)", ("dart", "default"): "DART",
         ("box2d", "default"): "Box2D"}
PEERS = [("bullet", "Bullet"), ("ode", "ODE"), ("mujoco", "MuJoCo"), ("dart", "DART"),
         ("box2d", "Box2D")]
COLOUR = {("ours", "continuous"): "#1b9e77", ("ours", "discrete"): "#66c2a5",
          ("ours", "stepped"): "#0b4f3c",
          ("bullet", "default"): "#d95f02", ("bullet", "bouncing"): "#fc8d62",
          ("ode", "default"): "#7570b3", ("mujoco", "default"): "#e7298a",
          ("mujoco", "restitution"): "#a6117a", ("dart", "default"): "#a6761d",
          ("box2d", "default"): "#1f78b4"}
MARKER = {10: "o", 30: "s", 60: "^", 100: "D", 300: "v", 1000: "P"}
FLOOR = 1e-18  # errors of exactly 0 are drawn on this line

# --- the scenes: tables, plot panels and key ratios ----------------------------------------------
# columns: (metric, header, format); headline: the metric of the plot and the key ratios (an
# error: smaller is better; n/a counts as the worst); group: long runs sharing one table.

def fmt(value, digits=2):
    if value is None:
        return "n/a"
    if value == 0:
        return "0"
    if abs(value) >= 1e4 or abs(value) < 1e-3:
        return f"{value:.{digits - 1}e}"
    return f"{value:.{digits}g}"


def count(value):
    return "n/a" if value is None else str(int(value))


def yes_no(value):
    return "n/a" if value is None else ("yes" if value else "no")


SCENES = [
    {"scene": "drop_test", "duration": 2.5,
     "short": "drop test (9 balls, 2.5 s)",
     "title": "Drop test: nine balls of the seed's table dropped 1 m onto concrete",
     "reference": "closed form, checked by the event-driven reference: bounce k rises to "
                  "h e^(2k), the first impact at sqrt(2h/g)",
     "note": "e = sqrt(h'/h) with h' the first flight's apex as the engine's output implies it: "
             "ours from each reported impact (the post-impact velocity at the contact, "
             "h + u^2/2g), the others (and ours, stepped: a stepped cluster reports no impacts) "
             "from their state at the top of each flight (the last update rising: h + u^2/2g, "
             "exact for any state of a ballistic flight). No flight "
             "(no bounce): an error of 1. The instant: ours reports it; the others' is the first "
             "update whose velocity is not the free fall's. Worst of the nine balls.",
     "columns": [("restitution", "e from the first apex (rel.)", fmt),
                 ("apex", "apex after 3 bounces (rel.)", fmt),
                 ("instant", "instant of the first impact (s)", fmt)],
     "headline": ("restitution", "error of e from the first bounce (relative)")},
    {"scene": "cradle", "duration": 0.1,
     "short": "Newton's cradle (5 balls, e = 1)",
     "title": "Newton's cradle: five touching balls, e = 1",
     "reference": "event-driven, doc/model.md's simultaneous-contact model: the first four at "
                  "rest, the last at 1 m/s",
     "note": "Worst ball's velocity after 0.1 s against the reference; energy and momentum "
             "against the start.",
     "columns": [("velocity", "worst velocity after (m/s)", fmt),
                 ("energy_drift", "energy drift (rel.)", fmt),
                 ("momentum_drift", "momentum drift (rel.)", fmt),
                 ("instant", "instant of the first impact (s)", fmt)],
     "headline": ("velocity", "worst velocity error after the impacts (m/s)")},
    {"scene": "billiards_break", "duration": 1.0,
     "short": "billiards break (16 balls, 1 s)",
     "title": "Billiards break: the cue ball at 6 m/s into a rack of fifteen",
     "reference": "event-driven, 50 digits, doc/model.md's simultaneous-contact model for the "
                  "touching rack (44 impacts)",
     "note": "RMS over the sixteen balls after 1 s against the event-driven reference. The rack "
             "touches: engines whose model of simultaneous contacts differs from doc/model.md's "
             "(rounds of joint Newton restitution) differ from it by that model as well.",
     "columns": [("velocity", "velocity RMS after 1 s (m/s)", fmt),
                 ("position", "position RMS after 1 s (m)", fmt),
                 ("instant", "instant of the cue's first impact (s)", fmt),
                 ("impacts", "impacts (exact: 44)", count)],
     "headline": ("velocity", "velocity RMS error after 1 s (m/s)")},
    {"scene": "tunnelling", "duration": 0.1,
     "short": "fast ball against a thin post",
     "title": "Tunnelling: a 0.02 m ball at 50 m/s against a 0.01 m post",
     "reference": "closed form: the impact at 0.0194 s, -40 m/s after",
     "note": "The velocity after 0.1 s against the exact -40 m/s (a ball that passes through "
             "keeps 50 m/s: an error of 90 m/s).",
     "columns": [("missed", "missed", yes_no), ("velocity", "velocity error after (m/s)", fmt),
                 ("instant", "instant (s)", fmt)],
     "headline": ("velocity", "velocity error after (m/s; 90: passed through)")},
    {"scene": "sphere_gas", "duration": 2.0,
     "short": "sphere gas (64 balls, 2 s)",
     "title": "Sphere gas: 64 elastic balls in a closed box for 2 s",
     "reference": "conservation: the energy at the start (no trajectory: the gas is chaotic)",
     "columns": [("energy_drift", "energy drift (rel.)", fmt), ("impacts", "impacts", count)],
     "headline": ("energy_drift", "energy drift over 2 s (relative)")},
    {"scene": "ball_corner", "duration": 2.0,
     "short": "ball into a corner (lasting contact)",
     "title": "Lasting contact: a ball slides down a 10-degree incline into a wall and rests in "
              "the corner",
     "reference": "closed form: the corner position, touching both planes",
     "note": "A ball (r = 0.05 m, 0.1 kg) released at rest on a frictionless 10-degree incline "
             "slides 0.2 m (0.485 s at g sin 10 deg) into a wall, e = 0.3 everywhere, and comes "
             "to rest in the corner; 2 s. With friction and spin (mu = 1) it rolls (a = 5/7 g "
             "sin 10 deg, 0.573 s to the wall). Penetration: the deepest into either plane at "
             "any state; rest error: the final centre against the corner's; energy gain: the "
             "largest rise of kinetic (of the centre) plus potential energy above the start at "
             "any state, as a fraction of what the fall releases (0: never gained).",
     "columns": [("penetration", "deepest penetration (m)", fmt),
                 ("rest_error", "rest position error (m)", fmt),
                 ("final_speed", "final speed (m/s)", fmt),
                 ("energy_gain", "energy gain (of released)", fmt)],
     "headline": ("rest_error", "final position error against the corner (m)")},
    {"scene": "ball_off_sphere", "duration": 1.5,
     "short": "ball off a fixed sphere (lasting contact)",
     "title": "Lasting contact: a ball nudged on top of a fixed sphere leaves it and falls to the "
              "floor",
     "reference": "closed form: frictionless cos theta = 2/3 + v0^2/(3 g (R + r))",
     "note": "A ball (r = 0.05 m) on top of a fixed sphere (R = 0.2 m, resting on the floor), "
             "nudged at v0 = 0.01 m/s, frictionless: it leaves where the normal force vanishes, "
             "cos theta = (2 + v0^2 / g (R + r)) / 3 (theta = 48.19 deg), then falls to the floor "
             "(e = 0.3); 1.5 s. The leaving angle is read from the first state in flight (10 um "
             "clear of the sphere), its parabola traced back to the contact distance: exact for "
             "any state of a ballistic flight, as the apexes of the drop test. With friction and "
             "spin (mu = 1, a solid ball): the reference solves the slip at the start, the "
             "rolling and the slip before leaving in closed form (the rolling limit, mu -> "
             "infinity, is cos theta = 10/17); see the integrator table below.",
     "columns": [("leave_angle", "leaving angle error (rad)", fmt),
                 ("penetration_sphere", "penetration into the sphere (m)", fmt),
                 ("penetration_floor", "penetration into the floor (m)", fmt),
                 ("energy_gain", "energy gain (J)", fmt)],
     "headline": ("leave_angle", "leaving angle error (rad)")},
    {"scene": "ball_stack", "duration": 2.0,
     "short": "stack of three balls (lasting contact)",
     "title": "Lasting contact: three balls stacked on a floor, at rest for 2 s",
     "reference": "closed form: at rest, centres at r, 3r, 5r",
     "note": "Three balls (r = 0.05 m, 0.1 kg) on one vertical line on a floor, touching: an "
             "equilibrium. Drift: the largest distance of any centre from r, 3r, 5r at any "
             "state; penetration: the deepest overlap of two balls or a ball and the floor.",
     "columns": [("drift", "drift of the centres (m)", fmt),
                 ("penetration", "deepest penetration (m)", fmt),
                 ("energy_gain", "energy gain (J)", fmt)],
     "headline": ("drift", "drift of the centres from r, 3r, 5r (m)")},
    {"scene": "ball_off_edge", "duration": 0.8,
     "short": "ball off a table's edge (a box; lasting contact)",
     "title": "Lasting contact on a finite shape: a ball slides along a table (a box) and off its "
              "edge",
     "reference": "closed form: frictionless cos theta = 2/3 + v0^2/(3 g r); in flight "
                  "v_x = sqrt(g r) cos^(3/2) theta",
     "note": "A ball (r = 0.05 m) sliding frictionless at v0 = 0.2 m/s along the top face of a "
             "box (1 x 1 x 0.5 m) from 5 cm before its edge: it pivots about the edge and leaves "
             "it where the normal force vanishes, cos theta = (2 + v0^2 / g r) / 3 (the ball off "
             "a sphere of radius 0), then flies with the horizontal velocity sqrt(g r) "
             "cos^(3/2) theta (0.405 m/s); 0.8 s. Error: the horizontal velocity at the last "
             "state; penetration: the deepest into the box at any state. Box2D's box has a skin "
             "of b2_polygonRadius (1 cm), so its edge is a rounded corner.",
     "columns": [("flight_vx", "horizontal velocity error in flight (m/s)", fmt),
                 ("penetration_box", "penetration into the box (m)", fmt),
                 ("energy_gain", "energy gain (J)", fmt)],
     "headline": ("flight_vx", "horizontal velocity error after the edge (m/s)")},
    {"scene": "ball_off_moving_paddle", "duration": 0.5,
     "short": "ball off a moving paddle (a box on a moving frame)",
     "title": "A ball off a moving paddle: a thin box moving at -0.5 m/s strikes a ball at 1 m/s",
     "reference": "closed form: v' = v_p + e (v_p - v)",
     "note": "A ball (r = 0.033 m, 0.057 kg) flying at 1 m/s along x into a paddle (a box 0.02 x "
             "0.3 x 0.3 m) that moves at -0.5 m/s towards it, e = 0.3, no gravity: it leaves at "
             "v_p + e (v_p - v) = -0.95 m/s; 0.5 s. Ours moves the paddle on a frame (as tf "
             "does); Bullet and ODE as a kinematic body; MuJoCo, DART and Box2D: no moving "
             "obstacles in this harness. Error: the ball's velocity at the last state; "
             "penetration: the deepest into the moving paddle at any state.",
     "columns": [("velocity_after", "velocity error after (m/s)", fmt),
                 ("penetration_paddle", "penetration into the paddle (m)", fmt)],
     "headline": ("velocity_after", "velocity error after the paddle (m/s)")},
    {"scene": "ball_on_mesh_floor", "duration": 1.0,
     "short": "ball across a tessellated floor (a mesh)",
     "title": "A ball sliding across a tessellated floor (a triangle mesh), over its internal edges",
     "reference": "closed form: as on the plane, z = r and the velocity unchanged",
     "note": "A ball (r = 0.05 m) sliding frictionless at (1.5, 0.9, 0) m/s across a flat floor "
             "mesh of 8 x 8 squares of two triangles (2 m across) for 1 s, crossing about 20 "
             "internal edges. Height: the largest distance of the centre from z = r at any state "
             "(a ghost collision off an internal edge lifts it); velocity error: at the end. "
             "Bullet: btBvhTriangleMeshShape; ODE: dGeomTriMesh; MuJoCo and DART: no meshes in "
             "this harness; Box2D: not planar.",
     "columns": [("height_off", "height off z = r (m)", fmt),
                 ("velocity_error", "velocity error at the end (m/s)", fmt),
                 ("penetration_floor", "penetration into the floor (m)", fmt)],
     "headline": ("velocity_error", "velocity error after 1 s (m/s)")},
    {"scene": "ball_pile_27", "group": "pile", "variant": "27 balls", "duration": 2.0,
     "short": "27 balls settling in a box",
     "title": "A pile of 27 balls settling in a box", "reference": "at rest: kinetic energy 0, "
     "no overlap", "headline": ("penetration", "deepest penetration (m)")},
    {"scene": "ball_pile_100", "group": "pile", "variant": "100 balls", "duration": 2.0,
     "short": "100 balls settling in a box",
     "title": "A pile of 100 balls settling in a box", "reference": "at rest: kinetic energy 0, "
     "no overlap", "headline": ("penetration", "deepest penetration (m)")},
    {"scene": "ball_pile_100_4s", "group": "pile", "variant": "100 balls, 4 s", "duration": 4.0,
     "short": "100 balls settling in a box, 4 s",
     "title": "A pile of 100 balls settling in a box for 4 s", "reference": "at rest: kinetic "
     "energy 0, no overlap", "headline": ("penetration", "deepest penetration (m)")},
    {"scene": "ball_pile_300", "group": "pile", "variant": "300 balls", "duration": 2.0,
     "short": "300 balls settling in a box",
     "title": "A pile of 300 balls settling in a box", "reference": "at rest: kinetic energy 0, "
     "no overlap", "headline": ("penetration", "deepest penetration (m)")},
    {"scene": "ball_pile_1000", "group": "pile", "variant": "1,000 balls", "duration": 2.0,
     "short": "1,000 balls settling in a box",
     "title": "A pile of 1,000 balls settling in a box", "reference": "at rest: kinetic energy 0, "
     "no overlap", "headline": ("penetration", "deepest penetration (m)")},
    {"scene": "bounce_e0.5", "group": "bounce", "variant": "e = 0.5", "duration": 1.9,
     "short": "1,000 bounces, e = 0.5",
     "title": "1,000 bounces, e = 0.5", "exact": 14,
     "reference": "closed form h e^(2k) for every bounce rising at least 1 nm (14)",
     "headline": ("apex_error_10", "worst apex error, bounces 1-10 (relative)")},
    {"scene": "bounce_e0.9", "group": "bounce", "variant": "e = 0.9", "duration": 9.1,
     "short": "1,000 bounces, e = 0.9",
     "title": "1,000 bounces, e = 0.9", "exact": 98,
     "reference": "closed form h e^(2k) for every bounce rising at least 1 nm (98)",
     "headline": ("apex_error_10", "worst apex error, bounces 1-10 (relative)")},
    {"scene": "bounce_e1", "group": "bounce", "variant": "e = 1", "duration": 903.5,
     "short": "1,000 bounces, e = 1",
     "title": "1,000 bounces, e = 1", "exact": 1000,
     "reference": "closed form: every apex at the drop height",
     "headline": ("apex_error_10", "worst apex error, bounces 1-10 (relative)")},
    {"scene": "chain_ratio_1", "group": "chain", "variant": "M/m = 1", "duration": 3.0,
     "short": "two-ball chain, M/m = 1",
     "title": "Two-ball chain, M/m = 1",
     "reference": "event-driven, 50 digits: 3 impacts",
     "headline": ("velocity", "final velocity error (m/s)")},
    {"scene": "chain_ratio_1e3", "group": "chain", "variant": "M/m = 1e3", "duration": 3.0,
     "short": "two-ball chain, M/m = 1e3",
     "title": "Two-ball chain, M/m = 1e3",
     "reference": "event-driven, 50 digits: 99 impacts",
     "headline": ("velocity", "final velocity error (m/s)")},
    {"scene": "chain_ratio_1e6", "group": "chain", "variant": "M/m = 1e6", "duration": 3.0,
     "short": "two-ball chain, M/m = 1e6",
     "title": "Two-ball chain, M/m = 1e6",
     "reference": "event-driven, 50 digits: 3141 impacts",
     "headline": ("velocity", "final velocity error (m/s)")},
    {"scene": "sphere_gas_60s", "group": "gas", "variant": "60 s", "duration": 60.0,
     "short": "sphere gas for 60 s",
     "title": "Sphere gas for 60 s",
     "reference": "conservation: the energy at the start",
     "headline": ("energy_drift", "energy drift over 60 s (relative)")},
]
GROUPS = {
    "pile": {
        "title": "Lasting contact: piles of balls settling in a box",
        "note": "N balls (r = 0.05 m, 0.1 kg, e = 0.5, frictionless) dropped from a loose cubic "
                "lattice (0.12 m apart, random offsets up to 5 mm) into a closed box, 2 s (the "
                "100 balls also 4 s), played once each (long runs). Ours steps the pile: a "
                "connected set of at least 32 balls near each other "
                "(`Scene::stepped_cluster_min_bodies`) is advanced by gap-keeping sub-steps, each "
                "update's interval (10 ms at 100 Hz, 3.3 ms at 300, 1 ms at 1000); the 27 balls "
                "stay with the exact event-driven model, and *ours, stepped (every body)* "
                "(`stepped_cluster_min_bodies = 1`) steps them too. 'stepped bodies': ours' "
                "bodies in stepped clusters after the last update. Before stepping, a settling "
                "pile of more than about 64 balls was an inelastic collapse for the exact model "
                "(more than 20,000 impacts in one 10 ms update of the 100-ball pile, whose first "
                "0.5 s took 218 s of CPU), and ours played 27 only. ODE plays up to 100 balls: "
                "its `dWorldStep` took 28 s at 300 (its dense solve grows as the cube of the "
                "contacts). Penetration: the deepest overlap of any pair or wall at any state "
                "(every state kept); the kinetic energy and the fastest ball at the end; the "
                "energy's largest rise above the start, and from one state to the next ('per "
                "update'; 0: it never rose). The balls are frictionless: at 2 s no engine's pile "
                "is at rest, balls still sliding on the floor and the upper ones wedging the "
                "lower apart; what moves at the end is that rearrangement, not energy put in, "
                "where the energy rises from one state to the next by no more than settling "
                "within the touching band allows (ours: below the table).",
        "columns": [("penetration_pairs", "deepest overlap, pairs (m)", fmt),
                    ("penetration_walls", "deepest penetration, walls (m)", fmt),
                    ("kinetic_end", "kinetic energy at the end (J)", fmt),
                    ("final_speed", "fastest ball at the end (m/s)", fmt),
                    ("energy_gain", "energy gain (J)", fmt),
                    ("energy_step_rise", "energy rise per update, largest (J)", fmt),
                    ("stepped_bodies", "stepped bodies", count)]},
    "bounce": {
        "title": "Long runs: 1,000 bounces on a floor, threshold 0",
        "note": "One ball (r = 0.03 m) dropped from h = 1 m, e = 0.5, 0.9 and 1, restitution "
                "threshold 0 (DART's is fixed at 0.1 m/s; MuJoCo has none). Each bounce's apex "
                "(as in the drop test: ours from its reported impacts, the others from their "
                "state at the top of each flight) against h e^(2k). With e < 1 the bounces "
                "never end but accumulate at t = sqrt(2h/g)(1 + e)/(1 - e) and soon rise less "
                "than a nanometre: bounce 15 (e = 0.5) and 99 (e = 0.9) do; the table counts the "
                "bounces that rise at least 1 nm (of N: how many do exactly); ours lets a ball "
                "rest once a bounce would not leave its contact tolerance (1e-9 of the radius). "
                "'flights seen': the flights in the engine's output (jitter at rest counts); "
                "'within 1 %': the leading bounces whose apex is within 1 % of the exact one; a "
                "missing bounce is an error of 1.",
        "columns": [("bounces", "flights seen", count),
                    ("faithful", "leading bounces within 1 %", count),
                    ("apex_error_10", "worst apex error, bounces 1-10", fmt),
                    ("apex_error_last", "apex error, last bounce above 1 nm", fmt)]},
    "chain": {
        "title": "Long runs: the two-ball chain",
        "note": "A heavy ball (1 kg, 1 m/s) driven into a light one (1/ratio kg) that rests "
                "between it and a wall, on one line, e = 1: the light ball shuttles between "
                "them, faster and faster, until both leave; ceil(pi / atan(sqrt(m/M))) - 1 "
                "impacts (3, 99, 3141; G. Galperin, 'Playing pool with pi', 2003). The light "
                "ball reaches sqrt(M/m) m/s: 1000 m/s at 1e6, which no fixed step of these "
                "rates resolves (and Box2D clips to 2 m per step). Final velocities after 3 s "
                "against the event-driven reference (worst of the two); 'through': the light "
                "ball ended behind the wall or beyond the heavy one.",
        "columns": [("velocity", "final velocity error (m/s)", fmt),
                    ("energy_drift", "energy drift (rel.)", fmt),
                    ("passed", "through", yes_no), ("impacts", "impacts (ours)", count)]},
    "gas": {
        "title": "Long runs: the sphere gas for 60 s",
        "note": "The gas of the short table, played for 60 s.",
        "columns": [("energy_drift", "energy drift (rel.)", fmt),
                    ("impacts", "impacts", count)]},
}

SETTINGS_TEXT = """Settings (each also in its source file, with where it comes from):

- **ours**: the core's `ImpactMonitor` fed at the state rate by a source that applies its
  responses (the scene player's loop, `core::Playback`), continuous or discrete detection,
  restitution threshold 0. From 32 bodies near each other under gravity (a settling pile) the
  monitor steps them as one cluster (`Scene::stepped_cluster_min_bodies`: gap-keeping sub-steps
  of each update's interval, at most 10 ms). *Stepped (every body)*: the same with
  `stepped_cluster_min_bodies = 1`, every body under gravity stepped, on the scenes that ask for
  it; its errors are read from its states, as the peers' (a stepped cluster reports no impacts).
- **Bullet** (`bench/accuracy/bullet.cpp`): `btDiscreteDynamicsWorld`, `btDbvtBroadphase`,
  sequential impulse solver, spheres and static planes, friction 0, one step per state.
  *Defaults*, and *bouncing settings* (what its maintainers recommend for bouncing: restitution
  velocity threshold 0, no warm starting, split impulse, CCD with a motion threshold of one
  radius and a swept sphere of half a radius). Bullet multiplies two bodies' restitutions: each
  body's is set so that every product is the scene's coefficient. Single precision (Debian's).
- **ODE** (`ode.cpp`): `dWorldStep`, contact joints with `dContactBounce`, bounce = e,
  bounce_vel = 0, mu = 0, default ERP and CFM. No continuous detection.
- **MuJoCo** (`mujoco.cpp`): an MJCF model per scene (free-joint spheres, static planes and
  spheres, frictionless contacts, condim 1; its default Euler integrator and Newton solver),
  one `mj_step` per state; the model is compiled once per scene and rate, outside the timing.
  *Default contact*: solref 0.02 1, solimp 0.9 0.95 0.001 (critically damped: it does not
  bounce, by design). *Restitution (solref)*: MuJoCo has no coefficient of restitution; its
  documentation (modeling guide, "Restitution") prescribes a negative solref, (-stiffness,
  -damping), with damping 0 for e = 1. For e < 1 the damping comes from the unilateral linear
  spring-dashpot the reference acceleration describes (it lets go when its force returns to
  zero: e = exp(-(beta/w)(pi - atan2(2 beta w, w^2 - beta^2))), Schwager and Poeschel, Granular
  Matter 9, 2007), inverted per pair; the stiffness gives a contact of 8 steps (the best of 2,
  4, 8, 16 on these scenes); solimp 0.9999 so that the contact follows that spring. No
  continuous detection.
- **DART** (`dart.cpp`): a `World` of free-joint spheres and welded obstacles, its boxed-LCP
  (Dantzig) constraint solver, the FCL detector with analytic primitives (planes as 200 m boxes:
  FCL's broadphase crashes on several half-spaces), restitution on each shape (DART multiplies
  the two, set as for Bullet), friction 0. DART hard-codes that a contact bounces only when
  e times its approach speed exceeds 0.1 m/s, and never faster than 100 m/s
  (`ContactConstraint.cpp`); threshold 0 cannot be asked for. **DART has no continuous
  collision detection.**
- **Box2D** (`box2d.cpp`, 2.4): the planar scenes only (the gas is 3D): circles, planes as
  two-sided edges set back by their 1 cm skin, 8 velocity and 3 position iterations (its
  manual's suggestion), the pair's coefficient set on every contact in `PreSolve`,
  `restitutionThreshold` 0, every ball a bullet (continuous detection against moving bodies
  too), sleeping off. Box2D clips a body's motion to 2 m per step (`b2_maxTranslation`) and
  works in single precision; its manual says restitution with several contacts is "simulated
  approximately".
"""


def package_version(name):
    try:
        return subprocess.run(["dpkg-query", "-W", "-f=${Version}", name], capture_output=True,
                              text=True, check=False).stdout or "?"
    except OSError:
        return "?"


class Results:
    def __init__(self, out):
        errors = json.loads((out / "errors.json").read_text())
        timing = {}
        for row in json.loads((out / "timing.json").read_text())["benchmarks"]:
            scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[row["time_unit"]]
            # Google Benchmark appends the run's options ("/min_time:0.200") to the name.
            name = row["name"].split("/min_time:")[0].split("/iterations:")[0]
            timing[name] = row["cpu_time"] * scale
        self.timing = timing
        self.kernels = errors["kernels"]
        self.runs = errors["runs"]
        for run in self.runs:
            run["cpu"] = timing.get(run["name"])  # s per run of the scene

    def find(self, scene, engine, variant, rate, effects="none"):
        for run in self.runs:
            if (run["scene"], run["engine"], run["variant"], run["rate"], run["effects"]) == (
                    scene, engine, variant, rate, effects):
                return run
        return None

    def played(self, scene, engine, variant):
        """The runs of a setting on a scene, by rate (unsupported ones left out)."""
        return [r for r in self.runs if (r["scene"], r["engine"], r["variant"], r["effects"]) ==
                (scene, engine, variant, "none") and not r["unsupported"]]

    def unsupported(self, scene):
        reasons = {}
        for r in self.runs:
            if r["scene"] == scene and r["unsupported"]:
                reasons[LABEL[(r["engine"], r["variant"])]] = r["unsupported"]
        return reasons


def metric(run, key):
    return None if run is None else run["metrics"].get(key)


def badness(run, key):
    value = metric(run, key)
    return math.inf if value is None else value


def best(results, scene, engine, key):
    """The engine's best setting on the scene: the smallest error, then the least CPU."""
    candidates = [r for (e, v) in ENGINES if e == engine for r in results.played(scene, e, v)
                  if r["cpu"] is not None]
    if not candidates:
        return None
    return min(candidates, key=lambda r: (badness(r, key), r["cpu"]))


def ms(seconds):
    return "n/a" if seconds is None else f"{seconds * 1e3:.3g} ms"


def setting_name(run):
    return f"{LABEL[(run['engine'], run['variant'])]}, {int(run['rate'])} Hz"


# --- the tables ----------------------------------------------------------------------------------

def cpu_cells(run):
    cpu = run["cpu"]
    per_update = None if cpu is None else cpu / max(run["updates"], 1)
    return ["n/a" if per_update is None else f"{per_update * 1e6:.3g} us", ms(cpu)]


def scene_table(results, spec):
    lines = [f"## {spec['title']}", "", f"Reference: {spec['reference']}.", ""]
    if spec.get("note"):
        lines += [spec["note"], ""]
    header = ["setting", "rate (Hz)"] + [c[1] for c in spec["columns"]] + ["CPU per update",
                                                                           "CPU per run"]
    lines.append("| " + " | ".join(header) + " |")
    lines.append("|" + "---|" * len(header))
    for engine, variant in ENGINES:
        for run in results.played(spec["scene"], engine, variant):
            cells = [LABEL[(engine, variant)], str(int(run["rate"]))] + [
                c[2](metric(run, c[0])) for c in spec["columns"]] + cpu_cells(run)
            lines.append("| " + " | ".join(cells) + " |")
    for run in results.runs:
        if (run["scene"] == spec["scene"] and run["effects"] != "none"
                and not run["variant"].startswith("tolerance_")):
            cells = [f"ours, continuous, {run['effects']} on", str(int(run["rate"]))] + [
                c[2](metric(run, c[0])) if c[0] in run["metrics"] else "no reference"
                for c in spec["columns"]] + cpu_cells(run)
            lines.append("| " + " | ".join(cells) + " |")
    for label, reason in results.unsupported(spec["scene"]).items():
        lines += ["", f"{label}: {reason}."]
    return lines + [""]


def group_table(results, group, specs):
    info = GROUPS[group]
    lines = [f"## {info['title']}", "", info["note"], "",
             "References: " + "; ".join(f"{s['variant']}: {s['reference']}" for s in specs) + ".",
             ""]
    header = ["case", "setting", "rate (Hz)"] + [c[1] for c in info["columns"]] + ["CPU per run"]
    lines.append("| " + " | ".join(header) + " |")
    lines.append("|" + "---|" * len(header))
    for spec in specs:
        for engine, variant in ENGINES:
            for run in results.played(spec["scene"], engine, variant):
                cells = [spec["variant"], LABEL[(engine, variant)], str(int(run["rate"]))]
                for key, _, form in info["columns"]:
                    text = form(metric(run, key))
                    if key == "faithful" and "exact" in spec and text != "n/a":
                        text += f" of {spec['exact']}"
                    cells.append(text)
                cells.append(ms(run["cpu"]))
                lines.append("| " + " | ".join(cells) + " |")
    reasons = {}
    for spec in specs:
        reasons.update(results.unsupported(spec["scene"]))
    for label, reason in reasons.items():
        lines += ["", f"{label}: {reason}."]
    if group == "pile":
        lines += pile_findings(results, specs)
    return lines + [""]


def pile_findings(results, specs):
    """What the pile table shows of ours that its note cannot know in advance."""
    def runs(variant):
        return [(spec, r) for spec in specs for r in results.played(spec["scene"], "ours", variant)]

    def where(found):
        return "; ".join(f"{spec['variant']} at {int(r['rate'])} Hz ({fmt(metric(r, key))} m)"
                         for spec, r, key in found)
    lines = []
    rises = [metric(r, "energy_step_rise") for _, r in runs("continuous") + runs("stepped")]
    rises = [v for v in rises if v is not None]
    # The 27-ball pile is below stepped_cluster_min_bodies: the exact model alone.
    exact_rises = [metric(r, "energy_step_rise") for spec, r in runs("continuous")
                   if spec["scene"] == "ball_pile_27"]
    exact_rises = [v for v in exact_rises if v is not None] or [0.0]
    if rises:
        lines += ["", f"Ours' largest energy rise from one state to the next, over every pile and "
                      f"rate: {fmt(max(rises))} J. Settling within the touching band (1e-11 m) "
                      f"accounts for 1e-9 J at most. The 27-ball pile, never stepped (the exact "
                      f"model alone), rises by up to "
                      f"{fmt(max(exact_rises))} J: the player resolves the impacts it has not "
                      f"heard yet itself (doc/model.md, 'The scene player and the scenes'), and the monitor's, heard "
                      f"an update later, replace them; in a ball's last micro-bounces the two "
                      f"histories part at the rounding of the contact, each losing energy, one "
                      f"losing a little more. Above that, the stepped bounce: a contact "
                      f"that closes within a sub-step is stopped at it (the state shows the ball "
                      f"at the contact, its arrival's energy gone), and bounces at the next "
                      f"sub-step at e times the speed it arrived at, giving back part of what "
                      f"the state before did not show. The energy never rises above the drop's "
                      f"('energy gain')."]
    deep = [(spec, r, "penetration") for spec, r in runs("continuous") + runs("stepped")
            if (metric(r, "penetration") or 0) > 1e-9]
    if deep:
        lines += ["", "Ours deeper than 1e-9 m: " + where(deep) + ". Open work: doc/model.md, "
                  "'Where it does not hold yet'."]
    through = [(spec, r, "penetration_walls") for spec, r in runs("discrete")
               if (metric(r, "penetration_walls") or 0) > 0.1]
    if through:
        lines += ["", "Ours, discrete, let a ball through a wall (deeper than a diameter): " +
                  where(through) + " (a ball "
                  "pressed into the floor while it overlaps it is not found again: discrete "
                  "detection tests only pairs that did not overlap at the state before)."]
    return lines


def tolerance_table(results, scene="ball_off_sphere"):
    """Ours at each contact_integration_tolerance: the curved contact's error against CPU."""
    runs = [r for r in results.runs if r["scene"] == scene and r["variant"].startswith("tolerance_")]
    if not runs:
        return []
    lines = ["## The curved contact's integrator: error against CPU", "",
             "The ball off the fixed sphere, ours (continuous, 100 Hz) at each "
             "`Scene::contact_integration_tolerance` (the Dormand-Prince error allowed per step, "
             "default 1e-9): the leaving angle's error against the closed form, and the CPU per "
             "run of the scene (1.5 s).", "",
             "| effects | tolerance | leaving angle error (rad) | penetration into the sphere (m) "
             "| CPU per update | CPU per run |", "|---|---|---|---|---|---|"]
    for run in sorted(runs, key=lambda r: (r["effects"], -r["tolerance"])):
        effects = "frictionless" if run["effects"] == "none" else run["effects"]
        lines.append(f"| {effects} | {run['tolerance']:.0e} | {fmt(metric(run, 'leave_angle'))} | "
                     f"{fmt(metric(run, 'penetration_sphere'))} | " + " | ".join(cpu_cells(run)) +
                     " |")
    return lines + [""]


def substep(rate, time_step=0.01):
    """The stepped clusters' sub-step at a state rate: the update's interval split into the
    fewest equal sub-steps of at most 1.25 Scene::stepped_cluster_time_step (0.01 s), as
    Stepping::beginStep does."""
    interval = 1.0 / rate
    return interval / max(1, math.ceil(interval / (1.25 * time_step)))


STEPPED = [("drop_test", "restitution", "e from the first apex (rel.)"),
           ("ball_corner", "rest_error", "rest position error (m)"),
           ("ball_off_sphere", "leave_angle", "leaving angle error (rad)"),
           ("ball_stack", "drift", "drift of the centres (m)"),
           ("ball_pile_27", "penetration", "deepest penetration (m)")]


def stepped_table(results):
    """Ours, stepped (every body) beside ours, exact, on the scenes with closed-form answers."""
    lines = ["## What the stepped model costs: error against CPU", "",
             "Ours with every body under gravity in a stepped cluster "
             "(`Scene::stepped_cluster_min_bodies = 1`, *ours, stepped (every body)*) beside the "
             "exact event-driven model (*ours, continuous*) on the same scenes, against the same "
             "closed-form references; the sub-step is each update's interval, split into the fewest "
             "equal sub-steps of at most 1.25 `Scene::stepped_cluster_time_step` (0.01 s). CPU "
             "per run of "
             "the scene. The stepped run's error is read from its states, as the peers' (a "
             "stepped cluster reports no impacts).", "",
             "| scene | measure | rate (Hz) | sub-step (ms) | exact: error | exact: CPU | "
             "stepped: error | stepped: CPU | stepped / exact CPU |",
             "|---|---|---|---|---|---|---|---|---|"]
    for scene, key, label in STEPPED:
        short = next(spec["short"] for spec in SCENES if spec["scene"] == scene)
        for run in results.played(scene, "ours", "stepped"):
            exact = results.find(scene, "ours", "continuous", run["rate"])
            ratio = (f"{run['cpu'] / exact['cpu']:.2f}" if exact and exact["cpu"] and run["cpu"]
                     else "n/a")
            lines.append(f"| {short} | {label} | {int(run['rate'])} | "
                         f"{substep(run['rate']) * 1e3:.3g} | {fmt(metric(exact, key))} | "
                         f"{ms(exact['cpu'] if exact else None)} | {fmt(metric(run, key))} | "
                         f"{ms(run['cpu'])} | {ratio} |")
    if len(lines) == 7:
        return []
    lasting = [metric(r, key) for scene, key, _ in STEPPED if scene != "drop_test" and
               scene != "ball_off_sphere" for r in results.played(scene, "ours", "stepped")]
    lasting = [v for v in lasting if v is not None]
    text = STEPPED_TEXT
    if lasting:
        text += (f" There the corner's rest, the stack's drift and the 27-ball pile's "
                 f"penetration, stepped, stay within {fmt(max(lasting))} m at every rate above.")
    return lines + ["", text, ""]


STEPPED_TEXT = """How a sub-step moves a body (`src/core/solver/stepped_contact.h`): the
touching contacts that strike bounce (Newton's law, at e times the larger of their approach
and the speed they arrived at in the sub-step before), gravity's kick g h is added, and the velocities
nearest those that keep every gap open at the sub-step's end are taken; the body moves in a
straight line at them. Three consequences, all visible above:

- **In flight** the straight line at the velocity after the kick puts a falling body
  g h t / 2 below its parabola after a time t (first order in h: 2.2 cm after the drop test's
  0.44 s of fall at 100 Hz), and the energy it loses so is never regained.
- **On a curved surface** the gap kept is the linear one along the normal at the sub-step's
  start: a ball sliding at v over the fixed sphere (radius R + r to its centre) ends each
  sub-step v^2 h^2 / 2 (R + r) = g h^2 (1 - cos theta) clear of it and falls back. The ball off
  the sphere is read as having left once a state is 10 um clear: at a 10 ms sub-step that is at
  theta = 0.14 rad, long before the exact 0.84 rad; at 1 ms the clearance stays below 10 um.
- **A bounce**: the sub-step in which the ball reaches the floor ends with it touching, its
  approach cut by the gap keeping to gap / h; that sub-step records the speed at which it
  arrived, and the next one's bounce sends it off at e times that. The state between shows
  the ball at the floor, not on its way back up, so the apex read from the states is that of
  a ball leaving up to one sub-step late, from a height the straight-line fall has left below
  the parabola: e is off by 1 to 2.5 % up to 100 Hz (above), and the energy rises from that
  state to the next by what the arrival lost there.

Resting and sliding contact on planes and between balls (the corner, the stack, the pile) is
what the stepped model is for."""


def key_ratios(results):
    """For every scene: our error and CPU against each peer's best setting."""
    lines = ["## Key ratios", "",
             "For every scene and every peer: the peer's best setting (the smallest error of the "
             "scene's headline metric over its variants and rates, then the least CPU), beside "
             "our continuous detection at the same rate; CPU per run of the scene, from this one "
             "run. 'ours / peer': our CPU over the peer's.", "",
             "| scene | metric | peer: best setting | peer: error | peer: CPU | ours: error | "
             "ours: CPU | ours / peer |", "|---|---|---|---|---|---|---|---|"]
    for spec in SCENES:
        key, label = spec["headline"]
        for engine, name in PEERS:
            peer = best(results, spec["scene"], engine, key)
            if peer is None:
                reasons = {r["unsupported"] for r in results.runs
                           if r["scene"] == spec["scene"] and r["engine"] == engine
                           and r["unsupported"]}
                if reasons:
                    lines.append(f"| {spec['short']} | {label} | {name}: {reasons.pop()} "
                                 f"| | | | | |")
                continue
            ours = results.find(spec["scene"], "ours", "continuous", peer["rate"])
            ratio = (f"{ours['cpu'] / peer['cpu']:.2f}" if ours and ours["cpu"] and peer["cpu"]
                     else "n/a")
            lines.append(f"| {spec['short']} | {label} | {setting_name(peer)} | "
                         f"{fmt(metric(peer, key))} | {ms(peer['cpu'])} | "
                         f"{fmt(metric(ours, key))} | {ms(ours['cpu'] if ours else None)} | "
                         f"{ratio} |")
    return lines + [""]


def detection_ratios(results):
    lines = []
    for rate in (30, 100, 1000):
        c = results.find("drop_test", "ours", "continuous", rate)
        d = results.find("drop_test", "ours", "discrete", rate)
        if c and d and c["cpu"] and d["cpu"]:
            lines.append(f"- Drop test at {rate} Hz: continuous detection costs "
                         f"{c['cpu'] / d['cpu']:.2f}x discrete ({ms(c['cpu'])} vs {ms(d['cpu'])} "
                         f"per run); e error {fmt(metric(c, 'restitution'))} vs "
                         f"{fmt(metric(d, 'restitution'))}.")
    return lines


def kernel_table(results):
    k = results.kernels
    t = {name: results.timing.get(f"kernel/{name}") for name in
         ("impact/double", "impact/float", "time_of_impact/double", "time_of_impact/float")}

    def ns(value):
        return "n/a" if value is None else f"{value * 1e9:.3g} ns"
    return [
        "## Float against double (the core's kernels)", "",
        "Worst error against long double over 100,000 random cases, and CPU time per call:", "",
        "| kernel | double: error | float: error | double: CPU | float: CPU |",
        "|---|---|---|---|---|",
        f"| impact velocity (m/s, speeds ~1) | {fmt(k['impact_velocity_error']['double'])} | "
        f"{fmt(k['impact_velocity_error']['float'])} | {ns(t['impact/double'])} | "
        f"{ns(t['impact/float'])} |",
        f"| time of impact (s, times ~1) | {fmt(k['time_of_impact_error']['double'])} | "
        f"{fmt(k['time_of_impact_error']['float'])} | {ns(t['time_of_impact/double'])} | "
        f"{ns(t['time_of_impact/float'])} |", "",
        "The monitor runs in double only: float saves little CPU here and costs 9 digits.", ""]


# --- the plot ------------------------------------------------------------------------------------

def plot(results, path):
    columns = 5
    rows = math.ceil((len(SCENES) + 2) / columns)  # and two cells of legends
    figure, axes = plt.subplots(rows, columns, figsize=(4.6 * columns, 4.4 * rows))
    axes = axes.flatten()
    for ax, spec in zip(axes, SCENES):
        key, label = spec["headline"]
        ceiling = 0
        for engine, variant in ENGINES:
            points = [(r["cpu"] / spec["duration"] * 1e3, metric(r, key), int(r["rate"]))
                      for r in results.played(spec["scene"], engine, variant)
                      if r["cpu"] and metric(r, key) is not None]
            if not points:
                continue
            ceiling = max([ceiling] + [y for _, y, _ in points])
            colour = COLOUR[(engine, variant)]
            ax.plot([x for x, _, _ in points], [max(y, FLOOR) for _, y, _ in points], "-",
                    color=colour, linewidth=0.8, alpha=0.6)
            for x, y, rate in points:
                ax.plot([x], [max(y, FLOOR)], MARKER.get(rate, "x"), color=colour, markersize=6,
                        markeredgecolor="black", markeredgewidth=0.4)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.axhline(FLOOR, color="black", linestyle="--", linewidth=0.9)
        ax.text(0.98, 0.06, "exact (error 0)", transform=ax.transAxes, fontsize=7.5,
                ha="right", va="bottom")
        ax.set_ylim(FLOOR / 30, max(ceiling, 1.0) * 30)
        ax.set_title(spec["short"] + "\n" + textwrap.fill("reference: " + spec["reference"], 62),
                     fontsize=8)
        ax.set_ylabel(label, fontsize=8)
        ax.set_xlabel("CPU ms per simulated second", fontsize=8)
        ax.grid(True, which="major", linewidth=0.3)
        ax.tick_params(labelsize=7)
    for ax in axes[len(SCENES):]:
        ax.axis("off")
    axes[len(SCENES)].legend(
        handles=[Line2D([], [], color=COLOUR[e], marker="o", linestyle="-", label=LABEL[e])
                 for e in ENGINES], loc="center", title="engine setting (colour)", fontsize=9)
    axes[len(SCENES) + 1].legend(
        handles=[Line2D([], [], color="grey", marker=m, linestyle="", markeredgecolor="black",
                        label=f"{r} Hz") for r, m in MARKER.items()],
        loc="center", title="state rate (marker)", fontsize=9)
    figure.suptitle("Error against CPU time (log-log), one panel per scene: each point one engine "
                    "setting at one state rate; an error of exactly 0 lies on the dashed 'exact' "
                    "line", fontsize=12)
    figure.tight_layout(rect=(0, 0, 1, 0.97))
    figure.savefig(path, dpi=80)


# --- the section of doc/measurements.md ------------------------------------------------------------------------

def readme_section(results):
    rows = ["| scene | measure | reference | ours, continuous, 100 Hz | its CPU | best peer: setting "
            "| its error | its CPU |", "|---|---|---|---|---|---|---|---|"]
    for spec in SCENES:
        key, label = spec["headline"]
        ours = results.find(spec["scene"], "ours", "continuous", 100)
        peers = [best(results, spec["scene"], engine, key) for engine, _ in PEERS]
        peers = [p for p in peers if p is not None]
        top = min(peers, key=lambda r: (badness(r, key), r["cpu"])) if peers else None
        rows.append(f"| {spec['short']} | {label} | {spec['reference']} | "
                    f"{fmt(metric(ours, key))} | {ms(ours['cpu'] if ours else None)} | "
                    f"{setting_name(top) if top else 'n/a'} | {fmt(metric(top, key))} | "
                    f"{ms(top['cpu'] if top else None)} |")
    gas = {}
    for engine, variant in ENGINES:
        values = [metric(r, "energy_drift") for r in results.played("sphere_gas_60s", engine,
                                                                      variant)]
        values = [v for v in values if v is not None]
        if values:
            gas[LABEL[(engine, variant)]] = (min(values), max(values))
    gas_text = "; ".join(f"{name} {fmt(lo)}" + ("" if fmt(lo) == fmt(hi) else f" to {fmt(hi)}")
                         for name, (lo, hi) in gas.items())
    bounce = results.find("bounce_e1", "ours", "continuous", 100)
    chain = results.find("chain_ratio_1e6", "ours", "continuous", 100)
    caught = {}
    for r in results.runs:
        if (r["scene"] == "tunnelling" and r["engine"] != "ours" and not r["unsupported"]
                and metric(r, "missed") == 0):
            caught.setdefault(LABEL[(r["engine"], r["variant"])], []).append(int(r["rate"]))
    tunnel = [f"{name} ({', '.join(str(rate) for rate in rates)} Hz)"
              for name, rates in caught.items()]
    lines = [
        "![error against CPU time, one panel per scene](accuracy.png)", "",
        "Each panel is one scene: the error of its headline measure (y, log) against the CPU time "
        "per simulated second (x, log) for every engine setting (colour) at every state rate "
        "(marker); an error of exactly 0 sits on the dashed line marked 'exact'. Each panel "
        "names its reference, computed outside the code under test "
        "(`bench/accuracy/reference/make_references.py`: closed forms, or the exact "
        "event-driven motion in 50-digit arithmetic; the gas: its conserved energy). Full "
        "tables, every setting and the key ratios against each peer: [accuracy.md](accuracy.md).", "",
        "Key rows, from the last run (one shared 2-core machine; ratios within one run hold "
        "better than absolute times):", ""] + rows + [""]
    lines += detection_ratios(results)
    if bounce and chain:
        lines.append(f"- 1,000 bounces with e = 1: our 1,000th apex is within "
                     f"{fmt(metric(bounce, 'apex_error_last'))} of the drop height; the "
                     f"two-ball chain at mass ratio 1e6 makes {count(metric(chain, 'impacts'))} "
                     f"impacts (exact: 3141) and ends within {fmt(metric(chain, 'velocity'))} m/s "
                     f"of the exact velocities.")
    lines.append(f"- Energy of the gas over 60 s (drift, over the rates run): {gas_text}.")
    tolerances = sorted((r for r in results.runs if r["scene"] == "ball_off_sphere"
                         and r["variant"].startswith("tolerance_") and r["effects"] == "none"),
                        key=lambda r: -r["tolerance"])
    if tolerances:
        lines.append("- Lasting contact, the curved contact's integrator (the ball off the sphere, "
                     "100 Hz): leaving angle error " + "; ".join(
                         f"{fmt(metric(r, 'leave_angle'))} rad in {ms(r['cpu'])} at tolerance "
                         f"{r['tolerance']:.0e}" for r in tolerances) + ".")
    piles = [(spec["variant"], results.find(spec["scene"], "ours", "continuous", 100))
             for spec in SCENES if spec.get("group") == "pile"]
    lines.append("- Piles settling (ours, 100 Hz; from 32 balls stepped): " + "; ".join(
        f"{variant}: CPU {ms(run['cpu'])}, deepest penetration "
        f"{fmt(metric(run, 'penetration'))} m, kinetic energy at the end "
        f"{fmt(metric(run, 'kinetic_end'))} J" if run else f"{variant}: not played"
        for variant, run in piles) + ".")
    drops = [(results.find("drop_test", "ours", "continuous", rate),
              results.find("drop_test", "ours", "stepped", rate)) for rate in (100, 1000)]
    if all(exact and stepped for exact, stepped in drops):
        lines.append("- Every body stepped (`stepped_cluster_min_bodies = 1`), the drop test's e "
                     "from the first bounce: " + "; ".join(
                         f"{fmt(metric(stepped, 'restitution'))} in {ms(stepped['cpu'])} at "
                         f"{int(stepped['rate'])} Hz (exact: {fmt(metric(exact, 'restitution'))} in "
                         f"{ms(exact['cpu'])})" for exact, stepped in drops) +
                     "; see [accuracy.md](accuracy.md), 'What the stepped model costs'.")
    lines.append("- The fast ball against the post is caught by ours (continuous) at every "
                 "rate; among the peers by: " + (", ".join(tunnel) if tunnel else "none") + ".")
    return lines


def replace_readme(readme, section):
    text = readme.read_text()
    begin = "<!-- accuracy:begin: written by scripts/accuracy_report.py (bash scripts/accuracy.sh); do not edit -->"
    end = "<!-- accuracy:end -->"
    if begin not in text or end not in text:
        sys.exit(f"{readme}: the accuracy markers are missing")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    readme.write_text(head + begin + "\n" + "\n".join(section) + "\n" + end + tail)


def main():
    out, doc, readme = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    results = Results(out)
    lines = [
        "# What accuracy costs in time", "",
        "Regenerate: `bash scripts/accuracy.sh` (it builds, installs what it needs, computes the "
        "references, runs every setting and writes this page, `doc/accuracy.png` and the "
        "accuracy section of `doc/measurements.md`). Errors are against references computed outside the code "
        "under test, by `bench/accuracy/reference/make_references.py` (mpmath, 50 digits, from "
        "the scenes' inputs taken exactly): closed forms where they exist, otherwise the exact "
        "event-driven motion, and for the gas its conserved energy; each table names its "
        "reference. CPU time is Google Benchmark's, per run of the scene (the short scenes: "
        "repeated for at least 0.1 s; the long runs: one run each), on a "
        f"{platform.machine()} machine of this project, every engine in the same run. Bullet "
        f"{package_version('libbullet-dev')}, ODE {package_version('libode-dev')}, MuJoCo "
        f"{package_version('libmujoco-dev')}, DART {package_version('libdart-dev')} and Box2D "
        f"{package_version('libbox2d-dev')}, all Debian's.", "", SETTINGS_TEXT]
    lines += key_ratios(results)
    lines += ["## Continuous against discrete detection", ""] + detection_ratios(results) + [""]
    for spec in SCENES:
        if "group" not in spec:
            lines += scene_table(results, spec)
    done = set()
    for spec in SCENES:
        group = spec.get("group")
        if group and group not in done:
            done.add(group)
            lines += group_table(results, group, [s for s in SCENES if s.get("group") == group])
    lines += stepped_table(results)
    lines += tolerance_table(results)
    lines += kernel_table(results)
    (doc / "accuracy.md").write_text("\n".join(lines) + "\n")
    plot(results, doc / "accuracy.png")
    replace_readme(readme, readme_section(results))


if __name__ == "__main__":
    main()
