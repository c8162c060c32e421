#include "geometry/polynomial_roots.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace collision_response::core {

namespace {

constexpr std::size_t kMaxDegree = 8;
constexpr int kMaxPieces = 4096;
constexpr std::size_t kMaxLevels = 128;

/// A stretch [low, high] of u = t / horizon, the Bernstein coefficients of p on it, and a bound
/// on their rounding. Trivial (no initialisers): a stack of them is not cleared at every call.
struct Piece {
  std::array<long double, kMaxDegree + 1> b;
  long double low, high, error;
};

/// Pascal's triangle, once.
const std::array<std::array<long double, kMaxDegree + 1>, kMaxDegree + 1>& binomials() {
  static const auto table = [] {
    std::array<std::array<long double, kMaxDegree + 1>, kMaxDegree + 1> t{};
    for (std::size_t i = 0; i <= kMaxDegree; ++i) {
      t[i][0] = 1;
      for (std::size_t k = 1; k <= i; ++k) t[i][k] = t[i - 1][k - 1] + (k < i ? t[i - 1][k] : 0);
    }
    return t;
  }();
  return table;
}

/// The piece [low, high] of p(u) = sum a_k u^k (0 <= low): its coefficients from the monomial
/// ones each time (not by subdividing another piece's), so that their rounding is that of the
/// terms on the piece, sum |a_k| high^k, and not that of the whole horizon's (a root at 1e-200
/// of a long horizon keeps its digits). p(low + w s) = sum_j c_j s^j with c_j = w^j sum_{k >= j}
/// C(k, j) a_k low^(k - j) (Taylor's shift), then b_i = sum_{j <= i} C(i, j) / C(n, j) c_j
/// (Farouki and Rajan, "On the numerical condition of polynomials in Bernstein form", CAGD 4,
/// 1987, eq. 8).
Piece pieceOf(const std::vector<long double>& a, std::size_t degree, long double low,
              long double high) {
  const auto& choose = binomials();
  Piece piece;
  piece.low = low;
  piece.high = high;
  const long double width = high - low;
  std::array<long double, kMaxDegree + 1> shifted{};
  long double size = 0, reach = 1, width_power = 1;
  for (std::size_t k = 0; k <= degree; ++k) {
    size += std::abs(a[k]) * reach;
    reach *= high;
  }
  for (std::size_t j = 0; j <= degree; ++j) {
    long double sum = 0, low_power = 1;
    for (std::size_t k = j; k <= degree; ++k) {
      sum += choose[k][j] * a[k] * low_power;
      low_power *= low;
    }
    shifted[j] = sum * width_power;
    width_power *= width;
  }
  for (std::size_t i = 0; i <= degree; ++i) {
    long double sum = 0;
    for (std::size_t j = 0; j <= i; ++j) sum += choose[i][j] / choose[degree][j] * shifted[j];
    piece.b[i] = sum;
  }
  // The shift's and the conversion's roundings: sums of at most n + 1 terms each, every term at
  // most `size` (the binomial theorem: sum_j sum_k C(k, j) |a_k| low^(k-j) w^j = sum |a_k|
  // high^k), with room.
  constexpr long double kEps = std::numeric_limits<long double>::epsilon();
  piece.error = 8 * static_cast<long double>((degree + 2) * (degree + 2)) * kEps * size;
  return piece;
}

/// Bezier clipping (Sederberg and Nishita, "Curve intersection using Bezier clipping", CAD 22,
/// 1990), one side at a time: p lies on or above the lower hull of its control points (i / n, b_i),
/// which is convex and so above its tangent at the first point; where b_0 > error, no root lies
/// before the fraction at which that tangent falls to `error` (mirrored for b_0 < -error). 0 where
/// nothing can be cut; 1 where the hull never falls.
long double rootFreeStart(const std::array<long double, kMaxDegree + 1>& b, std::size_t degree,
                          long double error) {
  const long double start = b[0];
  if (std::abs(start) <= error) return 0;
  const long double sign = start > 0 ? 1 : -1;
  long double steepest = 0;  // the most negative slope towards 0 (signed by the start's side)
  for (std::size_t i = 1; i <= degree; ++i) {
    const long double at = static_cast<long double>(i) / static_cast<long double>(degree);
    steepest = std::min(steepest, sign * (b[i] - start) / at);
  }
  if (!(steepest < 0)) return 1;
  return std::clamp((sign * start - error) / -steepest, 0.0L, 1.0L);
}

int signOf(long double value, long double error) {
  if (value > error) return 1;
  if (value < -error) return -1;
  return 0;
}

/// The signs of a piece's Bernstein coefficients, each within its rounding or not.
struct Signs {
  bool positive = true, negative = true;  ///< every coefficient above (below) its rounding
  bool uncertain = false;                 ///< one within its rounding
  int changes = 0;                        ///< sign changes among the certain ones
  long double largest = 0;                ///< the largest coefficient's size
};

Signs signsOf(const Piece& piece, std::size_t degree) {
  Signs signs;
  int last = 0;
  for (std::size_t i = 0; i <= degree; ++i) {
    const int sign = signOf(piece.b[i], piece.error);
    signs.positive = signs.positive && sign > 0;
    signs.negative = signs.negative && sign < 0;
    signs.largest = std::max(signs.largest, std::abs(piece.b[i]));
    if (sign == 0) {
      signs.uncertain = true;
      continue;
    }
    if (last != 0 && sign != last) ++signs.changes;
    last = sign;
  }
  return signs;
}

/// The search of one polynomial's roots on [0, horizon], in u = t / horizon: pieces looked at
/// leftmost first (a piece's right part waits below its left), each either root-free, or one
/// simple root (polished), or a double root (placed), or clipped or halved into more pieces.
class RootSearch {
 public:
  RootSearch(std::vector<long double> scaled, std::size_t degree, double horizon,
             const std::function<bool(double, double)>& may_hold)
      : scaled_(std::move(scaled)), degree_(degree), horizon_(horizon), may_hold_(may_hold) {
    stack_[waiting_++] = pieceOf(scaled_, degree_, 0, 1);
  }

  /// The next piece to look at; none when all are, or after kMaxPieces.
  std::optional<Piece> next() {
    if (waiting_ == 0 || looked_at_ >= kMaxPieces) return std::nullopt;
    ++looked_at_;
    return stack_[--waiting_];
  }

  /// The root `piece` holds, if it holds one alone; otherwise its parts are left to look at.
  std::optional<PolynomialRoot> examine(const Piece& piece) {
    const Signs signs = signsOf(piece, degree_);
    if (signs.positive || signs.negative) return std::nullopt;  // no root here
    // p within its rounding of 0 on the whole piece (a double root is only known to the square
    // root of the rounding; dividing on would visit that whole stretch): one double root.
    if (signs.largest <= 2 * piece.error) return doubleRoot(piece, leastOn(piece));
    if (!signs.uncertain && signs.changes == 1) {
      return polish(piece.low, piece.high, signOf(piece.b[0], piece.error));
    }
    if (!tooShort(piece)) {
      divide(piece);
      return std::nullopt;
    }
    return onShortPiece(piece);
  }

 private:
  /// Exactly one root in (low, high), where p changes sign from `start_sign`: Newton's steps kept
  /// inside the bracket (a bisection where one would leave it), the bracket closed on each
  /// evaluation, until it is two doubles wide. A step shorter than a double's spacing is
  /// lengthened to one, so that the next evaluation lands across the root and closes the
  /// bracket from the other side. None where `may_hold` refuses the bracket once it is a
  /// millionth of the horizon wide.
  std::optional<PolynomialRoot> polish(long double low, long double high, int start_sign) const {
    long double x = 0.5L * (low + high);
    bool asked = !may_hold_;
    for (int iteration = 0; iteration < 256; ++iteration) {
      if (!asked && high - low <= 1e-6L) {
        asked = true;
        if (!mayHold(low, high)) return std::nullopt;
      }
      const double low_time = static_cast<double>(low * horizon_);
      const double high_time = static_cast<double>(high * horizon_);
      if (std::nextafter(low_time, INFINITY) >= high_time) break;
      const long double value = polynomialValue(scaled_, x);
      const int sign = signOf(value, 0);
      if (sign == 0) {
        low = high = x;
        break;
      }
      (sign == start_sign ? low : high) = x;
      const long double slope = polynomialSlope(scaled_, x);
      const long double step = slope != 0 ? value / slope : 0;
      const double t = static_cast<double>(x * horizon_);
      const long double spacing = (std::nextafter(t, INFINITY) - t) / horizon_;
      long double next = std::abs(step) < spacing ? x - std::copysign(spacing, step) : x - step;
      if (!(next > low && next < high) || slope == 0) next = 0.5L * (low + high);
      x = next;
    }
    PolynomialRoot root;
    root.time = static_cast<double>(0.5L * (low + high) * horizon_);
    root.simple = true;
    root.falling = start_sign > 0;
    return root;
  }

  /// A double root of the piece at `at`, unless `may_hold` refuses the piece.
  std::optional<PolynomialRoot> doubleRoot(const Piece& piece, long double at) const {
    if (!mayHold(piece.low, piece.high)) return std::nullopt;
    PolynomialRoot root;
    root.time = static_cast<double>(at * horizon_);
    root.simple = false;
    root.falling = polynomialSlope(scaled_, at) <= piece.error;
    return root;
  }

  /// Where |p| is least on the piece: its slope's sign change if it has one (a near-square's
  /// touch), else the end nearer 0.
  long double leastOn(const Piece& piece) const {
    if (polynomialSlope(scaled_, piece.low) < 0 && polynomialSlope(scaled_, piece.high) > 0) {
      long double falling_end = piece.low, rising_end = piece.high;
      for (int iteration = 0; iteration < 64; ++iteration) {
        const long double middle = 0.5L * (falling_end + rising_end);
        (polynomialSlope(scaled_, middle) < 0 ? falling_end : rising_end) = middle;
      }
      return 0.5L * (falling_end + rising_end);
    }
    return std::abs(polynomialValue(scaled_, piece.low)) <=
                   std::abs(polynomialValue(scaled_, piece.high))
               ? piece.low
               : piece.high;
  }

  /// Too short to divide: two doubles of t wide where it ends (and no less than the smallest
  /// double of time), or the stack is full.
  bool tooShort(const Piece& piece) const {
    const long double width = (piece.high - piece.low) * horizon_;
    return width <= 4 * std::numeric_limits<double>::epsilon() * (piece.high * horizon_) +
                        std::numeric_limits<double>::denorm_min() ||
           waiting_ + 2 > stack_.size();
  }

  /// Clipped from both ends where the hull shows no root (converging on a simple root
  /// quadratically, and on one a trillionth of the way into the piece at once); halved where
  /// clipping cuts less than half (more than one root, or a double one).
  void divide(const Piece& piece) {
    long double from = rootFreeStart(piece.b, degree_, piece.error);
    std::array<long double, kMaxDegree + 1> reversed;
    for (std::size_t i = 0; i <= degree_; ++i) reversed[i] = piece.b[degree_ - i];
    long double to = 1 - rootFreeStart(reversed, degree_, piece.error);
    // A little less than the hull allows: the fractions are rounded.
    from = std::max(0.0L, from - 1e-12L);
    to = std::min(1.0L, to + 1e-12L);
    if (!(from < to)) return;  // no root on the piece
    const long double width = piece.high - piece.low;
    if (to - from <= 0.5L) {
      stack_[waiting_++] =
          pieceOf(scaled_, degree_, piece.low + from * width, piece.low + to * width);
      return;
    }
    const long double middle = piece.low + 0.5L * width;
    stack_[waiting_++] = pieceOf(scaled_, degree_, middle, piece.high);
    stack_[waiting_++] = pieceOf(scaled_, degree_, piece.low, middle);
  }

  /// A piece too short to divide. Where p's values at its ends differ in sign, a root crosses
  /// here (on a split's point, or at the end of the horizon): polished as any. Otherwise a double
  /// root only where p is within its rounding of 0 here (its control points alone may straddle 0
  /// where p does not).
  std::optional<PolynomialRoot> onShortPiece(const Piece& piece) const {
    const long double at_low = polynomialValue(scaled_, piece.low);
    const long double at_high = polynomialValue(scaled_, piece.high);
    const int low_sign = signOf(at_low, 0), high_sign = signOf(at_high, 0);
    if (low_sign != 0 && high_sign != 0 && low_sign != high_sign) {
      return polish(piece.low, piece.high, low_sign);
    }
    const long double middle = 0.5L * (piece.low + piece.high);
    const long double at_middle = polynomialValue(scaled_, middle);
    if (std::min({std::abs(at_low), std::abs(at_middle), std::abs(at_high)}) > piece.error) {
      return std::nullopt;
    }
    return doubleRoot(piece, middle);
  }

  bool mayHold(long double low, long double high) const {
    return !may_hold_ ||
           may_hold_(static_cast<double>(low * horizon_), static_cast<double>(high * horizon_));
  }

  std::vector<long double> scaled_;  ///< a_k = c_k horizon^k: p on u in [0, 1]
  std::size_t degree_;
  double horizon_;
  const std::function<bool(double, double)>& may_hold_;
  std::array<Piece, kMaxLevels> stack_;
  std::size_t waiting_ = 0;
  int looked_at_ = 0;
};

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
  std::vector<long double> scaled(degree + 1);
  long double power = 1, size = 0;
  for (std::size_t k = 0; k <= degree; ++k) {
    scaled[k] = coefficients[k] * power;
    power *= horizon;
    size += std::abs(scaled[k]);
  }
  if (!std::isfinite(size) || !(size > 0)) return std::nullopt;
  RootSearch search(std::move(scaled), degree, horizon, may_hold);
  while (const auto piece = search.next()) {
    const auto root = search.examine(*piece);
    if (root && visit(*root)) return root;
  }
  return std::nullopt;
}

}  // namespace collision_response::core
