#!/usr/bin/env python3
"""A ball rolling or sliding off a box's edge: when it slips, when it leaves, how it flies on.

The numbers test/core/test_lasting_contact.cpp's edge scans (EdgeScan.*), test/ros/test_table.cpp
and test/ros/test_edge_roll_off.cpp (the flight to the floor, printed last) compare the monitor
with, derived here from Newton's and Coulomb's laws alone (nothing here calls or copies the C++
code under test).

The model (doc/model.md, "Lasting contact" and "Finite shapes"): a ball of radius r, mass m and
moment of inertia I = k m r^2 (k = 2/5, a solid ball) moves at v0 along a box's top face, rolling
(spin w0 = v0 / r) or sliding, towards the edge x = 0. Once its centre crosses the edge's line
it pivots about the edge, its centre on the circle of radius r about it; theta is the angle of
the line from the edge to the centre from the vertical (theta = 0 at the crossing, theta' = v0 / r).
Along the circle's inward normal and its tangent, with gravity g, the edge's push N (>= 0) and
Coulomb's friction F (on the ball, against the tangent; |F| <= mu N):

  N = m g cos(theta) - m r theta'^2            (centripetal)
  m r theta'' = m g sin(theta) - F              (tangential)
  I w' = F r                                    (the spin)

Rolling (the edge's point of the ball at rest, w = theta'): F = k/(1+k) m g sin(theta), and
theta'^2 = u(theta) = (v0/r)^2 + 2 g (1 - cos theta) / ((1 + k) r) in closed form (energy).
It rolls while F <= mu N; it starts to slip at the first theta_s where k/(1+k) g sin(theta) =
mu (g cos(theta) - r u(theta)). As N -> 0 with F -> k/(1+k) m g sin(theta) > 0, any finite mu
slips before the ball leaves: the closed form of leaving while rolling,
cos(theta) = (10 + 7 v0^2 / (g r)) / 17 (N = 0 with the rolling u), holds with unlimited
friction only.

Slipping (forwards: theta' > w, F = mu N against it): theta'' = (g/r)(sin theta - mu cos theta)
+ mu theta'^2, linear in u = theta'^2 as a function of theta:
  du/dtheta = 2 (g/r) (sin theta - mu cos theta) + 2 mu u,
  u(theta) = e^(2 mu (theta - theta_s)) u_s + 2 (g/r) / (1 + 4 mu^2) (P(theta)
             - e^(2 mu (theta - theta_s)) P(theta_s)),  P(x) = -3 mu sin x - (1 - 2 mu^2) cos x.
(mu = 0, sliding from the start: u = (v0/r)^2 + 2 (g/r) (1 - cos theta), and the closed form
cos(theta) = (2 + v0^2 / (g r)) / 3.) It leaves the edge where N = 0: g cos(theta) = r u(theta).
The time on the edge is the quadrature t(theta) = integral of dtheta / sqrt(u(theta)); the spin
while slipping, w' = mu N / (k m r), by the same quadrature in theta. After it leaves, the
centre's velocity r theta' (cos theta, -sin theta) is its flight's.

Everything in mpmath at 40 digits from the doubles the tests use (mpf(float)); each slipping
phase is also integrated as the full ODE in (theta, theta', w) by mpmath's Taylor series
(odefun, at 20 digits) and the script stops if its angle at the leave disagrees by 1e-15.

Over ROS (test/ros/edge_roll_off.yaml: the table's ball rolling at 0.3 m/s from x0 = 0.3 with
mu = 1, a floor plane at z = 0; its other balls the same, later by (0.3 - x0) / v0): after the
leave it flies freely, its centre on the parabola p(t) = p_l + v_l (t - t_l) + g (t - t_l)^2 / 2
from the leave's point p_l = (0.5 + r sin theta, 0.75 + r cos theta) and velocity v_l, until its
centre is r above the floor (the later root of that quadratic in closed form). N = 0 there makes
g cos theta = |v_l|^2 / r, so the flight's horizontal velocity is sqrt(g r) cos^(3/2) theta all
along: cos theta = (vx^2 / (g r))^(1/3), printed as a check of the leave.

Run: python3 test/exact/edge_roll_off.py
"""
import mpmath
from mpmath import mpf

mpmath.mp.dps = 40

G = mpf(9.81)
K = mpf(2) / 5  # a solid ball: I = k m r^2


def roll_off(r, v0, mu, rolling):
    """theta_s, t_s (the slip, None where it never rolls), theta_l, t_l (the leave), theta'
    and w at the leave; times from the centre's crossing of the edge's line."""
    r, v0 = mpf(r), mpf(v0)
    mu = None if mu is None else mpf(mu)  # None: unlimited friction

    def u_rolling(th):
        return (v0 / r) ** 2 + 2 * G * (1 - mpmath.cos(th)) / ((1 + K) * r)

    def normal(th, u):  # N / m
        return G * mpmath.cos(th) - r * u

    if rolling and mu is None:
        theta_l = mpmath.findroot(lambda th: normal(th, u_rolling(th)), mpf("0.7"))
        t_l = mpmath.quad(lambda th: 1 / mpmath.sqrt(u_rolling(th)), [0, theta_l])
        return None, None, theta_l, t_l, mpmath.sqrt(u_rolling(theta_l)), None
    if rolling and mu > 0:
        # The first angle at which rolling needs more than mu N (bracketed between the crossing,
        # where it needs none, and the rolling leave, where N = 0).
        theta_roll_leave = mpmath.findroot(lambda th: normal(th, u_rolling(th)), mpf("0.7"))
        need = lambda th: K / (1 + K) * G * mpmath.sin(th) - mu * normal(th, u_rolling(th))
        theta_s = mpmath.findroot(need, (mpf(0), theta_roll_leave), solver="illinois")
        t_s = mpmath.quad(lambda th: 1 / mpmath.sqrt(u_rolling(th)), [0, theta_s])
        u_s, w_s = u_rolling(theta_s), mpmath.sqrt(u_rolling(theta_s))
    else:  # sliding from the crossing (mu = 0, or no spin to roll with)
        theta_s, t_s, u_s, w_s = mpf(0), mpf(0), (v0 / r) ** 2, (v0 / r if rolling else mpf(0))
        mu = mpf(0) if mu is None else mu
        if mu > 0:
            raise ValueError("a ball sliding on a rough face rolls before the edge: not modelled")

    def P(x):
        return -3 * mu * mpmath.sin(x) - (1 - 2 * mu**2) * mpmath.cos(x)

    def u_slipping(th):
        grow = mpmath.exp(2 * mu * (th - theta_s))
        return grow * u_s + 2 * (G / r) / (1 + 4 * mu**2) * (P(th) - grow * P(theta_s))

    # N falls from its value at theta_s through 0 within 1 / mu rad (the slip's e^(2 mu theta)).
    upper = theta_s + min(mpf(mpmath.pi) / 2 - theta_s, 1 / mu if mu > 0 else mpf(1))
    theta_l = mpmath.findroot(lambda th: normal(th, u_slipping(th)), (theta_s, upper),
                              solver="illinois")
    t_l = t_s + mpmath.quad(lambda th: 1 / mpmath.sqrt(u_slipping(th)), [theta_s, theta_l])
    # The spin: dw/dtheta = w' / theta' = mu N / (m k r sqrt(u)).
    w_l = w_s + mpmath.quad(
        lambda th: mu * normal(th, u_slipping(th)) / (K * r * mpmath.sqrt(u_slipping(th))),
        [theta_s, theta_l])

    # The same phase as the full ODE in time (Taylor series, at 20 digits), as a check of the
    # algebra above.
    if t_l > t_s:
        with mpmath.workdps(20):
            def rate(t, y):
                th, thd, w = y
                n = G * mpmath.cos(th) - r * thd**2
                return [thd, (G * mpmath.sin(th) - mu * n) / r, mu * n / (K * r)]

            solution = mpmath.odefun(rate, t_s, [theta_s, mpmath.sqrt(u_s), w_s])
            at_leave = solution(t_l)
        if abs(at_leave[0] - theta_l) > mpf("1e-15") or abs(at_leave[2] - w_l) > mpf("1e-12"):
            raise SystemExit(f"the quadrature and the ODE disagree: {at_leave} at {t_l}")
    return theta_s, t_s, theta_l, t_l, mpmath.sqrt(u_slipping(theta_l)), w_l


def report(label, r, v0, mu, rolling):
    theta_s, t_s, theta_l, t_l, thd, w = roll_off(r, v0, mu, rolling)
    r = mpf(r)
    vx, vz = r * thd * mpmath.cos(theta_l), -r * thd * mpmath.sin(theta_l)
    print(f"{label}:")
    if theta_s is not None and t_s > 0:
        print(f"  slips at theta = {mpmath.nstr(theta_s, 17)} rad, "
              f"{mpmath.nstr(t_s, 17)} s after the crossing")
    print(f"  leaves at theta = {mpmath.nstr(theta_l, 17)} rad, cos = "
          f"{mpmath.nstr(mpmath.cos(theta_l), 17)}, {mpmath.nstr(t_l, 17)} s after the crossing")
    print(f"  flies on at vx = {mpmath.nstr(vx, 17)} m/s, vz = {mpmath.nstr(vz, 17)} m/s"
          + (f", spin {mpmath.nstr(w, 17)} rad/s" if w is not None else ""))


def main():
    r, v0 = 0.0335, 0.3  # config/scenes/table.yaml's tennis ball and slider
    g_r = G * mpf(r)
    print(f"r = {r} m, v0 = {v0} m/s, g = 9.81 m/s^2, solid ball (I = 2/5 m r^2); "
          "times from the centre's crossing of the edge's line")
    print(f"closed forms: sliding cos = (2 + v0^2/(g r))/3 = "
          f"{mpmath.nstr((2 + mpf(v0)**2 / g_r) / 3, 17)}; rolling with unlimited friction "
          f"cos = (10 + 7 v0^2/(g r))/17 = {mpmath.nstr((10 + 7 * mpf(v0)**2 / g_r) / 17, 17)}")
    report("sliding (mu = 0, or gravity alone)", r, v0, 0, False)
    report("rolling, mu = 1", r, v0, 1, True)
    report("rolling, mu = 100", r, v0, 100, True)
    report("rolling, unlimited friction", r, v0, None, True)
    # The run: from x0 = 0.3 the centre crosses the edge x = 0.5 at 0.2 / 0.3 s.
    _, _, theta_l, t_l, _, _ = roll_off(r, v0, 1, True)
    print(f"mu = 1 from x0 = 0.3 (crossing at 2/3 s): leaves at "
          f"{mpmath.nstr(mpf(0.2) / mpf(v0) + t_l, 17)} s")
    floor_flight(r, v0, mpf(0.3))


def floor_flight(r, v0, x0):
    """test/ros/edge_roll_off.yaml: rolling with mu = 1 from x0 on the top (z = 0.75, its edge at
    x = 0.5), off the edge onto a floor plane at z = 0; times from the scene's start."""
    _, _, theta_l, t_l, thd, w = roll_off(r, v0, 1, True)
    r = mpf(r)
    leaves = (mpf(0.5) - x0) / mpf(v0) + t_l
    px, pz = mpf(0.5) + r * mpmath.sin(theta_l), mpf(0.75) + r * mpmath.cos(theta_l)
    vx, vz = r * thd * mpmath.cos(theta_l), -r * thd * mpmath.sin(theta_l)
    # pz + vz s - g s^2 / 2 = r: the later root.
    s = (vz + mpmath.sqrt(vz**2 + 2 * G * (pz - r))) / G
    print("over ROS (test/ros/edge_roll_off.yaml), mu = 1 from x0 = 0.3, floor at z = 0:")
    print(f"  leaves at {mpmath.nstr(leaves, 17)} s, centre ({mpmath.nstr(px, 17)}, 0, "
          f"{mpmath.nstr(pz, 17)}), cos theta = {mpmath.nstr(mpmath.cos(theta_l), 17)}")
    print(f"  velocity ({mpmath.nstr(vx, 17)}, 0, {mpmath.nstr(vz, 17)}) m/s, spin about y "
          f"{mpmath.nstr(w, 17)} rad/s")
    print(f"  cos theta from the flight's vx, (vx^2/(g r))^(1/3) = "
          f"{mpmath.nstr(mpmath.cbrt(vx**2 / (G * r)), 17)}")
    print(f"  meets the floor at {mpmath.nstr(leaves + s, 17)} s ({mpmath.nstr(s, 17)} s of "
          f"flight), contact point ({mpmath.nstr(px + vx * s, 17)}, 0, 0), velocity before "
          f"({mpmath.nstr(vx, 17)}, 0, {mpmath.nstr(vz - G * s, 17)}) m/s")


if __name__ == "__main__":
    main()
