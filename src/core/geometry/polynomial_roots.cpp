#include "geometry/polynomial_roots.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace collision_response::core {

namespace {

constexpr std::size_t kMaxDegree = 8;
constexpr int kMaxPieces = 4096;
constexpr std::size_t kMaxLevels = 128;

/// A stretch [low, high] of u = t / horizon and the Bernstein coefficients of p on it.
/// Trivial (no initialisers): a stack of them is not cleared at every call.
struct Piece {
  std::array<long double, kMaxDegree + 1> b;
  long double low, high;
};

int signOf(long double value, long double error) {
  if (value > error) return 1;
  if (value < -error) return -1;
  return 0;
}

}  // namespace

long double polynomialValue(const std::vector<long double>& coefficients, long double t) {
  long double value = 0;
  for (auto k = coefficients.size(); k-- > 0;) value = value * t + coefficients[k];
  return value;
}

long double polynomialSlope(const std::vector<long double>& coefficients, long double t) {
  long double slope = 0;
  for (auto k = coefficients.size(); k-- > 1;) {
    slope = slope * t + static_cast<long double>(k) * coefficients[k];
  }
  return slope;
}

std::optional<PolynomialRoot> visitRoots(
    const std::vector<long double>& coefficients, double horizon,
    const std::function<bool(const PolynomialRoot&)>& visit,
    const std::function<bool(double low, double high)>& may_hold) {
  std::size_t degree = coefficients.size();
  while (degree > 0 && coefficients[degree - 1] == 0) --degree;
  if (degree < 2 || degree > kMaxDegree + 1 || !(horizon > 0) || !std::isfinite(horizon)) {
    return std::nullopt;  // a constant has no isolated root
  }
  --degree;  // now the degree
  // On u in [0, 1]: a_k = c_k horizon^k.
  std::vector<long double> scaled(degree + 1);  // Horner's rule on it below
  long double power = 1, size = 0;
  for (std::size_t k = 0; k <= degree; ++k) {
    scaled[k] = coefficients[k] * power;
    power *= horizon;
    size += std::abs(scaled[k]);
  }
  if (!std::isfinite(size) || !(size > 0)) return std::nullopt;
  // b_i = sum_{k <= i} C(i, k) / C(n, k) a_k (Farouki and Rajan, eq. 8).
  Piece whole;
  whole.low = 0;
  whole.high = 1;
  // Pascal's triangle, once.
  static const auto choose = [] {
    std::array<std::array<long double, kMaxDegree + 1>, kMaxDegree + 1> table{};
    for (std::size_t i = 0; i <= kMaxDegree; ++i) {
      table[i][0] = 1;
      for (std::size_t k = 1; k <= i; ++k) {
        table[i][k] = table[i - 1][k - 1] + (k < i ? table[i - 1][k] : 0);
      }
    }
    return table;
  }();
  for (std::size_t i = 0; i <= degree; ++i) {
    long double sum = 0;
    for (std::size_t k = 0; k <= i; ++k) sum += choose[i][k] / choose[degree][k] * scaled[k];
    whole.b[i] = sum;
  }
  // The rounding of a coefficient: the conversion's (n + 1 terms of a sum of at most `size`) and
  // each subdivision's (an average of two: one rounding, and at most 128 levels deep), with
  // room.
  constexpr long double kEps = std::numeric_limits<long double>::epsilon();
  const long double error =
      4 * (static_cast<long double>(degree + 1) * (degree + 1) + 128) * kEps * size;

  // Exactly one root in (low, high), where p changes sign from `start_sign`: Newton's steps kept
  // inside the bracket (a bisection where one would leave it), the bracket closed on each
  // evaluation, until it is two doubles wide. A step shorter than a double's spacing is
  // lengthened to one, so that the next evaluation lands across the root and closes the bracket
  // from the other side.
  const auto polish = [&](long double low, long double high,
                          int start_sign) -> std::optional<PolynomialRoot> {
    long double x = 0.5L * (low + high);
    bool asked = !may_hold;
    for (int iteration = 0; iteration < 256; ++iteration) {
      if (!asked && high - low <= 1e-6L) {
        asked = true;
        if (!may_hold(static_cast<double>(low * horizon), static_cast<double>(high * horizon))) {
          return std::nullopt;
        }
      }
      const double low_time = static_cast<double>(low * horizon);
      const double high_time = static_cast<double>(high * horizon);
      if (std::nextafter(low_time, INFINITY) >= high_time) break;
      const long double value = polynomialValue(scaled, x);
      const int sign = signOf(value, 0);
      if (sign == 0) {
        low = high = x;
        break;
      }
      (sign == start_sign ? low : high) = x;
      const long double slope = polynomialSlope(scaled, x);
      const long double step = slope != 0 ? value / slope : 0;
      const double t = static_cast<double>(x * horizon);
      const long double spacing = (std::nextafter(t, INFINITY) - t) / horizon;
      long double next = std::abs(step) < spacing ? x - std::copysign(spacing, step) : x - step;
      if (!(next > low && next < high) || slope == 0) next = 0.5L * (low + high);
      x = next;
    }
    PolynomialRoot root;
    root.time = static_cast<double>(0.5L * (low + high) * horizon);
    root.simple = true;
    root.falling = start_sign > 0;
    return root;
  };

  // Leftmost first: a piece's right half waits below its left. At most one piece waits per level
  // (pieces end at widths of 1e-30, about 2^-100).
  std::array<Piece, kMaxLevels> stack;
  std::size_t waiting = 0;
  stack[waiting++] = whole;
  for (int pieces = 0; waiting > 0 && pieces < kMaxPieces; ++pieces) {
    const Piece piece = stack[--waiting];
    bool positive = true, negative = true;
    int changes = 0, last = 0;
    bool uncertain = false;
    for (std::size_t i = 0; i <= degree; ++i) {
      const int sign = signOf(piece.b[i], error);
      positive = positive && sign > 0;
      negative = negative && sign < 0;
      if (sign == 0) uncertain = true;
      if (sign != 0) {
        if (last != 0 && sign != last) ++changes;
        last = sign;
      }
    }
    if (positive || negative) continue;  // no root here
    if (!uncertain && changes == 1) {
      const auto root = polish(piece.low, piece.high, signOf(piece.b[0], error));
      if (root && visit(*root)) return root;
      continue;
    }
    const long double width = piece.high - piece.low;
    if (width <= 4 * std::numeric_limits<double>::epsilon() * piece.high + 1e-30L) {
      // Too short to divide. Where p's values at its ends differ in sign, a root crosses here
      // (on a subdivision's point, or at the end of the horizon): polished as any.
      const int at_low = signOf(polynomialValue(scaled, piece.low), 0);
      const int at_high = signOf(polynomialValue(scaled, piece.high), 0);
      if (at_low != 0 && at_high != 0 && at_low != at_high) {
        const auto root = polish(piece.low, piece.high, at_low);
        if (root && visit(*root)) return root;
        continue;
      }
      if (may_hold && !may_hold(static_cast<double>(piece.low * horizon),
                                static_cast<double>(piece.high * horizon))) {
        continue;
      }
      // Otherwise p is within its rounding of 0 somewhere here: a double root.
      const long double middle = 0.5L * (piece.low + piece.high);
      PolynomialRoot root;
      root.time = static_cast<double>(middle * horizon);
      root.simple = false;
      root.falling = polynomialSlope(scaled, middle) <= error;
      if (visit(root)) return root;
      continue;
    }
    // De Casteljau at the middle: the left half's coefficients are the first of each row of
    // averages, the right half's the last.
    Piece left, right;
    left.low = piece.low;
    left.high = right.low = 0.5L * (piece.low + piece.high);
    right.high = piece.high;
    std::array<long double, kMaxDegree + 1> row = piece.b;
    for (std::size_t level = 0; level <= degree; ++level) {
      left.b[level] = row[0];
      right.b[degree - level] = row[degree - level];
      for (std::size_t i = 0; i + level < degree; ++i) row[i] = 0.5L * (row[i] + row[i + 1]);
    }
    if (waiting + 2 > stack.size()) break;  // deeper than widths of 1e-30: not reached
    stack[waiting++] = right;
    stack[waiting++] = left;
  }
  return std::nullopt;
}

}  // namespace collision_response::core
