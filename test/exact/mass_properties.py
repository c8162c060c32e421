#!/usr/bin/env python3
"""Mass properties of uniform solids, for test/core/test_mass_properties.cpp.

Derived here without the C++ code under test and without its closed forms:

- An irregular tetrahedron (vertices with exact binary fractions), in rationals: with barycentric
  coordinates l_k, x = sum l_k v_k and the Dirichlet integrals over a simplex,
  integral of l_a l_b dV = V (1 + [a == b]) / 20, so integral of x x^T dV =
  V / 20 (sum_k v_k v_k^T + S S^T), S = sum_k v_k. About the centroid c = S / 4 the second
  moments are C = integral of x x^T dV - V c c^T, and the tensor I = rho (trace(C) 1 - C),
  rho = m / V.
- A cylinder and a capsule (radius r, length h of the cylinder, axis z) by quadrature along the
  axis in mpmath at 40 digits: a slice at height z is a disc of radius s(z) (s = r on the
  cylinder; s = sqrt(r^2 - (|z| - h/2)^2) over the capsule's ends), whose own integrals are
  pi s^2 (area), pi s^4 / 2 (of x^2 + y^2) and pi s^4 / 4 (of y^2), so
  V = int pi s^2 dz, I_zz = rho int pi s^4 / 2 dz, I_xx = rho int (pi s^4 / 4 + z^2 pi s^2) dz.
  No hemisphere's moment and no parallel-axis shift enters: these check the closed forms'.

Prints each number as the shortest double that reads back (repr), for the test to compare with.
"""
from fractions import Fraction as F

import mpmath

mpmath.mp.dps = 40


def tetrahedron(vertices, mass):
    """Volume, centroid and inertia tensor (about the centroid) of a uniform tetrahedron."""
    v = [[F(c) for c in p] for p in vertices]
    e1 = [v[1][i] - v[0][i] for i in range(3)]
    e2 = [v[2][i] - v[0][i] for i in range(3)]
    e3 = [v[3][i] - v[0][i] for i in range(3)]
    det = (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
           e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]))
    volume = abs(det) / 6
    s = [sum(p[i] for p in v) for i in range(3)]
    centroid = [si / 4 for si in s]
    second = [[volume / 20 * (sum(p[i] * p[j] for p in v) + s[i] * s[j]) - volume * centroid[i] *
               centroid[j] for j in range(3)] for i in range(3)]
    rho = F(mass) / volume
    trace = second[0][0] + second[1][1] + second[2][2]
    tensor = [[rho * ((trace if i == j else 0) - second[i][j]) for j in range(3)] for i in range(3)]
    return volume, centroid, tensor


def axisymmetric(radius, length, mass, capsule):
    """Volume, I_xx and I_zz of a uniform cylinder or capsule along z, by quadrature in z."""
    r, h, m = mpmath.mpf(radius), mpmath.mpf(length), mpmath.mpf(mass)

    def s2(z):  # the slice's radius squared
        over = abs(z) - h / 2
        return r * r if over <= 0 else r * r - over * over

    ends = [-h / 2 - r, -h / 2, h / 2, h / 2 + r] if capsule else [-h / 2, h / 2]
    volume = mpmath.quad(lambda z: mpmath.pi * s2(z), ends)
    rho = m / volume
    izz = rho * mpmath.quad(lambda z: mpmath.pi * s2(z) ** 2 / 2, ends)
    ixx = rho * mpmath.quad(lambda z: mpmath.pi * s2(z) ** 2 / 4 + z * z * mpmath.pi * s2(z), ends)
    return volume, ixx, izz


def show(name, value):
    print(f"{name} = {float(value)!r}")


def main():
    print("# Tetrahedron (0.5, 0.25, -1), (2, 0.5, 0), (0.25, 1.5, 0.5), (1, 1, 2), 3 kg")
    volume, centroid, tensor = tetrahedron(
        [(0.5, 0.25, -1), (2, 0.5, 0), (0.25, 1.5, 0.5), (1, 1, 2)], 3)
    show("volume", volume)
    for axis, c in zip("xyz", centroid):
        show(f"centroid.{axis}", c)
    for name, (i, j) in {"ixx": (0, 0), "iyy": (1, 1), "izz": (2, 2), "ixy": (0, 1),
                         "ixz": (0, 2), "iyz": (1, 2)}.items():
        print(f"{name} = {float(tensor[i][j])!r}  # {tensor[i][j]}")
    print("# Cylinder r = 0.375, h = 0.5, 3 kg")
    for name, value in zip(("volume", "ixx", "izz"), axisymmetric(0.375, 0.5, 3, False)):
        show(name, value)
    print("# Capsule r = 0.25, h = 1.5, 2 kg")
    for name, value in zip(("volume", "ixx", "izz"), axisymmetric(0.25, 1.5, 2, True)):
        show(name, value)
    print("# Capsule r = 0.0525, h = 0.1, 0.37 kg (a can's size)")
    for name, value in zip(("volume", "ixx", "izz"), axisymmetric(0.0525, 0.1, 0.37, True)):
        show(name, value)


if __name__ == "__main__":
    main()
