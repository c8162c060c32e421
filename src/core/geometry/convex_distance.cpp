#include "geometry/convex_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace collision_response::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

template <class... Branches>
struct Dispatch : Branches... {
  using Branches::operator()...;
};
template <class... Branches>
Dispatch(Branches...) -> Dispatch<Branches...>;

double signOrPlus(double x) { return x >= 0 ? 1.0 : -1.0; }

/// A vertex of the simplex: a point w = p_a - p_b of A - B and the two support points.
struct Vertex {
  Eigen::Vector3d w, a, b;
};

/// The simplex (1 to 4 vertices) and the weights of its point nearest the origin.
struct Simplex {
  std::array<Vertex, 4> vertices;
  std::array<double, 4> weights{};
  int size = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< its point nearest the origin
  /// Where that point is inside a triangle: the triangle's normal (towards the triangle from
  /// the origin, not unit); zero otherwise.
  Eigen::Vector3d face_normal = Eigen::Vector3d::Zero();
};

/// Keeps the vertices `keep` (indices) with their weights.
void reduce(Simplex& s, std::initializer_list<std::pair<int, double>> keep) {
  std::array<Vertex, 4> kept;
  std::array<double, 4> weights{};
  int n = 0;
  for (const auto& [index, weight] : keep) {
    kept[static_cast<std::size_t>(n)] = s.vertices[static_cast<std::size_t>(index)];
    weights[static_cast<std::size_t>(n)] = weight;
    ++n;
  }
  s.vertices = kept;
  s.weights = weights;
  s.size = n;
}

/// The point of segment (0, 1) nearest the origin (Ericson 5.1.2).
void nearestOnSegment(Simplex& s) {
  s.face_normal = Eigen::Vector3d::Zero();
  const Eigen::Vector3d a = s.vertices[0].w;
  const Eigen::Vector3d ab = s.vertices[1].w - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0 ? -a.dot(ab) / length2 : 0.0;
  if (t <= 0) {
    reduce(s, {{0, 1.0}});
    s.point = a;
  } else if (t >= 1) {
    reduce(s, {{1, 1.0}});
    s.point = a + ab;
  } else {
    reduce(s, {{0, 1 - t}, {1, t}});
    s.point = a + t * ab;
  }
}

/// The point of triangle (i, j, k) of the simplex nearest the origin, by the triangle's Voronoi
/// regions (Ericson 5.1.5, ClosestPtPointTriangle with p = 0); `out` gets the vertices kept
/// (indices into s) and their weights, and the squared distance is returned.
struct TriangleResult {
  std::array<std::pair<int, double>, 3> kept;
  int size = 0;
  Eigen::Vector3d point;
  Eigen::Vector3d face_normal = Eigen::Vector3d::Zero();  ///< the face's, where it is the nearest
};
TriangleResult nearestOnTriangle(const Simplex& s, int i, int j, int k) {
  const auto& vs = s.vertices;
  const Eigen::Vector3d& a = vs[static_cast<std::size_t>(i)].w;
  const Eigen::Vector3d& b = vs[static_cast<std::size_t>(j)].w;
  const Eigen::Vector3d& c = vs[static_cast<std::size_t>(k)].w;
  TriangleResult r;
  const Eigen::Vector3d ab = b - a, ac = c - a;
  const double d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0 && d2 <= 0) {
    r.kept[0] = {i, 1.0};
    r.size = 1;
    r.point = a;
    return r;
  }
  const double d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0 && d4 <= d3) {
    r.kept[0] = {j, 1.0};
    r.size = 1;
    r.point = b;
    return r;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    r.kept[0] = {i, 1 - t};
    r.kept[1] = {j, t};
    r.size = 2;
    r.point = a + t * ab;
    return r;
  }
  const double d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0 && d5 <= d6) {
    r.kept[0] = {k, 1.0};
    r.size = 1;
    r.point = c;
    return r;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    r.kept[0] = {i, 1 - t};
    r.kept[1] = {k, t};
    r.size = 2;
    r.point = a + t * ac;
    return r;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    r.kept[0] = {j, 1 - t};
    r.kept[1] = {k, t};
    r.size = 2;
    r.point = b + t * (c - b);
    return r;
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) {
    // No area (the points in a line): the nearest of its edges' points.
    TriangleResult best;
    double best_distance = INFINITY;
    for (const auto& [p, q] : {std::pair{i, j}, std::pair{j, k}, std::pair{i, k}}) {
      const Eigen::Vector3d& x = vs[static_cast<std::size_t>(p)].w;
      const Eigen::Vector3d xy = vs[static_cast<std::size_t>(q)].w - x;
      const double length2 = xy.squaredNorm();
      const double t = length2 > 0 ? std::clamp(-x.dot(xy) / length2, 0.0, 1.0) : 0.0;
      const Eigen::Vector3d point = x + t * xy;
      if (point.squaredNorm() < best_distance) {
        best_distance = point.squaredNorm();
        best.kept[0] = {p, 1 - t};
        best.kept[1] = {q, t};
        best.size = 2;
        best.point = point;
      }
    }
    return best;
  }
  const double v = vb / sum, w = vc / sum;
  r.kept[0] = {i, 1 - v - w};
  r.kept[1] = {j, v};
  r.kept[2] = {k, w};
  r.size = 3;
  r.point = a + v * ab + w * ac;
  // The face's normal towards it from the origin, made of the edges alone: v, a sum of the
  // weighted corners (each as large as the shapes), loses its direction to their rounding where
  // it is 1e-10 long, and with it the lower bound a flat face gives (convexDistance).
  const Eigen::Vector3d normal = ab.cross(ac);
  r.face_normal = normal.dot(a) >= 0 ? normal : Eigen::Vector3d(-normal);
  return r;
}

void keepTriangle(Simplex& s, const TriangleResult& r) {
  if (r.size == 1) {
    reduce(s, {r.kept[0]});
  } else if (r.size == 2) {
    reduce(s, {r.kept[0], r.kept[1]});
  } else {
    reduce(s, {r.kept[0], r.kept[1], r.kept[2]});
  }
  s.point = r.point;
  s.face_normal = r.face_normal;
}

/// The tetrahedron's point nearest the origin (Ericson 5.1.6): the nearest over the faces the
/// origin is outside of; none (the origin inside): returns false.
bool nearestOnTetrahedron(Simplex& s) {
  const auto& vs = s.vertices;
  const std::array<std::array<int, 4>, 4> faces{
      {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}}};
  const double volume = (vs[1].w - vs[0].w).cross(vs[2].w - vs[0].w).dot(vs[3].w - vs[0].w);
  double scale = 0;
  for (int i = 1; i < 4; ++i)
    scale = std::max(scale, (vs[static_cast<std::size_t>(i)].w - vs[0].w).norm());
  const bool flat = !(std::abs(volume) > 64 * kEps * scale * scale * scale);
  TriangleResult best;
  double best_distance = INFINITY;
  for (const auto& f : faces) {
    const Eigen::Vector3d& a = vs[static_cast<std::size_t>(f[0])].w;
    const Eigen::Vector3d normal =
        (vs[static_cast<std::size_t>(f[1])].w - a).cross(vs[static_cast<std::size_t>(f[2])].w - a);
    const double origin_side = -a.dot(normal);
    const double other_side = (vs[static_cast<std::size_t>(f[3])].w - a).dot(normal);
    if (!flat && !(origin_side * other_side < 0)) continue;
    const TriangleResult r = nearestOnTriangle(s, f[0], f[1], f[2]);
    if (r.point.squaredNorm() < best_distance) {
      best_distance = r.point.squaredNorm();
      best = r;
    }
  }
  if (best.size == 0) return false;
  keepTriangle(s, best);
  return true;
}

}  // namespace

Eigen::Vector3d coreSupport(const ConvexShape& shape, const Eigen::Vector3d& d) {
  return std::visit(Dispatch{[](const Sphere& sphere) -> Eigen::Vector3d { return sphere.centre; },
                             [&](const Cuboid& box) -> Eigen::Vector3d {
                               return Eigen::Vector3d(signOrPlus(d.x()) * box.half_size.x(),
                                                      signOrPlus(d.y()) * box.half_size.y(),
                                                      signOrPlus(d.z()) * box.half_size.z());
                             },
                             [&](const Cylinder& cylinder) -> Eigen::Vector3d {
                               const double across = std::hypot(d.x(), d.y());
                               Eigen::Vector3d s(0, 0, signOrPlus(d.z()) * cylinder.half_length);
                               if (across > 0) {
                                 s.x() = cylinder.radius * (d.x() / across);
                                 s.y() = cylinder.radius * (d.y() / across);
                               }
                               return s;
                             },
                             [&](const Capsule& capsule) -> Eigen::Vector3d {
                               return Eigen::Vector3d(0, 0,
                                                      signOrPlus(d.z()) * capsule.half_length);
                             },
                             [&](const ConvexHull& hull) -> Eigen::Vector3d {
                               Eigen::Vector3d best = hull.vertices.front();
                               double best_dot = best.dot(d);
                               for (const Eigen::Vector3d& v : hull.vertices) {
                                 const double dot = v.dot(d);
                                 if (dot > best_dot) {
                                   best_dot = dot;
                                   best = v;
                                 }
                               }
                               return best;
                             }},
                    shape);
}

double marginOf(const ConvexShape& shape) {
  if (const auto* sphere = std::get_if<Sphere>(&shape)) return sphere->radius;
  if (const auto* capsule = std::get_if<Capsule>(&shape)) return capsule->radius;
  return 0.0;
}

double reachOf(const ConvexShape& shape) {
  return std::visit(
      Dispatch{[](const Sphere& sphere) { return sphere.centre.norm() + sphere.radius; },
               [](const Cuboid& box) { return box.half_size.norm(); },
               [](const Cylinder& cylinder) {
                 return std::hypot(cylinder.radius, cylinder.half_length);
               },
               [](const Capsule& capsule) { return capsule.half_length + capsule.radius; },
               [](const ConvexHull& hull) {
                 double reach = 0;
                 for (const Eigen::Vector3d& v : hull.vertices) reach = std::max(reach, v.norm());
                 return reach;
               }},
      shape);
}

void contactCandidates(const ConvexShape& shape, const Eigen::Vector3d& d,
                       std::vector<Eigen::Vector3d>& out) {
  const double length = d.norm();
  const Eigen::Vector3d unit = length > 0 ? Eigen::Vector3d(d / length) : Eigen::Vector3d::Zero();
  std::visit(
      Dispatch{[&](const Sphere& sphere) { out.push_back(sphere.centre + sphere.radius * unit); },
               [&](const Cuboid& box) {
                 for (int corner = 0; corner < 8; ++corner) {
                   out.emplace_back((corner & 1 ? 1 : -1) * box.half_size.x(),
                                    (corner & 2 ? 1 : -1) * box.half_size.y(),
                                    (corner & 4 ? 1 : -1) * box.half_size.z());
                 }
               },
               [&](const Cylinder& cylinder) {
                 const double across = std::hypot(d.x(), d.y());
                 Eigen::Vector2d u(1, 0);
                 if (across > 0) u = Eigen::Vector2d(d.x() / across, d.y() / across);
                 const Eigen::Vector2d u_perp(-u.y(), u.x());
                 for (const double z : {-cylinder.half_length, cylinder.half_length}) {
                   for (const Eigen::Vector2d& r :
                        {u, u_perp, Eigen::Vector2d(-u), Eigen::Vector2d(-u_perp)}) {
                     out.emplace_back(cylinder.radius * r.x(), cylinder.radius * r.y(), z);
                   }
                 }
               },
               [&](const Capsule& capsule) {
                 for (const double z : {-capsule.half_length, capsule.half_length}) {
                   out.push_back(Eigen::Vector3d(0, 0, z) + capsule.radius * unit);
                 }
               },
               [&](const ConvexHull& hull) {
                 out.insert(out.end(), hull.vertices.begin(), hull.vertices.end());
               }},
      shape);
}

Eigen::Vector3d TriangleSupport::support(const Eigen::Vector3d& d) const {
  const double d0 = corners_[0].dot(d), d1 = corners_[1].dot(d), d2 = corners_[2].dot(d);
  if (d0 >= d1 && d0 >= d2) return corners_[0];
  return d1 >= d2 ? corners_[1] : corners_[2];
}

double TriangleSupport::scale() const {
  return std::max({corners_[0].norm(), corners_[1].norm(), corners_[2].norm()});
}

namespace {

/// What the search for the cores' distance knows: its simplex, the simplex's nearest point v,
/// the best lower bound and its direction, whether the cores overlap, the iterations, and the
/// witness points on each core.
struct DistanceSearch {
  Simplex s;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  double lower = 0.0;
  Eigen::Vector3d lower_direction = Eigen::Vector3d::Zero();  // the lower bound's
  bool overlapping = false;
  int iteration = 0;
  Eigen::Vector3d core_a = Eigen::Vector3d::Zero(), core_b = Eigen::Vector3d::Zero();

  void bound(double value, const Eigen::Vector3d& along) {
    if (value > lower) {
      lower = value;
      lower_direction = along;
    }
  }
};

/// GJK's iterations from the support points along `direction`, until the bounds meet within
/// `tolerance`, no new support point comes, no progress is made, or the origin is found on or in
/// the simplex (the cores overlap).
void gjk(const SupportMapping& a, const SupportMapping& b, const Eigen::Vector3d& direction,
         double tolerance, double slack, int max_iterations, DistanceSearch& search) {
  Simplex& s = search.s;
  {
    const Eigen::Vector3d pa = a.support(direction), pb = b.support(-direction);
    s.vertices[0] = {pa - pb, pa, pb};
    s.weights[0] = 1.0;
    s.size = 1;
    s.point = s.vertices[0].w;
  }
  Eigen::Vector3d& v = search.v;
  v = s.vertices[0].w;
  for (; search.iteration < max_iterations; ++search.iteration) {
    const double vv = v.squaredNorm();
    if (!(vv > slack * slack)) {
      search.overlapping = true;  // the origin on the simplex, within rounding: the cores touch
      return;
    }
    const double v_norm = std::sqrt(vv);
    const Eigen::Vector3d pa = a.support(-v), pb = b.support(v);
    const Eigen::Vector3d w = pa - pb;
    const double vw = v.dot(w);
    search.bound(vw / v_norm, v / v_norm);
    if (v_norm - search.lower <= tolerance) return;
    bool repeated = false;
    for (int i = 0; i < s.size; ++i) {
      if (s.vertices[static_cast<std::size_t>(i)].w == w) repeated = true;
    }
    if (repeated || vv - vw <= 4 * kEps * vv) return;  // no new point: as near as it gets
    s.vertices[static_cast<std::size_t>(s.size)] = {w, pa, pb};
    ++s.size;
    if (s.size == 2) {
      nearestOnSegment(s);
    } else if (s.size == 3) {
      keepTriangle(s, nearestOnTriangle(s, 0, 1, 2));
    } else if (!nearestOnTetrahedron(s)) {
      search.overlapping = true;  // the origin inside the tetrahedron: the cores overlap
      return;
    }
    const Eigen::Vector3d next = s.point;
    if (s.face_normal.squaredNorm() > 0) {
      // A second lower bound along the face's normal (any direction gives one): exact for a
      // polytope's face however near the origin.
      const Eigen::Vector3d d = s.face_normal.normalized();
      search.bound(d.dot(Eigen::Vector3d(a.support(-d) - b.support(d))), d);
    }
    if (!(next.squaredNorm() < vv)) return;  // no progress (rounding): keep the last v
    v = next;
  }
}

/// The witness points on each core: the simplex's vertices' points by their weights.
void witnessPoints(DistanceSearch& search) {
  const Simplex& s = search.s;
  double weight_sum = 0;
  for (int i = 0; i < s.size; ++i) weight_sum += s.weights[static_cast<std::size_t>(i)];
  for (int i = 0; i < s.size; ++i) {
    const double weight = s.weights[static_cast<std::size_t>(i)] / weight_sum;
    search.core_a += weight * s.vertices[static_cast<std::size_t>(i)].a;
    search.core_b += weight * s.vertices[static_cast<std::size_t>(i)].b;
  }
}

/// Where GJK did not converge (near touching a round side the simplex's corners crowd together
/// and its nearest point stops coming nearer to rounding): Frank-Wolfe steps from there (x the
/// point of A - B, moved to the nearest point of the segment to the support point w in the
/// direction -x: nearer at every step, no simplex to round), each w bounding the distance from
/// below by x.w / |x|; the witness points move along.
void frankWolfe(const SupportMapping& a, const SupportMapping& b, double tolerance, double slack,
                DistanceSearch& search) {
  Eigen::Vector3d x = search.core_a - search.core_b;
  for (int step = 0; step < 64 && !(x.norm() - search.lower <= tolerance); ++step) {
    const double x_norm = x.norm();
    if (!(x_norm > slack)) break;
    const Eigen::Vector3d pa = a.support(-x), pb = b.support(x);
    const Eigen::Vector3d w = pa - pb;
    search.bound(x.dot(w) / x_norm, x / x_norm);
    const Eigen::Vector3d d = w - x;
    const double length2 = d.squaredNorm();
    if (!(length2 > 0)) break;
    const double t = std::min(1.0, -x.dot(d) / length2);
    if (!(t > 0)) break;
    search.core_a += t * (pa - search.core_a);
    search.core_b += t * (pb - search.core_b);
    x = search.core_a - search.core_b;
    ++search.iteration;
  }
  search.v = x;
}

/// The answer from the search: the normal along the best lower bound (a face's normal is known to
/// the shapes' relative rounding even where the distance is 1e-10, v's direction or the witness
/// points' difference only to their absolute rounding), the bounds less the margins, the
/// surface points.
ConvexDistance answerOf(const DistanceSearch& search, const SupportMapping& a,
                        const SupportMapping& b, const Eigen::Vector3d& direction, double slack) {
  ConvexDistance result;
  result.iterations = search.iteration;
  const double margins = a.margin() + b.margin();
  // The closest points are points of the cores: their distance bounds the cores' from above.
  const Eigen::Vector3d between = search.core_b - search.core_a;
  const double apart = between.norm();
  if (search.lower_direction.squaredNorm() > 0) {
    result.normal = -search.lower_direction;
  } else if (search.v.norm() > 0) {
    result.normal = -search.v.normalized();
  } else if (apart > 0) {
    result.normal = between / apart;
  } else {
    result.normal = direction.normalized();
  }
  result.overlapping = search.overlapping;
  if (search.overlapping) {
    result.lower = -INFINITY;
    result.upper = slack - margins;
  } else {
    result.lower = std::min(search.lower, apart) - slack - margins;
    result.upper = apart + slack - margins;
  }
  result.point_a = search.core_a + a.margin() * result.normal;
  result.point_b = search.core_b - b.margin() * result.normal;
  return result;
}

}  // namespace

ConvexDistance convexDistance(const SupportMapping& a, const SupportMapping& b, double tolerance,
                              int max_iterations) {
  // The rounding of a support point (a rotation and a translation of the shape's point) and of
  // the dot products below: a few ulps of the sets' sizes and positions.
  const double slack = 64 * kEps * (a.scale() + b.scale());
  Eigen::Vector3d direction = b.centre() - a.centre();  // from a towards b
  if (!(direction.squaredNorm() > 0)) direction = Eigen::Vector3d::UnitZ();
  DistanceSearch search;
  gjk(a, b, direction, tolerance, slack, max_iterations, search);
  witnessPoints(search);
  if (!search.overlapping && search.v.norm() - search.lower > tolerance) {
    frankWolfe(a, b, tolerance, slack, search);
  }
  return answerOf(search, a, b, direction, slack);
}

}  // namespace collision_response::core
