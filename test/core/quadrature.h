// The quadrature the tests' closed forms take an instant by: the integral of dq / q' along a
// motion whose rate q'(q) the energy gives (test_shaped_pivot.cpp, test_shaped_rim.cpp,
// edge_landing.h, shaped_scenes.h).
#pragma once

#include <cmath>

namespace collision_response::core::quadrature {

/// The integral of f over [a, b] by 5-point Gauss-Legendre over `panels` equal panels (b < a
/// gives its negative).
template <class F>
double gaussLegendre(const F& f, double a, double b, int panels) {
  const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                       0.9061798459386640};
  const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                       0.4786286704993665, 0.2369268850561891};
  const double width = (b - a) / panels;
  double sum = 0.0;
  for (int p = 0; p < panels; ++p) {
    for (int i = 0; i < 5; ++i) sum += w[i] * 0.5 * width * f(a + (p + 0.5 + 0.5 * x[i]) * width);
  }
  return sum;
}

/// The instant a motion from rest at q0 takes to reach q1 at the rate |q'(q)| (0 at q0): with
/// q = q0 + s u^2 (s the sign of q1 - q0) the integrand 2 u / |q'| is smooth at u = 0.
template <class Rate>
double fromRest(const Rate& rate, double q0, double q1, int panels) {
  const double s = q1 > q0 ? 1.0 : -1.0;
  return gaussLegendre([&](double u) { return 2 * u / rate(q0 + s * u * u); }, 0.0,
                       std::sqrt(std::abs(q1 - q0)), panels);
}

}  // namespace collision_response::core::quadrature
