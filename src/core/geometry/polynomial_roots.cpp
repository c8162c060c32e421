#include "geometry/polynomial_roots.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace collision_response::core {

namespace {

constexpr std::size_t kMaxDegree = 8;
constexpr int kMaxPieces = 4096;

/// A stretch [low, high] of u = t / horizon and the Bernstein coefficients of p on it.
struct Piece {
  std::array<long double, kMaxDegree + 1> b{};
  long double low = 0, high = 1;
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

std::optional<PolynomialRoot> visitRoots(const std::vector<long double>& coefficients,
                                         double horizon,
                                         const std::function<bool(const PolynomialRoot&)>& visit) {
  std::size_t degree = coefficients.size();
  while (degree > 0 && coefficients[degree - 1] == 0) --degree;
  if (degree < 2 || degree > kMaxDegree + 1 || !(horizon > 0) || !std::isfinite(horizon)) {
    return std::nullopt;  // a constant has no isolated root
  }
  --degree;  // now the degree
  // On u in [0, 1]: a_k = c_k horizon^k.
  std::vector<long double> scaled(degree + 1);
  long double power = 1, size = 0;
  for (std::size_t k = 0; k <= degree; ++k) {
    scaled[k] = coefficients[k] * power;
    power *= horizon;
    size += std::abs(scaled[k]);
  }
  if (!std::isfinite(size) || !(size > 0)) return std::nullopt;
  // b_i = sum_{k <= i} C(i, k) / C(n, k) a_k (Farouki and Rajan, eq. 8).
  Piece whole;
  std::array<std::array<long double, kMaxDegree + 1>, kMaxDegree + 1> choose{};
  for (std::size_t i = 0; i <= degree; ++i) {
    choose[i][0] = 1;
    for (std::size_t k = 1; k <= i; ++k) {
      choose[i][k] = choose[i - 1][k - 1] + (k < i ? choose[i - 1][k] : 0);
    }
  }
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

  std::vector<Piece> stack = {whole};
  for (int pieces = 0; !stack.empty() && pieces < kMaxPieces; ++pieces) {
    const Piece piece = stack.back();
    stack.pop_back();
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
      // Exactly one root, where p changes sign: bisected until its bracket is two doubles wide.
      const int start_sign = signOf(piece.b[0], error);
      long double low = piece.low, high = piece.high, middle = 0.5L * (low + high);
      for (int iteration = 0; iteration < 256; ++iteration) {
        middle = 0.5L * (low + high);
        const double low_time = static_cast<double>(low * horizon);
        const double high_time = static_cast<double>(high * horizon);
        if (std::nextafter(low_time, INFINITY) >= high_time) break;
        const int sign = signOf(polynomialValue(scaled, middle), 0);
        if (sign == 0) {
          low = high = middle;
          break;
        }
        (sign == start_sign ? low : high) = middle;
      }
      PolynomialRoot root;
      root.time = static_cast<double>(0.5L * (low + high) * horizon);
      root.simple = true;
      root.falling = start_sign > 0;
      if (visit(root)) return root;
      continue;
    }
    const long double width = piece.high - piece.low;
    if (width <= 4 * std::numeric_limits<double>::epsilon() * piece.high + 1e-30L) {
      // Too short to divide, p within its rounding of 0 somewhere here: a double root.
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
    stack.push_back(right);
    stack.push_back(left);
  }
  return std::nullopt;
}

}  // namespace collision_response::core
