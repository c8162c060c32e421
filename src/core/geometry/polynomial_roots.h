// The real roots of a polynomial on an interval, none missed and none invented: isolated by
// Descartes' rule of signs on the polynomial's Bernstein coefficients, subdivided by de
// Casteljau's algorithm, then polished by bisection to the last bits of the instant.
//
// On [0, 1] a polynomial p(u) = sum_i b_i B_i(u) (the Bernstein basis B_i(u) = C(n, i) u^i
// (1 - u)^(n - i)) lies within the hull of its coefficients, so b_i > 0 for all i proves p > 0
// there; and the number of roots in (0, 1) is at most the number of sign changes of b_0..b_n (and
// of the same parity), so one sign change proves exactly one root (Farouki and Rajan, "On the
// numerical condition of polynomials in Bernstein form", CAGD 4, 1987; Mourrain, Rouillier and
// Roy, "The Bernstein basis and real root isolation", 2005). Both are applied with a bound on the
// rounding of the coefficients: a coefficient within it has no sign.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

namespace collision_response::core {

/// What a root is: a certified simple root (p changes sign across it), or an interval too short
/// to divide where p is within its rounding of 0 (a double root: a graze, or a rolling
/// contact's own surface).
struct PolynomialRoot {
  double time = 0.0;     ///< the root, or the middle of the interval where p is about 0
  bool simple = true;    ///< p changes sign here
  bool falling = false;  ///< p goes from > 0 to < 0 (a simple root), or decreases here
};

/// Visits the real roots of p(t) = sum_k coefficients[k] t^k in [0, horizon], in increasing
/// order, until `visit` returns true; returns the root it stopped at. Coefficients in long
/// double, of degree at most 8. The polynomial is scaled to [0, 1] first (t = horizon u), its
/// Bernstein coefficients bounded for rounding, and subdivided leftmost first; a simple root is
/// polished by bisection until its bracket is two doubles wide. At most 4096 pieces are looked
/// at (a polynomial within its rounding of 0 on a whole stretch: a ball rolling on the very
/// surface): past that nothing more is visited.
///
/// `may_hold(low, high)`, if given, is asked once a simple root's bracket is a millionth of the
/// horizon wide (or at once, for a double root's short interval): false skips the root without
/// polishing it (a face's plane crossed outside the face), and it is not visited.
std::optional<PolynomialRoot> visitRoots(
    const std::vector<long double>& coefficients, double horizon,
    const std::function<bool(const PolynomialRoot&)>& visit,
    const std::function<bool(double low, double high)>& may_hold = nullptr);

/// p(t) and p'(t) by Horner's rule in long double.
long double polynomialValue(const std::vector<long double>& coefficients, long double t);
long double polynomialSlope(const std::vector<long double>& coefficients, long double t);

}  // namespace collision_response::core
