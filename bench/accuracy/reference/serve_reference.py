#!/usr/bin/env python3
# serve_reference.py -- an independent high-precision reference for a table-tennis serve flying
# through air (quadratic drag + Magnus force) and bouncing twice on the table top.
#
# What it computes (nothing here calls or copies the C++ code under test):
#   A ball (m = 0.0027 kg, r = 0.02 m, A = pi r^2, C_d = 0.5, C_L = 0.2) in air (rho = 1.2 kg/m^3)
#   under gravity g = (0, 0, -9.81) m/s^2, starting at t = 0 at p0 = (-1.2, 0, 1.0) m with the
#   velocity V0 below and the spin w = (0, 150, 0) rad/s (topspin for a ball moving +x). The
#   table top is the plane z = 0.76 m (the top face of the box centred at (0, 0, 0.745) of size
#   2.74 x 1.525 x 0.03 m); the ball touches it when its centre is at z = 0.76 + r = 0.78 m.
#   The script gives the first two bounces (time, centre, velocity before and after) and the
#   crossing of the vertical plane x = 1.6 m after the second bounce (time, centre, velocity).
#
# Formulas (SI units, world frame, z up):
#   drag        F_D = -1/2 rho C_d A |v| v          (standard quadratic drag, as in the source
#                                                    below: F_D = 1/2 C_D rho A v^2 against v)
#   Magnus      F_M =  1/2 rho C_L A |v| (w_hat x v), w_hat = w/|w| (zero force when w = 0),
#               i.e. F = 1/2 C_L rho A v^2 along w_hat x v_hat
#               Source for both: A. M. Nathan, "The effect of spin on the flight of a baseball",
#               Am. J. Phys. 76, 119 (2008), doi:10.1119/1.2805242.
#   motion      dp/dt = v,  dv/dt = g + (F_D + F_M)/m;  C_d and C_L constant; the spin w is
#               constant (no spin decay, no torque of the air).
#   bounce      at centre z = 0.78 while falling: v_z -> -e v_z with e = 0.9; v_x, v_y and the
#               spin unchanged (frictionless bounce, the spin does not change at the bounce).
#
# How:
#   - every constant is an exact decimal (mpmath.mpf of its string), carried with mp.dps = 40;
#   - each flight (start -> bounce 1 -> bounce 2 -> plane) is integrated with mpmath.odefun (a
#     Taylor-series integrator whose tolerance is the working precision), restarted at each bounce
#     from the bounced state;
#   - the flight is sampled every 1 ms to bracket the events and to check the scene (below); each
#     event (centre z = 0.78 while falling; x = 1.6; x = 0 for the net) is then solved with
#     mpmath.findroot (Newton, the derivative being the state's own velocity component) to the
#     full working precision; the vertical acceleration is checked negative at every sample (z
#     is concave in each flight: one apex, so the bracketed root is the flight's only descent
#     through z = 0.78 and no touch between samples is missed);
#   - the reference's own error is estimated by recomputing everything with 50 digits: the
#     written reference_error_bound is the largest absolute difference (in the quantity's own SI
#     unit, over every number written) between the printed 20-digit value and that 50-digit
#     value; it therefore includes the rounding to 20 significant digits (which dominates);
#   - checks of the scene (the script stops if one fails): first bounce on the server's half
#     (-1.37 + 0.05 < x < -0.1), second on the receiver's half (0.1 < x < 1.37 - 0.05), |y| < 0.7
#     at both; the net (0.1525 above the top at x = 0) cleared, centre z > 0.76 + 0.1525 + r at
#     x = 0 before the second bounce; the centre above z = 0.78 + 0.01 at every sample except on
#     the monotone descent into a bounce and the monotone rise out of it (so the ball touches the
#     top face only at the bounces, never an edge); |y| < 0.7625 - r - 0.01 throughout (never
#     near a side edge); after the second bounce the centre stays more than r + 0.01 from the
#     table's end edge (x = 1.37, z = 0.76) and crosses x = 1.6 with z > 0.8 before coming down
#     to z = 0.78 again.
#
# Run (needs Debian's python3-mpmath: apt-get install -y python3-mpmath):
#   /usr/bin/python3 bench/accuracy/reference/serve_reference.py
#       writes serve_reference.txt next to this script (from any working directory); about
#       15 s (5 s for the 40-digit reference, the rest for the 50-digit error estimate).
#   /usr/bin/python3 bench/accuracy/reference/serve_reference.py --no-air
#       prints (does not write) the same quantities with drag and Magnus off (pure ballistic
#       flight, same bounces), checks them against the closed-form parabolas and prints the
#       differences, and prints which of the scene's checks the ballistic flight passes.
#
# Output format (serve_reference.txt): '#' comment lines at the top, then one item per line,
# numbers with 20 significant digits; positions are the ball's centre:
#   initial_position x y z / initial_velocity x y z / angular_velocity x y z /
#   bounceK_time t / bounceK_position x y z / bounceK_velocity_before x y z /
#   bounceK_velocity_after x y z (K = 1, 2) / crossing_time t / crossing_position x y z /
#   crossing_velocity x y z / reference_error_bound value
import os
import sys
import time

import mpmath
from mpmath import mp, mpf

DPS = 40            # working precision of the reference (decimal digits)
CHECK_DPS = 50      # the recomputation that estimates the reference's error
DIGITS = 20         # significant digits written

# The constants, as exact decimal strings.
MASS = "0.0027"               # kg
RADIUS = "0.02"               # m
DRAG_COEFFICIENT = "0.5"      # C_d
LIFT_COEFFICIENT = "0.2"      # C_L
AIR_DENSITY = "1.2"           # kg/m^3
GRAVITY = ("0", "0", "-9.81")  # m/s^2
RESTITUTION = "0.9"           # e of the ball on the table top
TABLE_TOP = "0.76"            # m: z of the table's top face (box centre z 0.745, half height 0.015)
TABLE_HALF_LENGTH = "1.37"    # m: the table spans -1.37 < x < 1.37 (length 2.74)
TABLE_HALF_WIDTH = "0.7625"   # m: and -0.7625 < y < 0.7625 (width 1.525)
NET_HEIGHT = "0.1525"         # m above the top, at x = 0
PLANE_X = "1.6"               # m: the vertical plane crossed after the second bounce

P0 = ("-1.2", "0.0", "1.0")   # m: the centre at t = 0
W0 = ("0", "150", "0")        # rad/s: topspin for a ball moving +x (its Magnus force points down)
# m/s: the serve's initial velocity, chosen (round components) so that, with air, the first
# bounce is on the server's half (x ~ -0.90), the second on the receiver's half (x ~ 0.66), the
# net is cleared by ~18 cm and the ball crosses x = 1.6 at z ~ 0.88 (past the apex after the
# second bounce, falling); and so that the same serve without air (--no-air) passes the same
# checks too (bounces at x ~ -0.89 and ~1.22, crossing at z ~ 0.98), so that it can validate a
# ballistic run on the same table.
V0 = ("3.75", "0.25", "-2.25")

SAMPLE = mpf("0.001")         # s: the sampling step of the checks and of the event brackets
MARGIN = mpf("0.01")          # m: the clearance the checks ask for


class SceneError(Exception):
    pass


def vec(strings):
    return [mpf(s) for s in strings]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return mpmath.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def derivative_function(air):
    """dy/dt of y = (p, v) at the current precision: v, g + (F_D + F_M)/m."""
    g = vec(GRAVITY)
    m = mpf(MASS)
    area = mpmath.pi * mpf(RADIUS) ** 2
    rho = mpf(AIR_DENSITY)
    drag = rho * mpf(DRAG_COEFFICIENT) * area / (2 * m) if air else mpf(0)    # 1/m
    lift = rho * mpf(LIFT_COEFFICIENT) * area / (2 * m) if air else mpf(0)    # 1/m
    w = vec(W0)
    w_norm = norm(w)
    w_hat = [c / w_norm for c in w] if w_norm != 0 else [mpf(0)] * 3

    def f(t, y):
        v = y[3:6]
        speed = norm(v)
        magnus = cross(w_hat, v)
        a = [g[i] - drag * speed * v[i] + lift * speed * magnus[i] for i in range(3)]
        return [v[0], v[1], v[2], a[0], a[1], a[2]]
    return f


def solve_event(flight, component, target, t_before, t_after):
    """The time in [t_before, t_after] at which y[component] == target (component 0 or 2 of the
    position; its derivative is y[component + 3]), by Newton to full precision."""
    def residual(t):
        return flight(t)[component] - target

    def slope(t):
        return flight(t)[component + 3]
    r_before, r_after = residual(t_before), residual(t_after)
    guess = t_before + (t_after - t_before) * r_before / (r_before - r_after)   # the chord's root
    try:
        t = mpmath.findroot(residual, guess, solver="newton", df=slope, tol=mp.eps,
                            verify=False, maxsteps=50)
    except (ValueError, ZeroDivisionError) as error:
        raise SceneError("event root not found in [%s, %s]: %r" % (t_before, t_after, error))
    if not t_before <= t <= t_after:
        raise SceneError("event root %s outside its bracket [%s, %s]" % (t, t_before, t_after))
    if abs(residual(t)) > mp.eps * 16:
        raise SceneError("event root not converged: residual %s" % residual(t))
    return t


def fly(air):
    """Everything the output lists, computed at the current precision; and the checks' samples."""
    f = derivative_function(air)
    z_contact = mpf(TABLE_TOP) + mpf(RADIUS)
    plane_x = mpf(PLANE_X)
    state = vec(P0) + vec(V0)
    t0 = mpf(0)
    result = {"initial_position": state[0:3], "initial_velocity": state[3:6],
              "angular_velocity": vec(W0)}
    segments = []                # per flight: (list of (t, y) samples, start time, end kind)
    for leg in (1, 2, 3):        # to bounce 1, to bounce 2, to the plane x = 1.6
        if leg == 3 and state[0] >= plane_x:
            raise SceneError("the second bounce is past x = %s" % PLANE_X)
        flight = mpmath.odefun(f, t0, state)
        samples = [(t0, state)]
        k = 1
        while True:
            t = t0 + k * SAMPLE
            y = flight(t)
            if leg < 3 and y[2] <= z_contact and y[5] < 0:
                t_event = solve_event(flight, 2, z_contact, samples[-1][0], t)
                break
            if leg == 3 and y[2] <= z_contact and y[5] < 0:
                raise SceneError("the ball comes down to the table height before x = %s"
                                 % PLANE_X)
            if leg == 3 and y[0] >= plane_x:
                t_event = solve_event(flight, 0, plane_x, samples[-1][0], t)
                break
            if t > 10:
                raise SceneError("no event within 10 s")
            samples.append((t, y))
            k += 1
        y_event = flight(t_event)
        samples.append((t_event, y_event))
        net = None
        if leg == 2:             # the net: x = 0 between the bounces
            for (ta, ya), (tb, yb) in zip(samples, samples[1:]):
                if ya[0] < 0 <= yb[0]:
                    t_net = solve_event(flight, 0, mpf(0), ta, tb)
                    net = (t_net, flight(t_net))
        max_az = max(f(t, y)[5] for t, y in samples)
        segments.append((samples, leg, net, max_az))
        if leg < 3:
            after = list(y_event)
            after[5] = -mpf(RESTITUTION) * after[5]
            result["bounce%d_time" % leg] = t_event
            result["bounce%d_position" % leg] = y_event[0:3]
            result["bounce%d_velocity_before" % leg] = y_event[3:6]
            result["bounce%d_velocity_after" % leg] = after[3:6]
            t0, state = t_event, after
        else:
            result["crossing_time"] = t_event
            result["crossing_position"] = y_event[0:3]
            result["crossing_velocity"] = y_event[3:6]
    return result, segments


def check_scene(result, segments):
    """The scene's checks (see the header); returns (list of failures, list of margins)."""
    failures, notes = [], []
    half_length = mpf(TABLE_HALF_LENGTH)
    half_width = mpf(TABLE_HALF_WIDTH)
    r = mpf(RADIUS)
    top = mpf(TABLE_TOP)
    z_contact = top + r
    p1, p2 = result["bounce1_position"], result["bounce2_position"]
    if not -half_length + mpf("0.05") < p1[0] < mpf("-0.1"):
        failures.append("bounce 1 at x = %s, not on the server's half" % mpmath.nstr(p1[0], 6))
    if not mpf("0.1") < p2[0] < half_length - mpf("0.05"):
        failures.append("bounce 2 at x = %s, not on the receiver's half" % mpmath.nstr(p2[0], 6))
    for k, p in ((1, p1), (2, p2)):
        if not abs(p[1]) < mpf("0.7"):
            failures.append("bounce %d at |y| = %s >= 0.7" % (k, mpmath.nstr(abs(p[1]), 6)))
    notes.append("bounce 1 at x = %s, bounce 2 at x = %s"
                 % (mpmath.nstr(p1[0], 6), mpmath.nstr(p2[0], 6)))
    net = segments[1][2]
    max_az = max(seg[3] for seg in segments)
    if not max_az < 0:
        failures.append("the vertical acceleration reaches %s >= 0" % mpmath.nstr(max_az, 6))
    if net is None:
        failures.append("the ball does not reach the net between the bounces")
    else:
        net_z = net[1][2]
        need = top + mpf(NET_HEIGHT) + r
        notes.append("net: centre z = %s at x = 0 (t = %s), clears the net's top by %s m"
                     % (mpmath.nstr(net_z, 8), mpmath.nstr(net[0], 8),
                        mpmath.nstr(net_z - need + r, 6)))
        if not net_z > need:
            failures.append("the net is not cleared: centre z %s <= %s at x = 0"
                            % (mpmath.nstr(net_z, 8), mpmath.nstr(need, 8)))
    low_time, max_abs_y, min_edge = mpf(0), mpf(0), None
    for samples, leg, _, _ in segments:
        zs = [(y[2], y[5]) for _, y in samples]
        high = [i for i, (z, _) in enumerate(zs) if z > z_contact + MARGIN]
        if not high:
            failures.append("flight %d never rises above z = %s" % (leg, z_contact + MARGIN))
            continue
        first, last = high[0], high[-1]
        if any(zs[i][0] <= z_contact + MARGIN for i in range(first, last + 1)):
            failures.append("flight %d comes down to the table height between its ends" % leg)
        if any(zs[i][1] <= 0 for i in range(0, first)):     # rising out of a bounce
            failures.append("flight %d is low and not rising at its start" % leg)
        if any(zs[i][1] >= 0 for i in range(last + 1, len(zs) - 1)):   # falling into a bounce
            failures.append("flight %d is low and not falling before its bounce" % leg)
        if leg == 3 and last != len(zs) - 1:
            failures.append("the ball is below z = %s at the plane x = %s"
                            % (z_contact + MARGIN, PLANE_X))
        low_time = max(low_time, samples[first][0] - samples[0][0],
                       samples[-1][0] - samples[last][0] if leg < 3 else mpf(0))
        for _, y in samples:
            max_abs_y = max(max_abs_y, abs(y[1]))
            if leg == 3:         # the table's end edge, the line x = 1.37, z = 0.76
                d = mpmath.sqrt((y[0] - half_length) ** 2 + (y[2] - top) ** 2)
                min_edge = d if min_edge is None else min(min_edge, d)
    if not max_abs_y < half_width - r - MARGIN:
        failures.append("|y| reaches %s, near a side edge" % mpmath.nstr(max_abs_y, 6))
    if min_edge is not None and not min_edge > r + MARGIN:
        failures.append("the ball passes %s m from the table's end edge" % mpmath.nstr(min_edge, 6))
    crossing_z = result["crossing_position"][2]
    if not crossing_z > mpf("0.8"):
        failures.append("crosses x = %s at z = %s <= 0.8" % (PLANE_X, mpmath.nstr(crossing_z, 8)))
    notes.append("the centre is below z = 0.79 only within %s s of a bounce (1 ms samples);"
                 " max a_z = %s m/s^2; max |y| = %s; min distance to the end edge %s m;"
                 " crossing z = %s"
                 % (mpmath.nstr(low_time, 3), mpmath.nstr(max_az, 6), mpmath.nstr(max_abs_y, 6),
                    mpmath.nstr(min_edge, 6) if min_edge is not None else "?",
                    mpmath.nstr(crossing_z, 8)))
    return failures, notes


KEYS = ["initial_position", "initial_velocity", "angular_velocity",
        "bounce1_time", "bounce1_position", "bounce1_velocity_before", "bounce1_velocity_after",
        "bounce2_time", "bounce2_position", "bounce2_velocity_before", "bounce2_velocity_after",
        "crossing_time", "crossing_position", "crossing_velocity"]


def values(result, key):
    v = result[key]
    return list(v) if isinstance(v, (list, tuple)) else [v]


def fmt(x):
    if x == 0:
        return "0." + "0" * (DIGITS - 1)
    return mpmath.nstr(x, DIGITS, strip_zeros=False)


def lines(result):
    return ["%s %s" % (key, " ".join(fmt(x) for x in values(result, key))) for key in KEYS]


def compute(dps, air):
    with mp.workdps(dps):
        try:
            result, segments = fly(air)
        except SceneError as error:
            return None, [str(error)], []
        failures, notes = check_scene(result, segments)
    return result, failures, notes


def closed_form():
    """The ballistic flight without air, in closed form: parabolas between the bounces."""
    g = mpf(GRAVITY[2])                 # negative
    p, v = vec(P0), vec(V0)
    z_contact = mpf(TABLE_TOP) + mpf(RADIUS)
    e = mpf(RESTITUTION)
    out = {"initial_position": p, "initial_velocity": v, "angular_velocity": vec(W0)}
    t0 = mpf(0)
    for k in (1, 2):
        # z + v_z s + g s^2 / 2 = z_contact, the later root (falling)
        dz = p[2] - z_contact
        s = (-v[2] - mpmath.sqrt(v[2] ** 2 - 2 * g * dz)) / g
        p = [p[0] + v[0] * s, p[1] + v[1] * s, p[2] + v[2] * s + g * s * s / 2]
        before = [v[0], v[1], v[2] + g * s]
        after = [before[0], before[1], -e * before[2]]
        t0 += s
        out["bounce%d_time" % k] = t0
        out["bounce%d_position" % k] = p
        out["bounce%d_velocity_before" % k] = before
        out["bounce%d_velocity_after" % k] = after
        v = after
    s = (mpf(PLANE_X) - p[0]) / v[0]
    if s < 0:
        raise SceneError("without air the ball is past x = %s before its second bounce" % PLANE_X)
    out["crossing_time"] = t0 + s
    out["crossing_position"] = [p[0] + v[0] * s, p[1] + v[1] * s, p[2] + v[2] * s + g * s * s / 2]
    out["crossing_velocity"] = [v[0], v[1], v[2] + g * s]
    return out


def max_difference(a, b, printed_a=False):
    """The largest |a - b| over every number of KEYS (a's printed 20-digit value if printed_a)."""
    worst, where = mpf(0), None
    for key in KEYS:
        for x, y in zip(values(a, key), values(b, key)):
            xa = mpf(fmt(x)) if printed_a else x
            d = abs(xa - y)
            if d > worst:
                worst, where = d, key
    return worst, where


def no_air():
    start = time.time()
    result, failures, notes = compute(DPS, air=False)
    if result is None:
        print("no-air flight FAILS: " + "; ".join(failures), file=sys.stderr)
        return 1
    print("# serve_reference.py --no-air: the same serve with drag and Magnus off "
          "(mpmath odefun, %d digits)" % DPS)
    for line in lines(result):
        print(line)
    with mp.workdps(DPS):
        exact = closed_form()
        print("# closed-form ballistic formulas vs the integrated flight, |difference| per item:")
        worst = mpf(0)
        for key in KEYS:
            d = max(abs(x - y) for x, y in zip(values(result, key), values(exact, key)))
            worst = max(worst, d)
            print("#   %-24s %s" % (key, mpmath.nstr(d, 3)))
        print("# largest difference to the closed form: %s" % mpmath.nstr(worst, 3))
    for n in notes:
        print("# " + n)
    print("# scene checks: " + ("all pass" if not failures else "FAIL: " + "; ".join(failures)))
    print("# %.1f s" % (time.time() - start))
    return 0 if worst < mpf(10) ** (-(DPS - 8)) else 1


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_path = os.path.join(here, "serve_reference.txt")
    start = time.time()
    result, failures, notes = compute(DPS, air=True)
    t_main = time.time() - start
    for n in notes:
        print(n)
    if failures:
        print("scene checks FAIL:\n  " + "\n  ".join(failures), file=sys.stderr)
        return 1
    check, check_failures, _ = compute(CHECK_DPS, air=True)
    if check_failures:
        print("scene checks at %d digits FAIL: %s" % (CHECK_DPS, check_failures), file=sys.stderr)
        return 1
    with mp.workdps(CHECK_DPS):
        integration_error, where_i = max_difference(result, check)
        bound, where_b = max_difference(result, check, printed_a=True)
    print("largest |%d digits - %d digits| before printing: %s (%s)"
          % (DPS, CHECK_DPS, mpmath.nstr(integration_error, 3), where_i))
    print("largest |printed - %d digits|: %s (%s)" % (CHECK_DPS, mpmath.nstr(bound, 3), where_b))
    header = [
        "# serve_reference.py (bench/accuracy/reference): a table-tennis serve with quadratic drag",
        "# and the Magnus force, two bounces on the table top (z = 0.76), then the plane x = %s."
        % PLANE_X,
        "# mpmath odefun (Taylor series) at %d digits, events by findroot; do not edit, rerun:"
        % DPS,
        "#   /usr/bin/python3 bench/accuracy/reference/serve_reference.py",
        "# m = %s kg, r = %s m, A = pi r^2, C_d = %s, C_L = %s, rho = %s kg/m^3, g = (%s) m/s^2,"
        % (MASS, RADIUS, DRAG_COEFFICIENT, LIFT_COEFFICIENT, AIR_DENSITY, ", ".join(GRAVITY)),
        "# e = %s; contact at centre z = %s + r; F_D = -1/2 rho C_d A |v| v,"
        % (RESTITUTION, TABLE_TOP),
        "# F_M = 1/2 rho C_L A |v| (w/|w| x v); spin constant; frictionless bounces,"
        " v_z -> -e v_z.",
        "# reference_error_bound: largest |printed value - 50-digit recomputation| (SI units);",
        "# before rounding to %d digits the %d- and %d-digit runs differ by at most %s."
        % (DIGITS, DPS, CHECK_DPS, mpmath.nstr(integration_error, 3)),
    ]
    body = lines(result) + ["reference_error_bound %s" % fmt(bound)]
    with open(out_path, "w") as out:
        out.write("\n".join(header + body) + "\n")
    print("wrote %s (%.1f s at %d digits, %.1f s in all)"
          % (out_path, t_main, DPS, time.time() - start))
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    if args == ["--no-air"]:
        sys.exit(no_air())
    if args:
        print("usage: serve_reference.py [--no-air]", file=sys.stderr)
        sys.exit(2)
    sys.exit(main())
