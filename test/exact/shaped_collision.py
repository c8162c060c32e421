#!/usr/bin/env python3
"""Exact rational references for test/core/test_shaped_collision.cpp (and the compute_collision
rostest's box corner): one frictionless impact of two rigid bodies, Newton's e along the normal
with the effective mass, worked out with fractions and full matrices (not the hand shortcuts of
the test's comments, which it checks):

    n.K.n = 1/m_a + 1/m_b + (r_a x n).I_a^-1 (r_a x n) + (r_b x n).I_b^-1 (r_b x n),
    j = (1 + e) d / n.K.n, v' = v -/+ j n / m, w' = w -/+ I^-1 (r x j n),

and the energy the bodies lose, from their kinetic energies before and after.

Run: python3 test/exact/shaped_collision.py
"""
from fractions import Fraction as F


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def matvec(m, v):
    return [dot(row, v) for row in m]


def transpose(m):
    return [list(col) for col in zip(*m)]


def matmul(a, b):
    bt = transpose(b)
    return [[dot(row, col) for col in bt] for row in a]


def diag(d):
    return [[d[i] if i == j else F(0) for j in range(3)] for i in range(3)]


def impact(m_b, inv_inertia_b, r_b, n, v_a, v_b, w_b, e, m_a=None):
    """a a point (or a ball that does not turn) of mass m_a (None: immovable), b a rigid body."""
    inv_a = F(0) if m_a is None else 1 / m_a
    rn = cross(r_b, n)
    k = inv_a + 1 / m_b + dot(rn, matvec(inv_inertia_b, rn))
    u = [v_b[i] + cross(w_b, r_b)[i] - v_a[i] for i in range(3)]
    d = -dot(u, n)
    j = (1 + e) * d / k
    v_a2 = [v_a[i] - j * n[i] * inv_a for i in range(3)]
    v_b2 = [v_b[i] + j * n[i] / m_b for i in range(3)]
    w_b2 = [w_b[i] + x for i, x in enumerate(matvec(inv_inertia_b, [j * c for c in rn]))]
    return k, d, j, v_a2, v_b2, w_b2


def energy(m, inertia, v, w):
    return F(1, 2) * m * dot(v, v) + F(1, 2) * dot(w, matvec(inertia, w))


def box_corner():
    # A 12 kg box of edges (1, 2, 3), not turned, struck at its corner (1/2, 1, 3/2) by a 1 kg
    # ball moving at -(2, 3, 6) along n = -(2, 3, 6)/7 (ball a -> box b), e = 1/2.
    m = F(12)
    a, b, c = F(1), F(2), F(3)
    inertia = diag([m / 12 * (b * b + c * c), m / 12 * (a * a + c * c), m / 12 * (a * a + b * b)])
    assert inertia == diag([F(13), F(10), F(5)])
    inv = diag([1 / inertia[i][i] for i in range(3)])
    n = [F(-2, 7), F(-3, 7), F(-6, 7)]
    r = [F(1, 2), F(1), F(3, 2)]
    v_a = [F(-2), F(-3), F(-6)]
    e = F(1, 2)
    k, d, j, v_a2, v_b2, w_b2 = impact(m, inv, r, n, v_a, [F(0)] * 3, [F(0)] * 3, e, m_a=F(1))
    assert k == F(1) + F(1, 12) + F(9, 196) / 13 + F(1, 196) / 5 == F(41579, 38220)
    assert d == 7 and j == F(21, 2) / k
    assert w_b2 == [j * F(-3, 182), F(0), j * F(1, 70)]
    lost = energy(F(1), diag([F(0)] * 3), v_a, [F(0)] * 3) - (
        energy(F(1), diag([F(0)] * 3), v_a2, [F(0)] * 3) + energy(m, inertia, v_b2, w_b2))
    assert lost == (1 - e * e) * d * d / (2 * k)
    print("box corner: n.K.n", k, "j", j, "=", float(j))
    print("  v_a'", [float(x) for x in v_a2], "v_b'", [float(x) for x in v_b2])
    print("  w_b'", [float(x) for x in w_b2], "lost", float(lost))


def rod_on_its_end():
    # A 2 kg rod (ixx = iyy = 1/6, izz = 1e-4) tilted by theta about x (sin 3/5, cos 4/5),
    # struck at r = (0, 3/10, -41/100) from its centre along n = +z by the immovable ground,
    # falling at 3 m/s, e = 1/2.
    m = F(2)
    body = diag([F(1, 6), F(1, 6), F(1, 10000)])
    s, c = F(3, 5), F(4, 5)
    rot = [[F(1), F(0), F(0)], [F(0), c, -s], [F(0), s, c]]
    world = matmul(matmul(rot, body), transpose(rot))
    inv_body = diag([1 / body[i][i] for i in range(3)])
    inv = matmul(matmul(rot, inv_body), transpose(rot))
    r = [F(0), F(3, 10), F(-41, 100)]
    # the lever arm is the capsule's lowest point: its segment's lower end R (0, 0, -1/2) and
    # the radius 1/100 straight down
    assert r == [matvec(rot, [F(0), F(0), F(-1, 2)])[i] + [F(0), F(0), F(-1, 100)][i]
                 for i in range(3)]
    n = [F(0), F(0), F(1)]
    v_b = [F(0), F(0), F(-3)]
    e = F(1, 2)
    k, d, j, _, v_b2, w_b2 = impact(m, inv, r, n, [F(0)] * 3, v_b, [F(0)] * 3, e)
    assert k == F(104, 100) == (1 + 3 * s * s) / m
    assert j == F(9, 2) / k and v_b2 == [F(0), F(0), -3 + j / 2] and w_b2 == [F(18, 10) * j, 0, 0]
    lost = energy(m, world, v_b, [F(0)] * 3) - energy(m, world, v_b2, w_b2)
    assert lost == (1 - e * e) * d * d / (2 * k)
    print("rod on its end: n.K.n", k, "j", j, "=", float(j), "w'", [float(x) for x in w_b2],
          "lost", float(lost))


def box_on_a_box_corner():
    # The box corner again, struck by a 1 kg box a of edges (7/4, 1, 1) instead of the ball (the
    # contact found from the shapes): a's x axis along n (the rotation's columns below, a proper
    # rotation), its +x face's centre on the line through the corner along u = -n, `gap` from it.
    # a's lever arm to its closest point is (7/8) n: r_a x n = 0, so a adds only 1/m_a to n.K.n
    # and does not turn: the ball's closed form (box_corner) holds for the two boxes.
    u = [F(2, 7), F(3, 7), F(6, 7)]
    n = [-x for x in u]
    turn = transpose([n, [F(3, 7), F(-6, 7), F(2, 7)], [F(-6, 7), F(-2, 7), F(3, 7)]])
    assert matmul(transpose(turn), turn) == diag([F(1)] * 3)
    assert dot(transpose(turn)[0], cross(transpose(turn)[1], transpose(turn)[2])) == 1
    corner = [F(1, 2), F(1), F(3, 2)]
    half = F(7, 8)
    for gap in (F(0), F(7, 4)):
        centre = [corner[i] + (gap + half) * u[i] for i in range(3)]
        face_point = [centre[i] + half * n[i] for i in range(3)]  # a's +x face's centre
        assert face_point == [corner[i] + gap * u[i] for i in range(3)]
        r_a = [face_point[i] - centre[i] for i in range(3)]
        assert cross(r_a, n) == [0, 0, 0]
        middle = [(face_point[i] + corner[i]) / 2 for i in range(3)]
        print("box on a box corner, gap", gap, ": a's centre", centre, "contact point", middle)


if __name__ == "__main__":
    box_corner()
    rod_on_its_end()
    box_on_a_box_corner()
