#!/usr/bin/env python3
"""Torque-free rotation of a rigid body, for test/core/test_free_rotation.cpp.

Derived here without the C++ code under test and without its elliptic functions: Euler's
equations in the body's principal frame, J_1 w_1' = (J_2 - J_3) w_2 w_3 (and cyclically), and
the orientation's kinematics q' = q (0, w) / 2 (q world from body, w in the body frame),
integrated together by mpmath's Taylor-series solver (mpmath.odefun) at 30 digits. Each case is
given by its body-frame angular velocity; its world-frame one, R(q0) w, is rounded to doubles and
printed for the test to give, and the integration starts from those doubles taken exactly (q0
normalised here in 30 digits), so the test and this script start from the same state. Each case
says which side of the separatrix it is on (the sign of M^2 - 2 E J_2).

Prints, per case, the body-frame angular velocity and the quaternion (w, x, y, z) at each time,
and for the intermediate axis's flip the times at which w_2 crosses zero (found by mpmath's
findroot on the integrated solution): the flip's period is twice the time between two crossings.
"""
import mpmath

mpmath.mp.dps = 30


def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def rotate_inverse(q, v):
    """R(q)^T v: a world vector in the body frame."""
    qc = (q[0], -q[1], -q[2], -q[3])
    return qmul(qmul(qc, (0, v[0], v[1], v[2])), q)[1:]


def unit(q0):
    q = [mpmath.mpf(x) for x in q0]
    n = mpmath.sqrt(sum(x * x for x in q))
    return [x / n for x in q]


def world_of(q0, w_body):
    """R(q0) w_body rounded to doubles: the world-frame angular velocity the test gives."""
    q = unit(q0)
    qc = (q[0], -q[1], -q[2], -q[3])
    v = qmul(qmul(q, (0,) + tuple(mpmath.mpf(x) for x in w_body)), qc)[1:]
    return tuple(float(x) for x in v)


def solve(moments, q0, w0_world):
    j = [mpmath.mpf(x) for x in moments]
    q = unit(q0)
    w = rotate_inverse(q, [mpmath.mpf(x) for x in w0_world])

    def f(_t, y):
        w1, w2, w3, qw, qx, qy, qz = y
        dq = qmul((qw, qx, qy, qz), (0, w1, w2, w3))
        return [(j[1] - j[2]) * w2 * w3 / j[0], (j[2] - j[0]) * w3 * w1 / j[1],
                (j[0] - j[1]) * w1 * w2 / j[2], dq[0] / 2, dq[1] / 2, dq[2] / 2, dq[3] / 2]

    return mpmath.odefun(f, 0, list(w) + list(q))


CASES = [
    # name, principal moments, q0 (w, x, y, z), w0 in the body frame, times
    ("round_the_largest_axis", (2.0, 3.0, 4.0), (0.48, 0.64, 0.36, 0.48), (0.3, -0.5, 2.0),
     (0.5, 3.0, 10.0)),
    ("round_the_smallest_axis", (2.0, 3.0, 4.0), (0.48, 0.64, 0.36, 0.48), (2.0, 0.5, -0.3),
     (0.5, 3.0, 10.0)),
    ("on_the_separatrix", (3.0, 5.0, 6.0), (1.0, 0.0, 0.0, 0.0), (1.0, 0.5, 1.0), (0.5, 3.0, 10.0)),
    ("near_the_separatrix", (3.0, 5.0, 6.0), (1.0, 0.0, 0.0, 0.0), (1.0, 0.5, 1.000000001),
     (0.5, 3.0, 10.0)),
    # The angle about L's closed form cancels near a spin about axis 3 (a -> 1) and where L is
    # nearly across it (a small, a nearly axisymmetric body).
    ("near_a_spin_about_the_largest_axis", (2.0, 3.0, 4.0), (0.48, 0.64, 0.36, 0.48),
     (1e-4, -1e-4, 2.0), (0.5, 3.0, 10.0)),
    ("nearly_across_the_axis_of_a_nearly_symmetric_body", (2.0, 2.0002, 3.5),
     (0.48, 0.64, 0.36, 0.48), (2.0, 0.0, 0.03), (0.5, 3.0, 10.0)),
]


def main():
    for name, moments, q0, w_body, times in CASES:
        w0 = world_of(q0, w_body)
        j = [mpmath.mpf(x) for x in moments]
        wb = rotate_inverse(unit(q0), [mpmath.mpf(x) for x in w0])
        side = sum(j[i] * (j[i] - j[1]) * wb[i] ** 2 for i in (0, 2))
        print(f"# {name}: moments {moments}, q0 {q0}, w0 (world) {{{', '.join(repr(x) for x in w0)}}}, "
              f"M^2 - 2 E J_2 = {mpmath.nstr(side, 5)}")
        y = solve(moments, q0, w0)
        for t in times:
            v = y(t)
            print(f"t {t}: w_body {{{', '.join(mpmath.nstr(x, 17) for x in v[:3])}}}, "
                  f"q {{{', '.join(mpmath.nstr(x, 17) for x in v[3:])}}}")
    # The flip of a body spun about its intermediate axis, slightly perturbed.
    moments, q0, w0 = (2.0, 3.0, 4.0), (1.0, 0.0, 0.0, 0.0), (1e-6, 2.0, 1e-6)
    y = solve(moments, q0, w0)
    crossings = []
    t = mpmath.mpf(0)
    step = mpmath.mpf("0.25")
    while len(crossings) < 2:
        a, b = y(t)[1], y(t + step)[1]
        if a * b < 0:
            crossings.append(mpmath.findroot(lambda s: y(s)[1], (t, t + step), solver="anderson"))
        t += step
    print(f"# flip: moments {moments}, q0 {q0}, w0 (world) {w0}")
    print(f"w_2 crosses zero at {mpmath.nstr(crossings[0], 17)} and "
          f"{mpmath.nstr(crossings[1], 17)}: period {mpmath.nstr(2 * (crossings[1] - crossings[0]), 17)}")
    v = y(crossings[1])
    print(f"at the second crossing: w_body {{{', '.join(mpmath.nstr(x, 17) for x in v[:3])}}}, "
          f"q {{{', '.join(mpmath.nstr(x, 17) for x in v[3:])}}}")


if __name__ == "__main__":
    main()
