#!/usr/bin/env python3
"""The exact answers of the accuracy benchmark's scenes, computed outside the code under test.

Reads the scenes' inputs (scenes.txt, written by `accuracy_benchmark --export-scenes`: every
double exactly, as a C99 hex float) and writes references.txt, which the benchmark reads to
measure every engine (ours and the peers) against the same answers.

How (nothing here calls or copies the C++ code; the physics is the seed's and doc/model.md's):

- every number is taken exactly from its double (mpmath.mpf(float)) and carried in mpmath with
  50 significant digits, so the answers are exact to far below a double's rounding;
- coefficients of restitution: the seed's table (the slide "Coefficients of Restitution of Balls
  Bounced on a Concrete Surface", written out below and checked against the exported ones), a
  material against concrete uses its own coefficient, any other pair the smaller of the two
  (README, "Materials": combine rule min);
- "events" scenes are played event by event: between impacts every body moves on its exact
  parabola (a straight line without gravity); the next impact is the earliest exact root of
  |p_b - p_a| = r_a + r_b (relative motion is a straight line: every body feels the same
  gravity) or of a sphere-plane gap (a quadratic in time); at an impact the seed's combined
  formulas act along the line of impact (immovable bodies: inverse mass 0);
- contacts that touch at one instant (a rack, a cradle) follow doc/model.md's documented model,
  "Simultaneous contacts": in rounds, every touching pair that approaches gets the impulses
  J >= 0 of the joint solve of Newton's restitution (d' = -e d on every contact that receives
  one; a contact whose impulse would pull is dropped, the most negative first, and the rest
  solved again), until no touching pair approaches. Other models of touching contacts exist;
  engines that follow another one differ from this reference by the model too;
- a ball bouncing on a plane under gravity with threshold 0 bounces without end (the bounces
  accumulate at a finite instant); the reference lets it rest once a bounce would rise less than
  1e-30 m (REST_HEIGHT), far below anything a double can measure against metres;
- "conservation" scenes (the gas) get their conserved quantities only: energy (kinetic, plus
  -m g.p with gravity) and momentum from the inputs. A gas's trajectory is chaotic: no finite
  precision reproduces it beyond a few dozen impacts.

Closed forms are checked against the events where they exist (an apex after the k-th bounce is
h e^(2k) above the contact; a drop from h meets the floor at sqrt(2 h / g); the two-ball chain
ends after ceil(pi / atan(sqrt(m / M))) - 1 impacts) and the script stops if they disagree.

Regenerate (scripts/accuracy.sh does this on every run, so a changed scene never meets a stale
reference; the output is checked in so that a change of any answer shows in review):
  accuracy_benchmark --export-scenes bench/accuracy/reference/scenes.txt
  python3 bench/accuracy/reference/make_references.py \
      bench/accuracy/reference/scenes.txt bench/accuracy/reference/references.txt
"""
import math
import sys

import mpmath
from mpmath import mpf

mpmath.mp.dps = 50

SEED = {  # the slide "Coefficients of Restitution of Balls Bounced on a Concrete Surface"
    "range_golf_ball": 0.858, "tennis_ball": 0.712, "billiard_ball": 0.804, "hand_ball": 0.752,
    "wooden_ball": 0.603, "steel_ball_bearing": 0.597, "glass_marble": 0.658,
    "rubber_band_ball": 0.828, "hollow_hard_plastic_ball": 0.688,
}
TOUCH = mpf("1e-12")         # surfaces within this fraction of their contact distance touch
APPROACH = mpf("1e-30")      # m/s: slower approaches (rounding at 50 digits) are none
REST_HEIGHT = mpf("1e-30")   # m: a bounce rising less rests on the plane
MAX_EVENTS = 200000
BOUNCE_FLOOR = 1e-9          # m: the bounces of the long runs counted (rising at least 1 nm)


def vec(values):
    return [mpf(float.fromhex(v)) for v in values]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def add(a, b, k=1):
    return [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]]


class Body:
    def __init__(self, name, material, mass, radius, position, velocity):
        self.name, self.material = name, material
        self.mass = mpf(float.fromhex(mass))
        self.inverse_mass = 0 if mpmath.isinf(self.mass) else 1 / self.mass
        self.radius = mpf(float.fromhex(radius))
        self.position, self.velocity = vec(position), vec(velocity)
        self.start = list(self.position)
        self.resting_on = None  # plane index
        self.impacts = 0


class Scene:
    def __init__(self, name, fields):
        self.name = name
        def after(key, count=1):
            i = fields.index(key)
            return fields[i + 1:i + 1 + count]
        self.duration = mpf(float.fromhex(after("duration")[0]))
        self.reference = after("reference")[0]
        self.threshold = mpf(float.fromhex(after("threshold")[0]))
        self.friction, self.spin = after("friction")[0] == "1", after("spin")[0] == "1"
        self.has_gravity = after("gravity")[0] == "1"
        self.gravity = vec(after("gravity", 4)[1:]) if self.has_gravity else [mpf(0)] * 3
        if self.threshold != 0:
            sys.exit(f"{name}: a restitution threshold is not in this reference")
        self.own = {}       # material -> own coefficient (against concrete)
        self.own_friction = {}  # material -> Coulomb mu against itself
        self.bodies, self.planes, self.spheres, self.boxes = [], [], [], []
        self.obstacle_velocities = {}

    def restitution(self, first, second):
        if first == "concrete":
            return self.own[second]
        if second == "concrete":
            return self.own[first]
        return min(self.own[first], self.own[second])


def read_scenes(path):
    scenes, scene = [], None
    for line in open(path):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        kind = words[0]
        if kind == "scene":
            scene = Scene(words[1], words[2:])
        elif kind == "material":
            own = mpf(float.fromhex(words[2]))
            if words[1] in SEED and own != mpf(SEED[words[1]]):
                sys.exit(f"{scene.name}: {words[1]} has e {float(own)}, the seed's table says "
                         f"{SEED[words[1]]}")
            scene.own[words[1]] = own
            if len(words) > 3:
                scene.own_friction[words[1]] = mpf(float.fromhex(words[3]))
        elif kind == "body":
            scene.bodies.append(Body(words[1], words[2], words[3], words[4], words[5:8],
                                     words[8:11]))
        elif kind == "plane":
            scene.planes.append((words[1], words[2], vec(words[3:6]),
                                 mpf(float.fromhex(words[6]))))
        elif kind == "sphere":
            scene.spheres.append((words[1], words[2], vec(words[3:6]),
                                  mpf(float.fromhex(words[6]))))
        elif kind == "obstacle_velocity":
            scene.obstacle_velocities[words[1]] = vec(words[2:5])
        elif kind == "mesh":  # a floor mesh: its scene's reference needs only the plane
            pass
        elif kind == "box":  # along the axes: centre, size
            scene.boxes.append((words[1], words[2], vec(words[3:6]), vec(words[6:9])))
        elif kind == "end":
            scenes.append(scene)
    return scenes


# --- motion -------------------------------------------------------------------------------------

def acceleration(scene, body):
    if not scene.has_gravity or body.inverse_mass == 0:
        return [mpf(0)] * 3
    g = scene.gravity
    if body.resting_on is not None:  # slides on the plane: gravity's part along it
        n = scene.planes[body.resting_on][2]
        return add(g, n, -dot(g, n))
    return g


def advance(scene, bodies, dt):
    for body in bodies:
        a = acceleration(scene, body)
        body.position = [p + v * dt + a_ * dt * dt / 2 for p, v, a_ in
                         zip(body.position, body.velocity, a)]
        body.velocity = [v + a_ * dt for v, a_ in zip(body.velocity, a)]


def first_root(a, b, c):
    """The entering root tau > 0 of a/2 tau^2 + b tau + c = 0 (c: the gap, b: its rate, a: its
    acceleration), or None."""
    if a == 0:
        return -c / b if b < 0 else None
    disc = b * b - 2 * a * c
    if disc < 0:
        return None
    if a > 0 and b >= 0:
        return None
    tau = (-b - mpmath.sqrt(disc)) / a
    return tau if tau > 0 else None


# --- participants: bodies, then planes, then immovable spheres ----------------------------------

def contact_geometry(scene, i, j):
    """Gap, unit normal (i -> j), contact distance and normal rate d of body i and participant j."""
    body = scene.bodies[i]
    nb = len(scene.bodies)
    if j < nb or j >= nb + len(scene.planes):
        if j < nb:
            other_p, other_v, other_r = scene.bodies[j].position, scene.bodies[j].velocity, \
                scene.bodies[j].radius
        else:
            _, _, other_p, other_r = scene.spheres[j - nb - len(scene.planes)]
            other_v = [mpf(0)] * 3
        s = add(other_p, body.position, -1)
        dist = mpmath.sqrt(dot(s, s))
        n = [x / dist for x in s]
        reach = body.radius + other_r
        d = dot(add(other_v, body.velocity, -1), n)
        return dist - reach, n, reach, d
    _, _, normal, offset = scene.planes[j - nb]
    gap = dot(normal, body.position) - offset - body.radius
    n = [-x for x in normal]  # from the body into the plane
    return gap, n, body.radius, dot(body.velocity, normal)


def participant_velocity(scene, j):
    nb = len(scene.bodies)
    return scene.bodies[j].velocity if j < nb else [mpf(0)] * 3


def inverse_mass(scene, j):
    nb = len(scene.bodies)
    return scene.bodies[j].inverse_mass if j < nb else 0


def material(scene, j):
    nb = len(scene.bodies)
    if j < nb:
        return scene.bodies[j].material
    if j < nb + len(scene.planes):
        return scene.planes[j - nb][1]
    return scene.spheres[j - nb - len(scene.planes)][1]


def pairs(scene):
    nb, total = len(scene.bodies), len(scene.bodies) + len(scene.planes) + len(scene.spheres)
    for i in range(nb):
        for j in range(i + 1, total):
            if inverse_mass(scene, i) == 0 and inverse_mass(scene, j) == 0:
                continue
            yield i, j


def time_to_impact(scene, i, j):
    body = scene.bodies[i]
    nb = len(scene.bodies)
    if nb <= j < nb + len(scene.planes):
        if body.resting_on == j - nb:
            return None
        _, _, normal, offset = scene.planes[j - nb]
        gap = dot(normal, body.position) - offset - body.radius
        return first_root(dot(normal, acceleration(scene, body)), dot(normal, body.velocity), gap)
    if j < nb:
        other = scene.bodies[j]
        rel_a = add(acceleration(scene, other), acceleration(scene, body), -1)
        other_p, other_v, other_r = other.position, other.velocity, other.radius
    else:
        _, _, other_p, other_r = scene.spheres[j - nb - len(scene.planes)]
        other_v = [mpf(0)] * 3
        rel_a = [-x for x in acceleration(scene, body)]
    s, v, reach = add(other_p, body.position, -1), add(other_v, body.velocity, -1), \
        body.radius + other_r
    if any(x != 0 for x in rel_a):
        return accelerated_time_to_impact(s, v, rel_a, reach)
    a, b = dot(v, v), dot(s, v)
    if b >= 0 or a == 0:
        return None
    c = dot(s, s) - reach * reach
    disc = b * b - a * c
    if disc < 0:
        return None
    tau = c / (-b + mpmath.sqrt(disc))
    return tau if tau > 0 else None


def accelerated_time_to_impact(s, v, a, reach):
    """|s + v tau + a tau^2 / 2| = reach (a body at rest on a plane against a falling one): the
    smallest positive real root of the quartic, approaching; None when the motion across `a`
    alone (a straight line) keeps them apart."""
    along = [x / mpmath.sqrt(dot(a, a)) for x in a]
    s_across, v_across = add(s, along, -dot(s, along)), add(v, along, -dot(v, along))
    closest = dot(s_across, s_across)
    if dot(v_across, v_across) > 0:
        tau = max(mpf(0), -dot(s_across, v_across) / dot(v_across, v_across))
        closest = dot(add(s_across, v_across, tau), add(s_across, v_across, tau))
    if closest > reach * reach:
        return None
    coefficients = [dot(a, a) / 4, dot(v, a), dot(v, v) + dot(s, a), 2 * dot(s, v),
                    dot(s, s) - reach * reach]
    roots = mpmath.polyroots(coefficients, maxsteps=200, extraprec=200)
    best = None
    for root in roots:
        if abs(mpmath.im(root)) > mpf("1e-30") or mpmath.re(root) <= 0:
            continue
        tau = mpmath.re(root)
        rate = dot(add(s, add(v, a, tau / 2), tau), add(v, a, tau))
        if rate < 0 and (best is None or tau < best):
            best = tau
    return best


def resolve_instant(scene):
    """Every touching, approaching contact, in rounds (doc/model.md, "Simultaneous contacts").
    Returns the contacts that received an impulse, and the bodies whose velocity changed."""
    impacts, touched = 0, set()
    for _ in range(100000):
        contacts = []
        for i, j in pairs(scene):
            gap, n, reach, d = contact_geometry(scene, i, j)
            if abs(gap) <= TOUCH * reach and d < -APPROACH:
                contacts.append((i, j, n, d, scene.restitution(material(scene, i),
                                                                material(scene, j))))
        if not contacts:
            return impacts, touched
        active = list(range(len(contacts)))
        while True:
            size = len(active)
            matrix = mpmath.matrix(size, size)
            rhs = mpmath.matrix(size, 1)
            for row, k in enumerate(active):
                ik, jk, nk, dk, ek = contacts[k]
                rhs[row] = -(1 + ek) * dk
                for col, l in enumerate(active):
                    il, jl, nl, _, _ = contacts[l]
                    # d_k changes by sum over bodies of w s_ik s_il n_k.n_l J_l (s: +1 for the
                    # second participant of a contact, -1 for the first).
                    coupling = 0
                    for body, s_k in ((ik, -1), (jk, 1)):
                        for other, s_l in ((il, -1), (jl, 1)):
                            if body == other:
                                coupling += inverse_mass(scene, body) * s_k * s_l
                    matrix[row, col] = coupling * dot(nk, nl)
            impulses = mpmath.lu_solve(matrix, rhs)
            worst = min(range(size), key=lambda r: impulses[r])
            if impulses[worst] >= 0:
                break
            del active[worst]
        for row, k in enumerate(active):
            i, j, n, _, _ = contacts[k]
            impulse = impulses[row]
            if impulse <= 0:
                continue
            impacts += 1
            for body, sign in ((i, -1), (j, 1)):
                if body < len(scene.bodies) and scene.bodies[body].inverse_mass != 0:
                    b = scene.bodies[body]
                    b.velocity = add(b.velocity, n, sign * impulse * b.inverse_mass)
                    touched.add(body)
    sys.exit(f"{scene.name}: endless rounds")


def settle(scene, touched):
    """A body that bounced off a plane too low to leave it rests on it (gravity only)."""
    if not scene.has_gravity:
        return
    for i in touched:
        body = scene.bodies[i]
        for p, (_, _, normal, offset) in enumerate(scene.planes):
            gap = dot(normal, body.position) - offset - body.radius
            toward = dot(normal, scene.gravity)
            if abs(gap) > TOUCH * body.radius or toward >= 0:
                continue
            rate = dot(normal, body.velocity)
            if rate <= 0 or rate * rate / (-2 * toward) < REST_HEIGHT:
                body.velocity = add(body.velocity, normal, -rate)
                body.resting_on = p


def height(scene, body):
    """Height against gravity (m), and the speed along it."""
    g = scene.gravity
    norm = mpmath.sqrt(dot(g, g))
    up = [-x / norm for x in g]
    return dot(up, body.position), dot(up, body.velocity), norm


def play(scene, out):
    """The event-driven motion of `scene` up to its duration; writes its answers."""
    t, events, impacts = mpf(0), 0, 0
    first = last = None
    first_of = {}
    apexes = []
    flights = {i: 0 for i in range(len(scene.bodies))}
    while True:
        soonest = None
        for i, j in pairs(scene):
            tau = time_to_impact(scene, i, j)
            if tau is not None and (soonest is None or tau < soonest):
                soonest = tau
        if soonest is None or t + soonest > scene.duration:
            advance(scene, scene.bodies, scene.duration - t)
            break
        advance(scene, scene.bodies, soonest)
        t += soonest
        count, touched = resolve_instant(scene)
        events += 1
        if events > MAX_EVENTS:
            sys.exit(f"{scene.name}: more than {MAX_EVENTS} instants of impact")
        if count == 0:
            continue  # a grazing root: nothing approached
        impacts += count
        last = t
        if first is None:
            first = t
        for i in sorted(touched):
            first_of.setdefault(i, t)
        settle(scene, touched)
        if scene.has_gravity:
            for i in sorted(touched):
                body = scene.bodies[i]
                flights[i] += 1
                z, up_speed, g = height(scene, body)
                if body.resting_on is None and up_speed > 0:
                    apexes.append((i, flights[i], z + up_speed * up_speed / (2 * g)))
    out.append(f"{scene.name} impacts {impacts}")
    out.append(f"{scene.name} instants {events}")
    if first is not None:
        out.append(f"{scene.name} first_impact {num(first)}")
        out.append(f"{scene.name} last_impact {num(last)}")
    for i in sorted(first_of):
        out.append(f"{scene.name} first_impact_of {i} {num(first_of[i])}")
    for i, k, z in apexes:
        out.append(f"{scene.name} apex {i} {k} {num(z)}")
    for i, body in enumerate(scene.bodies):
        out.append(f"{scene.name} final {i} " + " ".join(num(x) for x in body.position) + " " +
                   " ".join(num(x) for x in body.velocity))
    return {"impacts": impacts, "apexes": apexes, "last": last, "first_of": first_of}


def conserved(scene, out):
    energy = sum(body.mass * dot(body.velocity, body.velocity) / 2 -
                 body.mass * dot(scene.gravity, body.position) for body in scene.bodies
                 if body.inverse_mass != 0)
    momentum = [sum(body.mass * body.velocity[k] for body in scene.bodies
                    if body.inverse_mass != 0) for k in range(3)]
    out.append(f"{scene.name} energy0 {num(energy)}")
    out.append(f"{scene.name} momentum0 " + " ".join(num(x) for x in momentum))


def num(x):
    return repr(float(x))


def check(condition, message):
    if not condition:
        sys.exit("closed form and events disagree: " + message)


def closed_forms(scene, result, out):
    """The long runs' closed forms, and the events checked against them."""
    if scene.name.startswith("bounce_") or scene.name == "drop_test":
        g = -scene.gravity[2]
        for i, body in enumerate(scene.bodies):
            e = scene.restitution(body.material, "concrete")
            h = body.start[2] - body.radius
            found = [(k, z) for (b, k, z) in result["apexes"] if b == i]
            for k, z in found:
                rise = h * e ** (2 * k)
                check(abs((z - body.radius) - rise) <= mpf("1e-40") * h,
                      f"{scene.name} body {i} apex {k}")
            drop = mpmath.sqrt(2 * h / g)
            check(abs(result["first_of"][i] - drop) < mpf("1e-40"),
                  f"{scene.name} body {i} first impact")
            if scene.name.startswith("bounce_"):
                # The apex of each of the first 1,000 bounces, h e^(2k) above the contact, as
                # long as it rises at least 1 nm (e < 1 bounces endlessly, ever lower).
                count = 0
                for k in range(1, 1001):
                    rise = h * e ** (2 * k)
                    if rise < BOUNCE_FLOOR:
                        break
                    count = k
                    out.append(f"{scene.name} bounce {k} {num(rise)}")
                out.append(f"{scene.name} bounces_above_1nm {count}")
                out.append(f"{scene.name} drop_height {num(h)}")
    if scene.name.startswith("chain_"):
        light, heavy = scene.bodies
        theta = mpmath.atan(mpmath.sqrt(light.mass / heavy.mass))
        expected = int(mpmath.ceil(mpmath.pi / theta)) - 1
        impacts, last = result["impacts"], result["last"]
        check(impacts == expected, f"{scene.name}: {impacts} impacts, Galperin: {expected}")
        check(last is not None and last < scene.duration - mpf("0.3"),
              f"{scene.name}: the last impact at {last} is too close to the end")


# --- lasting contact: closed forms of where the motion goes -------------------------------------

def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def bisect(f, low, high, steps=200):
    """The root of f in [low, high], f(low) and f(high) of opposite signs."""
    f_low = f(low)
    check(f_low * f(high) < 0, "no sign change to bisect")
    for _ in range(steps):
        middle = (low + high) / 2
        if (f(middle) < 0) == (f_low < 0):
            low = middle
        else:
            high = middle
    return (low + high) / 2


def potential(scene, body, position):
    return -body.mass * dot(scene.gravity, position)


def ball_corner(scene, out):
    """At rest in the corner of the two planes: touching both, not moved along their line (gravity
    has no part along it)."""
    (body,) = scene.bodies
    (_, _, n1, o1), (_, _, n2, o2) = scene.planes
    line = cross(n1, n2)
    check(abs(dot(line, scene.gravity)) < mpf("1e-40"), f"{scene.name}: gravity along the corner")
    matrix = mpmath.matrix([n1, n2, line])
    rhs = mpmath.matrix([o1 + body.radius, o2 + body.radius, dot(line, body.position)])
    rest = mpmath.lu_solve(matrix, rhs)
    rest = [rest[0], rest[1], rest[2]]
    out.append(f"{scene.name} rest 0 " + " ".join(num(x) for x in rest))
    out.append(f"{scene.name} energy_rest {num(potential(scene, body, rest))}")
    # The slide to the wall (for the record): d along the incline at g sin(theta), or 5/7 of it
    # rolling (a solid ball, I = 2/5 m r^2).
    g = mpmath.sqrt(dot(scene.gravity, scene.gravity))
    sin_incline = mpmath.sqrt(1 - n1[2] ** 2)
    downhill = [n1[2], 0, -n1[0]]  # along the incline, in the x-z plane
    gap = dot(n2, body.position) - o2 - body.radius  # to the wall, across it
    slide = -gap / dot(n2, downhill)
    a = g * sin_incline * (mpf(5) / 7 if scene.friction and scene.spin else 1)
    out.append(f"{scene.name} wall_arrival {num(mpmath.sqrt(2 * slide / a))}")


def ball_off_sphere(scene, out):
    """The angle at which a ball nudged on top of a fixed sphere leaves it. With v^2 = w(theta)
    (theta from the top, rho = R + r, n = g cos(theta) - w / rho the normal force per mass):
    - frictionless: w = v0^2 + 2 g rho (1 - cos(theta)); it leaves where n = 0:
      cos(theta) = (2 + v0^2 / g rho) / 3;
    - friction mu and spin (a solid ball): it starts slipping (no spin), friction mu n backwards
      on the centre and spinning it up (I w' = mu n m r): dw/dtheta - 2 mu w =
      2 g rho (sin - mu cos), solved in closed form; it rolls from where v = r omega (omega's
      integral, by quadrature), w = w1 + (10/7) g rho (cos(theta1) - cos(theta)), as long as the
      friction rolling needs, (2/7) g sin(theta), is at most mu n; then slips again (the same
      linear equation) until n = 0. Without the limit of mu (rolling to the end, v0 -> 0):
      cos(theta) = 10/17."""
    (body,) = scene.bodies
    (_, _, centre, big) = scene.spheres[0]
    g = mpmath.sqrt(dot(scene.gravity, scene.gravity))
    rho, r = big + body.radius, body.radius
    v0_squared = dot(body.velocity, body.velocity)
    top = add(body.position, centre, -1)
    # On the top, at the contact distance, to the doubles' rounding of the inputs.
    check(abs(dot(top, scene.gravity) / (rho * g) + 1) < mpf("1e-15"), "not on the top")
    if not scene.friction:
        leave = (2 + v0_squared / (g * rho)) / 3
        # The same from w's root, as a check.
        root = bisect(lambda t: g * mpmath.cos(t) - (v0_squared + 2 * g * rho *
                                                      (1 - mpmath.cos(t))) / rho, 0, mpmath.pi / 2)
        check(abs(mpmath.cos(root) - leave) < mpf("1e-40"), f"{scene.name}: leaving angle")
        out.append(f"{scene.name} leave_cos {num(leave)}")
        return
    mu = scene.own_friction[body.material]
    a = -2 * mu

    def slipping(theta_s, w_s):
        def integral(t):  # of e^(a t) (sin t - mu cos t)
            return mpmath.exp(a * t) * ((a * mpmath.sin(t) - mpmath.cos(t)) -
                                        mu * (a * mpmath.cos(t) + mpmath.sin(t))) / (a * a + 1)
        return lambda t: mpmath.exp(-a * t) * (w_s * mpmath.exp(a * theta_s) +
                                               2 * g * rho * (integral(t) - integral(theta_s)))

    def normal(t, w):
        return g * mpmath.cos(t) - w(t) / rho

    w_top = slipping(mpf(0), v0_squared)
    check(abs(mpmath.diff(w_top, mpf("0.1")) + a * w_top(mpf("0.1")) -
              2 * g * rho * (mpmath.sin(mpf("0.1")) - mu * mpmath.cos(mpf("0.1")))) < mpf("1e-25"),
          "the slipping solution")

    def spin(t):  # omega(t), from 0 at the top: d omega / d theta = (5/2) mu n rho / (r v)
        return mpmath.quad(lambda p: mpf(5) / 2 * mu * normal(p, w_top) * rho /
                           (r * mpmath.sqrt(w_top(p))), [0, t])

    # Rolling from theta1: the slip v - r omega reaches 0 (within a small angle of the top).
    high = mpf("1e-6")
    while mpmath.sqrt(w_top(high)) - r * spin(high) > 0:
        high *= 2
    theta1 = bisect(lambda t: mpmath.sqrt(w_top(t)) - r * spin(t), mpf(0), high, 120)
    w1 = w_top(theta1)

    def w_rolling(t):
        return w1 + mpf(10) / 7 * g * rho * (mpmath.cos(theta1) - mpmath.cos(t))

    theta2 = bisect(lambda t: mu * normal(t, w_rolling) - mpf(2) / 7 * g * mpmath.sin(t), theta1,
                    mpmath.pi / 2)
    w_slip = slipping(theta2, w_rolling(theta2))
    leave_angle = bisect(lambda t: normal(t, w_slip), theta2, mpmath.pi / 2)
    out.append(f"{scene.name} leave_cos {num(mpmath.cos(leave_angle))}")
    out.append(f"{scene.name} rolling_from {num(theta1)}")
    out.append(f"{scene.name} slipping_from_cos {num(mpmath.cos(theta2))}")
    out.append(f"{scene.name} leave_cos_rolling_limit {num(mpf(10) / 17)}")


def ball_off_edge(scene, out):
    """A ball sliding frictionless along a box's top face off its edge (R = 0 of the ball off a
    sphere): with v^2 = v0^2 + 2 g r (1 - cos(theta)) it leaves where g cos(theta) = v^2 / r,
    cos(theta) = (2 + v0^2 / g r) / 3, and flies on with the horizontal velocity
    v cos(theta) = sqrt(g r) cos(theta)^(3/2)."""
    (body,) = scene.bodies
    (_, _, centre, size) = scene.boxes[0]
    g = mpmath.sqrt(dot(scene.gravity, scene.gravity))
    r = body.radius
    top = centre[2] + size[2] / 2
    check(abs(body.position[2] - top - r) < mpf("1e-15"), f"{scene.name}: not on the top")
    check(body.position[0] < centre[0] + size[0] / 2, f"{scene.name}: not before the edge")
    check(body.velocity[1] == 0 and body.velocity[2] == 0, f"{scene.name}: not along x")
    v0_squared = dot(body.velocity, body.velocity)
    leave = (2 + v0_squared / (g * r)) / 3
    out.append(f"{scene.name} leave_cos {num(leave)}")
    out.append(f"{scene.name} flight_vx {num(mpmath.sqrt(g * r) * leave ** mpf(1.5))}")


def ball_on_mesh_floor(scene, out):
    """A ball sliding frictionless across a flat floor mesh at z = 0 as across the plane: at its
    height r, at its velocity."""
    (body,) = scene.bodies
    check(body.position[2] == body.radius and body.velocity[2] == 0,
          f"{scene.name}: not sliding on z = 0")
    out.append(f"{scene.name} height {num(body.radius)}")
    out.append(f"{scene.name} velocity " + " ".join(num(x) for x in body.velocity))


def ball_off_moving_paddle(scene, out):
    """A ball flying along x into a paddle (a box) moving along x: it meets the paddle's face
    when the gap closes, gap / (v - v_p), and leaves at v_p + e (v_p - v)."""
    (body,) = scene.bodies
    (name, material, centre, size) = scene.boxes[0]
    v_p = scene.obstacle_velocities[name][0]
    v = body.velocity[0]
    e = scene.restitution(body.material, material)
    gap = centre[0] - size[0] / 2 - body.position[0] - body.radius
    check(gap > 0 and v > v_p, f"{scene.name}: no approach")
    out.append(f"{scene.name} impact_time {num(gap / (v - v_p))}")
    out.append(f"{scene.name} velocity_after {num(v_p + e * (v_p - v))}")


def lasting(scene, out):
    """The closed forms of the lasting-contact scenes (where they come to rest, or leave)."""
    base = scene.name.split("+")[0]
    if base == "ball_corner":
        ball_corner(scene, out)
    elif base == "ball_off_sphere":
        ball_off_sphere(scene, out)
    elif base == "ball_off_edge":
        ball_off_edge(scene, out)
    elif base == "ball_on_mesh_floor":
        ball_on_mesh_floor(scene, out)
    elif base == "ball_off_moving_paddle":
        ball_off_moving_paddle(scene, out)
    elif base == "ball_stack":
        # At rest where they are: each centre on the one below (r, 3r, 5r): the inputs.
        for i, body in enumerate(scene.bodies):
            check(abs(body.position[2] - (2 * i + 1) * body.radius) < mpf("1e-15"),
                  f"{scene.name}: ball {i} not at {2 * i + 1} r")
            out.append(f"{scene.name} rest {i} " + " ".join(num(x) for x in body.position))
    # the pile: its conserved energy only (at rest, its kinetic energy is 0)


def main():
    scenes_path, out_path = sys.argv[1], sys.argv[2]
    out = ["# The exact answers of bench/accuracy's scenes, by make_references.py (mpmath, 50 digits)",
           "# from scenes.txt; do not edit. Rows: SCENE KEY VALUES..."]
    for scene in read_scenes(scenes_path):
        if scene.reference == "lasting":
            conserved(scene, out)
            lasting(scene, out)
            continue
        if scene.friction or scene.spin:
            out.append(f"# {scene.name}: friction and spin are not in this reference")
            continue
        conserved(scene, out)
        if scene.reference == "conservation":
            continue
        closed_forms(scene, play(scene, out), out)
    with open(out_path, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
