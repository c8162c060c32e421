#!/usr/bin/python3
# The reference instant of TumblingContact.ACubeOnItsCornerSpinningRisesByItsTurningInFewSteps
# (test_tumbling_contact.cpp), computed with mpmath at 40 digits, independently of the code under
# test: a cube of half side s = 0.05 m, its corner (-s, -s, -s) turned straight down by the least
# rotation taking (-1, -1, -1) / sqrt(3) to -z, its centre at rest at z0 = s sqrt(3) + 5e-12 m
# (the double C++ computes) under gravity g = 9.81 m/s^2, turning at w = 37 rad/s about x (fixed:
# a cube is isotropic). Its lowest corner is z(t) + min over corners of (Rx(w t) R0 c).z, z(t) =
# z0 - g t^2 / 2; the instant printed is that function's first root after 0 (it rises first:
# the corner below lifts as the cube turns, then the next corner comes down), bracketed on a grid
# of 1e-5 s and refined by bisection to 1e-30 s.
import math

import mpmath as mp

mp.mp.dps = 40
s = mp.mpf(0.05)
z0 = mp.mpf(0.05 * math.sqrt(3.0) + 5e-12)  # the double of the C++ expression
g = mp.mpf("9.81")
w = mp.mpf(37)


def rodrigues(axis, angle):
    k = axis / mp.norm(axis)
    kx = mp.matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return mp.eye(3) + mp.sin(angle) * kx + (1 - mp.cos(angle)) * kx * kx


a = mp.matrix([-1, -1, -1]) / mp.sqrt(3)
b = mp.matrix([0, 0, -1])
cross = mp.matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
r0 = rodrigues(cross, mp.acos(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]))
corners = [mp.matrix([sx * s, sy * s, sz * s]) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]


def lowest(t):
    r = rodrigues(mp.matrix([1, 0, 0]), w * t) * r0
    return z0 - g * t * t / 2 + min((r * c)[2] for c in corners)


assert lowest(mp.mpf(0)) > 0
t0, t1 = mp.mpf(0), None
step = mp.mpf("1e-5")
t = step
while t < 1:
    if lowest(t) <= 0:
        t1 = t
        break
    t0 = t
    t += step
lo, hi = t0, t1
for _ in range(200):
    mid = (lo + hi) / 2
    if lowest(mid) > 0:
        lo = mid
    else:
        hi = mid
print(mp.nstr(lo, 25))
