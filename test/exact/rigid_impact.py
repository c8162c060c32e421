#!/usr/bin/env python3
"""One impact of two rigid bodies with rotation, for test/core/test_rigid_impact.cpp.

Derived here without the C++ code under test, in rationals (fractions) where the answer is
rational and in mpmath at 50 digits where a square root enters.

K is the contact's inverse effective mass (Mirtich 1996): K = (w_a + w_b) 1 - [r_a]x Ia^-1 [r_a]x
- [r_b]x Ib^-1 [r_b]x. An impulse P on b (-P on a) at the contact changes the relative velocity
of the contact points by K P, and the kinetic energy by dE = P.u0 + P.K.P / 2.

1. The energy search. Two readings of Chatterjee and Ruina's law (J. Appl. Mech. 65:939, 1998)
   with e_t = 0, over random K (random inertia tensors, lever arms, masses), u0, e in [0, 1],
   mu >= 0, each impulse's energy change exact (given the cone's projection factor, whose
   square root is taken in mpmath and then held as a rational):
   (a) P_I = K^-1 (-u0) split along n: P^ = (1 + e) P_I,n n + (1 + e_t) P_I,t, its tangential
       part scaled onto the cone. It GAINS energy (the search finds cases; one is printed),
       since K couples n and t.
   (b) the paper's: P_I = (-u_n / n.K.n) n (frictionless, plastic), P_II = K^-1 (-u0) (sticking,
       plastic), P^ = (1 + e) P_I + (1 + e_t) (P_II - P_I); outside the cone
       P = (1 + e) P_I + kappa (P_II - P_I), kappa putting P on the cone. Never gains energy: with
       D = P_II - P_I, n.K.D = 0, so dE = -(1 - e^2) P_I.K.P_I / 2 - kappa (2 - kappa) D.K.D / 2,
       and 0 <= kappa <= 1 + e_t. The search finds no gain (the largest dE / E printed, <= 0).
2. A box struck at a corner, frictionless: a box of edges (1, 2, 3) m and 6 kg, turned by a
   rational rotation, its corner striking a still floor (n = z). Its velocity and angular
   velocity after, exact.
3. A rod falling on its end (Kane and Levinson's example of Newton's law gaining energy with
   friction; Stronge, J. Appl. Mech. 58:1049, 1991): a thin box (0.2 x 2 x 0.2 m, 1 kg) tilted
   by theta (sin 5/13, cos 12/13) about z, falling at 1 m/s and drifting at -0.1 m/s, not
   turning, striking a still floor (n = y) with its lower end's centre. Newton's algebraic law with Coulomb friction along
   the initial slip (u_n' = -e u_n, P_t = -mu P_n s0) gains energy; the law of (b) loses it.

Prints each number as the shortest double that reads back (repr), for the test to compare with.
"""
import random
from fractions import Fraction as F

import mpmath

mpmath.mp.dps = 50


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def add(a, b):
    return [x + y for x, y in zip(a, b)]


def scale(s, a):
    return [s * x for x in a]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def matvec(m, v):
    return [dot(row, v) for row in m]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(m):
    return [[m[j][i] for j in range(3)] for i in range(3)]


def inverse(m):
    """The inverse of a 3 x 3 matrix by its adjugate (exact in rationals)."""
    c = [[m[(i + 1) % 3][(j + 1) % 3] * m[(i + 2) % 3][(j + 2) % 3] -
          m[(i + 1) % 3][(j + 2) % 3] * m[(i + 2) % 3][(j + 1) % 3] for i in range(3)]
         for j in range(3)]
    det = sum(m[0][k] * c[k][0] for k in range(3))
    return [[c[i][j] / det for j in range(3)] for i in range(3)]


def skew(r):
    return [[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]]


def side_term(inverse_inertia, r):
    s = skew(r)
    m = matmul(matmul(s, inverse_inertia), s)
    return [[-x for x in row] for row in m]


def collision_matrix(wa, ia, ra, wb, ib, rb):
    ta, tb = side_term(ia, ra), side_term(ib, rb)
    return [[(wa + wb if i == j else 0) + ta[i][j] + tb[i][j] for j in range(3)]
            for i in range(3)]


def energy_change(k, u0, p):
    return dot(p, u0) + dot(p, matvec(k, p)) / 2


def rotation(q):
    """The rotation of the rational quaternion q (w, x, y, z), rational itself."""
    w, x, y, z = q
    s = w * w + x * x + y * y + z * z
    return [[(w * w + x * x - y * y - z * z) / s, 2 * (x * y - w * z) / s, 2 * (x * z + w * y) / s],
            [2 * (x * y + w * z) / s, (w * w - x * x + y * y - z * z) / s, 2 * (y * z - w * x) / s],
            [2 * (x * z - w * y) / s, 2 * (y * z + w * x) / s, (w * w - x * x - y * y + z * z) / s]]


def norm_as_fraction(v):
    """|v|, from mpmath at 50 digits, as a rational."""
    return F(str(mpmath.sqrt(mpmath.mpf(dot(v, v).numerator) / dot(v, v).denominator)))


def tangential(v, n):
    return sub(v, scale(dot(v, n), n))


def law_split_sticking(k, u0, n, e, mu):
    """Reading (a): the sticking impulse split along n, its normal part times 1 + e."""
    pi = matvec(inverse(k), scale(-1, u0))
    pn, pt = dot(pi, n), tangential(pi, n)
    normal = (1 + e) * pn
    t = norm_as_fraction(pt) if any(pt) else F(0)
    if t > mu * normal:
        pt = scale(mu * normal / t, pt)
    return add(scale(normal, n), pt)


def law_chatterjee_ruina(k, u0, n, e, mu, et=F(0)):
    """Reading (b), the paper's; returns the impulse and kappa."""
    un = dot(u0, n)
    p1 = scale(-un / dot(n, matvec(k, n)), n)
    p2 = matvec(inverse(k), scale(-1, u0))
    d = sub(p2, p1)
    hat = add(scale(1 + e, p1), scale(1 + et, d))
    dt = tangential(d, n)
    t = norm_as_fraction(dt) if any(dt) else F(0)
    if t > mu * dot(hat, n) and t > 0:
        kappa = mu * (1 + e) * dot(p1, n) / (t - mu * dot(d, n))
        return add(scale(1 + e, p1), scale(kappa, d)), kappa
    return hat, 1 + et


def random_fraction(rng, low, high, steps=1000):
    return F(low) + F(rng.randrange(steps + 1), steps) * (F(high) - F(low))


def random_inverse_inertia(rng):
    """A random body's inverse inertia in a random orientation: principal moments satisfying the
    triangle inequality (from random second moments c_i >= 0: I_1 = c_2 + c_3, ...)."""
    c = [random_fraction(rng, F(1, 100), 2) for _ in range(3)]
    principal = [[F(0)] * 3 for _ in range(3)]
    moments = [c[1] + c[2], c[0] + c[2], c[0] + c[1]]
    for i in range(3):
        principal[i][i] = 1 / moments[i]
    q = [F(rng.randrange(-9, 10), 1) for _ in range(4)]
    if not any(q):
        q[0] = F(1)
    r = rotation(q)
    return matmul(matmul(r, principal), transpose(r)), F(1)


def random_vector(rng, size):
    return [random_fraction(rng, -size, size) for _ in range(3)]


def energy_search(count, seed):
    rng = random.Random(seed)
    n = [F(0), F(0), F(1)]
    worst = {"split": (F(-1), None), "paper": (F(-1), None)}
    gains = 0
    for _ in range(count):
        ia, _ = random_inverse_inertia(rng)
        ib, _ = random_inverse_inertia(rng)
        wa = random_fraction(rng, 0, 2) if rng.random() < 0.7 else F(0)
        wb = random_fraction(rng, F(1, 10), 2)
        if wa == 0:
            ia = [[F(0)] * 3 for _ in range(3)]
        ra, rb = random_vector(rng, 1), random_vector(rng, 1)
        k = collision_matrix(wa, ia, ra, wb, ib, rb)
        u0 = random_vector(rng, 1)
        u0[2] = -abs(u0[2]) - F(1, 1000)
        e = random_fraction(rng, 0, 1)
        mu = random_fraction(rng, 0, 2)
        if rng.random() < 0.2:
            mu = F(1000)  # inside the cone
        # the kinetic energy available in the contact's frame: u0.K^-1.u0 / 2 (the sticking
        # impulse's loss), which bounds every loss; gains are measured against it.
        scale_energy = dot(u0, matvec(inverse(k), u0)) / 2
        for name, law in (("split", law_split_sticking), ("paper", law_chatterjee_ruina)):
            if name == "split" and dot(matvec(inverse(k), u0), n) > 0:
                continue  # its normal impulse would pull: reading (a) is undefined there
            p = law(k, u0, n, e, mu)
            if name == "paper":
                p, kappa = p
                assert 0 <= kappa <= 1
                assert dot(add(u0, matvec(k, p)), n) == -e * dot(u0, n)  # Newton's along n
            relative = energy_change(k, u0, p) / scale_energy
            if name == "split" and relative > 0:
                gains += 1
            if relative > worst[name][0]:
                worst[name] = (relative, (k, u0, e, mu))
    return worst, gains


def box_struck_at_a_corner():
    mass = F(6)
    edges = [F(1), F(2), F(3)]
    principal_inertia = [mass / 12 * (edges[1] ** 2 + edges[2] ** 2),
                         mass / 12 * (edges[0] ** 2 + edges[2] ** 2),
                         mass / 12 * (edges[0] ** 2 + edges[1] ** 2)]
    r = rotation([F(2), F(1), F(-1), F(1)])  # a rational turn
    inverse_body = [[F(0)] * 3 for _ in range(3)]
    for i in range(3):
        inverse_body[i][i] = 1 / principal_inertia[i]
    inverse_world = matmul(matmul(r, inverse_body), transpose(r))
    corner = matvec(r, [-edges[0] / 2, -edges[1] / 2, -edges[2] / 2])
    v = [F(1, 2), F(-1, 4), F(-3)]
    w = [F(1), F(-2), F(1, 2)]
    n = [F(0), F(0), F(1)]
    e = F(1, 2)
    k = collision_matrix(F(0), [[F(0)] * 3] * 3, [F(0)] * 3, 1 / mass, inverse_world, corner)
    u0 = add(v, cross(w, corner))
    nkn = dot(n, matvec(k, n))
    impulse = -(1 + e) * dot(u0, n) / nkn
    v_after = add(v, scale(impulse / mass, n))
    w_after = add(w, matvec(inverse_world, cross(corner, scale(impulse, n))))
    lost = (1 - e * e) * dot(u0, n) ** 2 / nkn / 2
    return {"rotation": r, "inverse_inertia": inverse_world, "corner": corner, "v": v, "w": w,
            "e": e, "impulse": impulse, "v_after": v_after, "w_after": w_after,
            "energy_lost": lost}


def rod_on_its_end():
    mass = F(1)
    width, length = F(1, 5), F(2)
    izz = mass / 12 * (length ** 2 + width ** 2)
    ixx = izz  # about the box's x (across), in its own frame
    iyy = mass / 12 * (2 * width ** 2)  # about its long axis
    sin, cos = F(5, 13), F(12, 13)
    r = [[cos, -sin, F(0)], [sin, cos, F(0)], [F(0), F(0), F(1)]]  # about z by theta
    inverse_world = matmul(matmul(r, [[1 / ixx, 0, 0], [0, 1 / iyy, 0], [0, 0, 1 / izz]]),
                           transpose(r))
    end = matvec(r, [F(0), -length / 2, F(0)])  # the lower end's centre
    v = [F(-1, 10), F(-1), F(0)]
    w = [F(0), F(0), F(0)]
    n = [F(0), F(1), F(0)]
    e, mu = F(1), F(1, 2)
    k = collision_matrix(F(0), [[F(0)] * 3] * 3, [F(0)] * 3, 1 / mass, inverse_world, end)
    u0 = add(v, cross(w, end))
    slip = tangential(u0, n)
    # Newton's algebraic law with Coulomb friction along the initial slip s0 (sliding):
    # P = P_n (n - mu s0), P_n from u_n' = -e u_n.
    s0 = scale(1 / abs(slip[0]), slip)
    direction = sub(n, scale(mu, s0))
    pn = -(1 + e) * dot(u0, n) / dot(n, matvec(k, direction))
    newton = scale(pn, direction)
    newton_gain = energy_change(k, u0, newton)
    ours, kappa = law_chatterjee_ruina(k, u0, n, e, mu)
    ours_change = energy_change(k, u0, ours)
    return {"inverse_inertia": inverse_world, "end": end, "v": v, "w": w, "e": e, "mu": mu,
            "u0": u0, "newton_impulse": newton, "newton_energy_change": newton_gain,
            "newton_slip_after": tangential(add(u0, matvec(k, newton)), n),
            "energy_before": (dot(v, v) * mass + dot(w, matvec(inverse(inverse_world), w))) / 2,
            "ours": ours, "kappa": kappa, "ours_energy_change": ours_change,
            "v_after": add(v, scale(1 / mass, ours)),
            "w_after": add(w, matvec(inverse_world, cross(end, ours)))}


def show(name, value):
    if isinstance(value, list):
        if value and isinstance(value[0], list):
            for i, row in enumerate(value):
                show(f"{name}[{i}]", row)
            return
        print(f"{name} = ({', '.join(repr(float(x)) for x in value)})  exact {value}")
    else:
        print(f"{name} = {float(value)!r}  exact {value}")


if __name__ == "__main__":
    worst, gains = energy_search(3000, 42)
    print(f"(a) split sticking impulse: {gains} of 3000 gain energy, the most "
          f"{float(worst['split'][0])!r} of u0.K^-1.u0 / 2")
    k, u0, e, mu = worst["split"][1]
    show("  K", k)
    show("  u0", u0)
    show("  e", e)
    show("  mu", mu)
    print(f"(b) the paper's law: the largest dE / (u0.K^-1.u0 / 2) {float(worst['paper'][0])!r}")
    print("box struck at a corner")
    for key, value in box_struck_at_a_corner().items():
        show("  " + key, value)
    print("rod on its end")
    for key, value in rod_on_its_end().items():
        show("  " + key, value)
