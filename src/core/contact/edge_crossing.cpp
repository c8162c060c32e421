// A body's edge or rim crossing a fixed line (edge_crossing.h).
#include "contact/edge_crossing.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace collision_response::core {

namespace {

using Vec = Eigen::Vector3d;

/// The crossing at X on a feature of unit tangent `t` and curvature vector `kappa` there: its
/// normal from the line into the body (towards the centre of mass: the body is on one side of
/// the plane through the feature's tangent and the line, the line touching it), the gap, and how
/// X and the normal move (edge_crossing.h).
std::optional<LineCrossing> completed(const Vec& x, const Vec& t, const Vec& kappa, double inside,
                                      const BodyRates& body, const FaceEdge& line) {
  const Vec& a = line.along;
  const Vec cross = t.cross(a);
  const double length = cross.norm();
  if (!(length > 1e-9)) return std::nullopt;
  LineCrossing c;
  c.point = x;
  c.tangent = t;
  c.inside = inside;
  c.on_line = a.dot(x - line.point);
  c.on = line.point + c.on_line * a;
  const double sign = cross.dot(body.centre - x) >= 0 ? 1.0 : -1.0;
  c.normal = sign * cross / length;
  c.gap = c.normal.dot(x - c.on);
  // lambda' a - s' t = V in the plane at right angles to the normal (a and t span it).
  const Vec velocity = body.velocity + body.spin.cross(x - body.centre);
  const double b = a.dot(t), det = 1.0 - b * b;
  const double line_rate = (a.dot(velocity) - b * t.dot(velocity)) / det;
  c.along_feature = (b * a.dot(velocity) - t.dot(velocity)) / det;
  c.over = line_rate * a - velocity;
  const Vec tangent_rate = body.spin.cross(t) + c.along_feature * kappa;
  const Vec bent = tangent_rate.cross(a) / length;
  c.normal_rate = sign * (bent - c.normal.dot(bent) * c.normal);
  return c;
}

}  // namespace

std::optional<LineCrossing> segmentCrossing(const Vec& p0, const Vec& p1, const BodyRates& body,
                                            const FaceEdge& line) {
  const Vec d = p1 - p0;
  const double length = d.norm();
  if (!(length > 0)) return std::nullopt;
  const Vec t = d / length;
  const Vec& a = line.along;
  // The nearest points of p0 + mu t and E + lambda a: t.(w0 + mu t - lambda a) = 0 and
  // a.(w0 + mu t - lambda a) = 0, w0 = p0 - E.
  const Vec w0 = p0 - line.point;
  const double b = t.dot(a), det = 1.0 - b * b;
  if (!(det > 1e-18)) return std::nullopt;
  const double mu = (b * a.dot(w0) - t.dot(w0)) / det;
  auto c = completed(p0 + mu * t, t, Vec::Zero(), std::min(mu, length - mu), body, line);
  if (c) c->entering = mu <= length - mu ? c->along_feature > 0 : c->along_feature < 0;
  return c;
}

std::optional<LineCrossing> rimCrossing(const Vec& centre, const Vec& axis, const Vec& u,
                                        double radius, int side, const BodyRates& body,
                                        const FaceEdge& line) {
  const Vec v = axis.cross(u);
  // The line's shadow on the rim's plane, and its chord's end on `side`.
  const Vec point = line.point - axis.dot(line.point - centre) * axis;
  const Vec shadow = line.along - axis.dot(line.along) * axis;
  if (!(shadow.norm() > 1e-9)) return std::nullopt;
  const Vec along = shadow.normalized();
  const Vec foot = point + along.dot(centre - point) * along;
  const double d = (foot - centre).norm();
  const double inside = radius - d;
  if (!(inside > 0)) return std::nullopt;
  const double half = std::sqrt((radius - d) * (radius + d));
  const Vec end = foot + (side > 0 ? half : -half) * along;
  double theta = std::atan2((end - centre).dot(v), (end - centre).dot(u));
  // Newton on f(theta) = Q_perp.t (Q = X - E, its part across the line): the common
  // perpendicular's condition; f' = rho (1 - (t.a)^2) - Q_perp.(X - C) / rho.
  const Vec& a = line.along;
  for (int i = 0; i < 8; ++i) {
    const Vec radial = std::cos(theta) * u + std::sin(theta) * v;
    const Vec t = -std::sin(theta) * u + std::cos(theta) * v;
    const Vec q = centre + radius * radial - line.point;
    const Vec across = q - a.dot(q) * a;
    const double f = across.dot(t);
    const double slope = radius * (1.0 - a.dot(t) * a.dot(t)) - across.dot(radial);
    if (!(std::abs(slope) > 0)) break;
    const double step = f / slope;
    theta -= step;
    if (std::abs(step) <= 1e-16) break;
  }
  const Vec radial = std::cos(theta) * u + std::sin(theta) * v;
  const Vec t = -std::sin(theta) * u + std::cos(theta) * v;
  return completed(centre + radius * radial, t, -radial / radius, inside, body, line);
}

}  // namespace collision_response::core
