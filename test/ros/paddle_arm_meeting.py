#!/usr/bin/python3
"""The instant the ball of config/scenes/paddle_arm.yaml meets the paddle of urdf/paddle_arm.urdf
swung by examples/paddle_arm_joints.py (defaults) from the ball's start, worked out here apart from
the code under test (test/ros/test_paddle_arm.cpp, TheBallMeetsThePaddleAtTheInstant...): the
first t at which the ball's centre, on its lob c(t) = (2 - 1.5 t, 0, 0.6 + 4.05 t - g t^2 / 2), is
r + thickness / 2 = 0.025 m out from the paddle's face centre along its normal n = Rz(q1) Ry(q2) x,
q1 = 0.05 sin(pi t), q2 = 0.3 sin(pi t), by bisection to the double's resolution; and how far from
the disc's axis (< 0.08 m: on its face).
  /usr/bin/python3 test/ros/paddle_arm_meeting.py   -> 0.846476538914 s, 0.0617 m"""
from math import cos, pi, sin, sqrt

G = 9.81


def ball(t):
    return [2 - 1.5 * t, 0.0, 0.6 + 4.05 * t - G * t * t / 2]


def paddle(t):
    q1, q2 = 0.05 * sin(pi * t), 0.3 * sin(pi * t)

    def rz(v):
        return [cos(q1) * v[0] - sin(q1) * v[1], sin(q1) * v[0] + cos(q1) * v[1], v[2]]

    normal = rz([cos(q2), 0.0, -sin(q2)])
    out = rz([0.4 + 0.3 * cos(q2), 0.0, -0.3 * sin(q2)])
    return normal, [out[0], out[1], 0.5 + out[2]]


def gap(t):
    c = ball(t)
    n, p = paddle(t)
    return sum(n[i] * (c[i] - p[i]) for i in range(3)) - 0.025


def main():
    step = 1e-3
    t = step
    while gap(t) > 0:
        t += step
    low, high = t - step, t
    for _ in range(200):
        middle = (low + high) / 2
        if gap(middle) > 0:
            low = middle
        else:
            high = middle
    c = ball(low)
    n, p = paddle(low)
    d = [c[i] - p[i] for i in range(3)]
    along = sum(n[i] * d[i] for i in range(3))
    radial = sqrt(sum((d[i] - n[i] * along) ** 2 for i in range(3)))
    print("%.12f s, %.4f m from the axis" % (low, radial))


if __name__ == "__main__":
    main()
