#include "collision_response/core/mass_properties.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <variant>

#include "collision_response/core/triangle_mesh.h"
#include "collision_response/core/validation.h"

// qhull's reentrant C library (Debian's libqhull-dev; its header declares itself extern "C").
#include <libqhull_r/libqhull_r.h>

namespace collision_response::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kPi = 3.14159265358979323846;

template <class... Ts>
struct Dispatch : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Dispatch(Ts...) -> Dispatch<Ts...>;

MassProperties diagonal(double mass, double volume, double ixx, double iyy, double izz) {
  MassProperties properties;
  properties.mass = mass;
  properties.volume = volume;
  properties.inertia = Eigen::Vector3d(ixx, iyy, izz).asDiagonal();
  return properties;
}

/// Eberly's subexpressions of one coordinate w0, w1, w2 of a triangle's vertices: the sums f1,
/// f2, f3 and g0, g1, g2 the face integrals are made of ("Polyhedral Mass Properties
/// (Revisited)", 2002).
struct Subexpressions {
  double f1, f2, f3, g0, g1, g2;
};
Subexpressions subexpressions(double w0, double w1, double w2) {
  const double temp0 = w0 + w1;
  const double temp1 = w0 * w0;
  const double temp2 = temp1 + w1 * temp0;
  Subexpressions s;
  s.f1 = temp0 + w2;
  s.f2 = temp2 + w2 * s.f1;
  s.f3 = w0 * temp1 + w1 * temp2 + w2 * s.f2;
  s.g0 = s.f2 + w0 * (s.f1 + w0);
  s.g1 = s.f2 + w1 * (s.f1 + w1);
  s.g2 = s.f2 + w2 * (s.f1 + w2);
  return s;
}

/// qhull's messages go to a FILE; this one keeps them in memory for the error (open_memstream).
class MessageStream {
 public:
  MessageStream() : file_(open_memstream(&buffer_, &size_)) {}
  ~MessageStream() {
    if (file_ != nullptr) std::fclose(file_);
    std::free(buffer_);
  }
  MessageStream(const MessageStream&) = delete;
  MessageStream& operator=(const MessageStream&) = delete;
  FILE* file() const { return file_; }
  /// The first line written so far (qhull's error, e.g. "QH6214 qhull input error: ...").
  std::string firstLine() {
    if (file_ == nullptr) return "";
    std::fflush(file_);
    const std::string text(buffer_ == nullptr ? "" : buffer_, size_);
    const std::size_t start = text.find_first_not_of(" \n");
    if (start == std::string::npos) return "";
    return text.substr(start, text.find('\n', start) - start);
  }

 private:
  char* buffer_ = nullptr;
  std::size_t size_ = 0;
  FILE* file_ = nullptr;
};

/// One run of qhull, its memory freed however it ends.
class Qhull {
 public:
  explicit Qhull(FILE* errors) { qh_zero(&qh_, errors); }
  ~Qhull() {
    qh_freeqhull(&qh_, !qh_ALL);
    int current_long = 0, total_long = 0;
    qh_memfreeshort(&qh_, &current_long, &total_long);
  }
  Qhull(const Qhull&) = delete;
  Qhull& operator=(const Qhull&) = delete;
  qhT* get() { return &qh_; }

 private:
  qhT qh_{};
};

}  // namespace

Eigen::Matrix3d InertiaTensor::matrix() const {
  Eigen::Matrix3d m;
  m << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  return m;
}

InertiaTensor InertiaTensor::fromMatrix(const Eigen::Matrix3d& m) {
  InertiaTensor tensor;
  tensor.ixx = m(0, 0);
  tensor.iyy = m(1, 1);
  tensor.izz = m(2, 2);
  tensor.ixy = m(0, 1);
  tensor.ixz = m(0, 2);
  tensor.iyz = m(1, 2);
  return tensor;
}

MassProperties sphereMassProperties(double mass, double radius, Inertia inertia) {
  // I = k m r^2 with 1/k = spinFactor (5/2 solid, 3/2 hollow): one place holds the factors.
  const double factor = spinFactor(1.0, 1.0, inertia);
  const double moment = mass * radius * radius / factor;
  return diagonal(mass, 4.0 / 3.0 * kPi * radius * radius * radius, moment, moment, moment);
}

MassProperties solidMassProperties(const Cuboid& box, double mass) {
  const Eigen::Vector3d edges = 2.0 * box.half_size;
  const Eigen::Vector3d squares = edges.cwiseProduct(edges);
  return diagonal(mass, edges.prod(), mass / 12.0 * (squares.y() + squares.z()),
                  mass / 12.0 * (squares.x() + squares.z()),
                  mass / 12.0 * (squares.x() + squares.y()));
}

MassProperties solidMassProperties(const Cylinder& cylinder, double mass) {
  const double r = cylinder.radius, h = 2.0 * cylinder.half_length;
  const double transverse = mass * (3.0 * r * r + h * h) / 12.0;
  return diagonal(mass, kPi * r * r * h, transverse, transverse, mass * r * r / 2.0);
}

MassProperties solidMassProperties(const Capsule& capsule, double mass) {
  const double r = capsule.radius, h = 2.0 * capsule.half_length;
  // The volumes pi r^2 h and 4/3 pi r^3 share the mass; pi cancels from the shares.
  const double cylinder_mass = mass * h / (h + 4.0 / 3.0 * r);
  const double spheres_mass = mass * (4.0 / 3.0 * r) / (h + 4.0 / 3.0 * r);
  const double axial = cylinder_mass * r * r / 2.0 + 2.0 / 5.0 * spheres_mass * r * r;
  const double transverse = cylinder_mass * (3.0 * r * r + h * h) / 12.0 +
                            spheres_mass * (2.0 / 5.0 * r * r + h * h / 4.0 + 3.0 / 8.0 * h * r);
  return diagonal(mass, kPi * r * r * (h + 4.0 / 3.0 * r), transverse, transverse, axial);
}

Expected<Polyhedron> convexHull(const std::vector<Eigen::Vector3d>& points,
                                const std::string& field) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (auto status = checkFinite(points[i], field + "[" + std::to_string(i) + "]"); !status) {
      return status.error();
    }
  }
  if (points.size() < 4) {
    return Error{field, "has " + std::to_string(points.size()) +
                            " points: a hull that encloses a volume needs at least four"};
  }
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    return Error{field, "has more points than qhull takes (" + std::to_string(points.size()) + ")"};
  }
  // One point however often repeated: qhull finds no width to measure its rounding by and stops
  // with an internal error rather than its singular one.
  if (std::all_of(points.begin(), points.end(),
                  [&](const Eigen::Vector3d& point) { return point == points.front(); })) {
    return Error{field,
                 "spans no volume: its points are all one point " + formatVector(points.front())};
  }
  std::vector<coordT> coordinates;
  coordinates.reserve(3 * points.size());
  for (const Eigen::Vector3d& point : points) {
    coordinates.insert(coordinates.end(), {point.x(), point.y(), point.z()});
  }
  MessageStream messages;
  Qhull qhull(messages.file());
  qhT* qh = qhull.get();
  // Qt: the hull's facets triangulated (a box's faces come as two triangles each). qhull's
  // default merging of facets within its rounding keeps the hull convex and its faces flat.
  char command[] = "qhull Qt";
  const int exit_code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coordinates.data(),
                                     False, command, nullptr, messages.file());
  if (exit_code == qh_ERRsingular) {
    return Error{field,
                 "spans no volume: its points lie on one plane, one line or at one point, to "
                 "qhull's rounding (a hull needs thickness in every direction)"};
  }
  if (exit_code != qh_ERRnone) {
    return Error{field, "qhull could not compute its convex hull: " + messages.firstLine()};
  }
  Polyhedron hull;
  std::unordered_map<int, std::uint32_t> hull_index;  // qhull's point id -> the hull's vertex
  const auto vertexOf = [&](vertexT* vertex) {
    const int id = qh_pointid(qh, vertex->point);
    const auto [where, added] =
        hull_index.emplace(id, static_cast<std::uint32_t>(hull.vertices.size()));
    if (added) hull.vertices.push_back(points[static_cast<std::size_t>(id)]);
    return where->second;
  };
  facetT* facet = nullptr;
  FORALLfacets {
    if (facet->vertices == nullptr || qh_setsize(qh, facet->vertices) != 3) continue;
    std::array<std::uint32_t, 3> triangle{};
    for (int k = 0; k < 3; ++k) {
      triangle[static_cast<std::size_t>(k)] =
          vertexOf(static_cast<vertexT*>(facet->vertices->e[k].p));
    }
    // Wound so that its normal points where qhull's outward normal does.
    const Eigen::Vector3d& a = hull.vertices[triangle[0]];
    const Eigen::Vector3d& b = hull.vertices[triangle[1]];
    const Eigen::Vector3d& c = hull.vertices[triangle[2]];
    const Eigen::Vector3d outward(facet->normal[0], facet->normal[1], facet->normal[2]);
    if ((b - a).cross(c - a).dot(outward) < 0) std::swap(triangle[1], triangle[2]);
    hull.triangles.push_back(triangle);
  }
  if (hull.triangles.size() < 4) {
    return Error{
        field, "spans no volume: its hull has " + std::to_string(hull.triangles.size()) + " faces"};
  }
  return hull;
}

Expected<MassProperties> polyhedronMassProperties(const Polyhedron& polyhedron, double mass,
                                                  const std::string& field) {
  const std::vector<Eigen::Vector3d>& vertices = polyhedron.vertices;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (auto status = checkFinite(vertices[i], field + ".vertices[" + std::to_string(i) + "]");
        !status) {
      return status.error();
    }
  }
  if (vertices.empty() || polyhedron.triangles.empty()) {
    return Error{field, "has no triangles: it encloses no volume"};
  }
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& vertex : vertices) reference += vertex;
  reference /= static_cast<double>(vertices.size());

  // The integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the solid (unit density), about
  // `reference` (Eberly's Compute).
  std::array<double, 10> integral{};
  for (std::size_t t = 0; t < polyhedron.triangles.size(); ++t) {
    const auto& triangle = polyhedron.triangles[t];
    for (const std::uint32_t index : triangle) {
      if (index >= vertices.size()) {
        return Error{field + ".triangles[" + std::to_string(t) + "]",
                     "vertex index " + std::to_string(index) + " is out of range (" +
                         std::to_string(vertices.size()) + " vertices)"};
      }
    }
    const Eigen::Vector3d p0 = vertices[triangle[0]] - reference;
    const Eigen::Vector3d p1 = vertices[triangle[1]] - reference;
    const Eigen::Vector3d p2 = vertices[triangle[2]] - reference;
    const Eigen::Vector3d d = (p1 - p0).cross(p2 - p0);
    const Subexpressions x = subexpressions(p0.x(), p1.x(), p2.x());
    const Subexpressions y = subexpressions(p0.y(), p1.y(), p2.y());
    const Subexpressions z = subexpressions(p0.z(), p1.z(), p2.z());
    integral[0] += d.x() * x.f1;
    integral[1] += d.x() * x.f2;
    integral[2] += d.y() * y.f2;
    integral[3] += d.z() * z.f2;
    integral[4] += d.x() * x.f3;
    integral[5] += d.y() * y.f3;
    integral[6] += d.z() * z.f3;
    integral[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
    integral[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
    integral[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
  }
  constexpr std::array<double, 10> kFactor = {1.0 / 6,  1.0 / 24, 1.0 / 24,  1.0 / 24,  1.0 / 60,
                                              1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (std::size_t k = 0; k < integral.size(); ++k) integral[k] *= kFactor[k];

  const double volume = integral[0];
  if (!(volume > 0)) {
    return Error{field, "encloses no volume (" + formatNumber(volume) +
                            " m^3: its triangles are not closed, or are wound inwards)"};
  }
  const Eigen::Vector3d centroid = Eigen::Vector3d(integral[1], integral[2], integral[3]) / volume;
  // Second moments about the centroid, integral of x^2 dV - V cx^2, ...
  const double xx = integral[4] - volume * centroid.x() * centroid.x();
  const double yy = integral[5] - volume * centroid.y() * centroid.y();
  const double zz = integral[6] - volume * centroid.z() * centroid.z();
  const double xy = integral[7] - volume * centroid.x() * centroid.y();
  const double yz = integral[8] - volume * centroid.y() * centroid.z();
  const double zx = integral[9] - volume * centroid.z() * centroid.x();
  const double density = mass / volume;
  MassProperties properties;
  properties.mass = mass;
  properties.volume = volume;
  properties.centre_of_mass = reference + centroid;
  properties.inertia << density * (yy + zz), -density * xy, -density * zx,  //
      -density * xy, density * (xx + zz), -density * yz,                    //
      -density * zx, -density * yz, density * (xx + yy);
  return properties;
}

double surfaceArea(const Polyhedron& polyhedron) {
  double twice = 0.0;
  for (const auto& t : polyhedron.triangles) {
    const Eigen::Vector3d& a = polyhedron.vertices[t[0]];
    twice += (polyhedron.vertices[t[1]] - a).cross(polyhedron.vertices[t[2]] - a).norm();
  }
  return 0.5 * twice;
}

double meanCrossSection(const Shape& shape) {
  return std::visit(
      Dispatch{
          [](const Plane&) { return 0.0; },
          [](const Sphere& sphere) { return kPi * sphere.radius * sphere.radius; },
          [](const Cuboid& box) {
            const Eigen::Vector3d& h = box.half_size;
            return 2.0 * (h.x() * h.y() + h.y() * h.z() + h.z() * h.x());
          },
          [](const Cylinder& c) { return 0.5 * kPi * c.radius * (c.radius + 2 * c.half_length); },
          [](const Capsule& c) { return kPi * c.radius * (c.radius + c.half_length); },
          [](const Mesh& mesh) {
            if (mesh.triangles == nullptr) return 0.0;
            const auto hull = convexHull(mesh.triangles->vertices(), "mesh");
            return hull ? 0.25 * surfaceArea(*hull) : 0.0;
          }},
      shape);
}

Expected<MassProperties> uniformMassProperties(const Shape& shape, double mass,
                                               Inertia sphere_inertia, const std::string& field) {
  if (!std::isfinite(mass) || !(mass > 0)) {
    return Error{field, "a uniform solid's mass properties need a finite mass > 0 kg, got " +
                            formatNumber(mass) + " (an immovable body turns by no inertia)"};
  }
  auto properties =
      std::visit(Dispatch{[&](const Plane&) -> Expected<MassProperties> {
                            return Error{field, "a plane is unbounded: no body has its shape"};
                          },
                          [&](const Sphere& sphere) -> Expected<MassProperties> {
                            MassProperties sphere_properties =
                                sphereMassProperties(mass, sphere.radius, sphere_inertia);
                            sphere_properties.centre_of_mass = sphere.centre;
                            return sphere_properties;
                          },
                          [&](const Mesh& mesh) -> Expected<MassProperties> {
                            if (mesh.triangles == nullptr) return Error{field, "has no triangles"};
                            const auto hull = convexHull(mesh.triangles->vertices(), field);
                            if (!hull) return hull.error();
                            return polyhedronMassProperties(*hull, mass, field);
                          },
                          [&](const auto& finite) -> Expected<MassProperties> {
                            return solidMassProperties(finite, mass);
                          }},
                 shape);
  if (!properties) return properties;
  if (!(properties->volume > 0)) {
    return Error{field, "encloses no volume (" + formatNumber(properties->volume) +
                            " m^3): a body's shape needs a nonzero size in every direction"};
  }
  if (!std::isfinite(properties->volume) || !properties->inertia.allFinite()) {
    return Error{field,
                 "is too large: its volume or moments of inertia are beyond the range of double"};
  }
  return properties;
}

Status checkInertiaTensor(const InertiaTensor& tensor, const std::string& field) {
  const std::array<std::pair<const char*, double>, 6> entries = {{{"ixx", tensor.ixx},
                                                                  {"iyy", tensor.iyy},
                                                                  {"izz", tensor.izz},
                                                                  {"ixy", tensor.ixy},
                                                                  {"ixz", tensor.ixz},
                                                                  {"iyz", tensor.iyz}}};
  for (const auto& [name, value] : entries) {
    if (!std::isfinite(value)) {
      return Error{field + "." + name,
                   "must be a finite number (kg m^2), got " + formatNumber(value)};
    }
  }
  for (std::size_t k = 0; k < 3; ++k) {
    if (!(entries[k].second > 0)) {
      return Error{field + "." + entries[k].first,
                   "must be > 0 kg m^2 (a moment of inertia about an axis), got " +
                       formatNumber(entries[k].second)};
    }
  }
  // Each 2 x 2 principal minor: the tensor restricted to a plane of two axes is definite only
  // when the product is smaller than the geometric mean of their moments.
  struct Minor {
    const char* product;
    double first, second, value;
    const char* first_name;
    const char* second_name;
  };
  const std::array<Minor, 3> minors = {{{"ixy", tensor.ixx, tensor.iyy, tensor.ixy, "ixx", "iyy"},
                                        {"ixz", tensor.ixx, tensor.izz, tensor.ixz, "ixx", "izz"},
                                        {"iyz", tensor.iyy, tensor.izz, tensor.iyz, "iyy", "izz"}}};
  for (const Minor& minor : minors) {
    // |p| < sqrt(a) sqrt(b), without the overflow of a b.
    if (!(std::abs(minor.value) < std::sqrt(minor.first) * std::sqrt(minor.second))) {
      return Error{field + "." + minor.product,
                   "makes the tensor not positive definite: |" + std::string(minor.product) +
                       "| = " + formatNumber(std::abs(minor.value)) + " must be below sqrt(" +
                       minor.first_name + " " + minor.second_name +
                       ") = " + formatNumber(std::sqrt(minor.first) * std::sqrt(minor.second))};
    }
  }
  // The principal moments. The tensor is scaled by its largest entry first (a tensor of 1e300
  // kg m^2 or of 1e-300 is as good as any other), and scaled back.
  const Eigen::Matrix3d matrix = tensor.matrix();
  const double scale = matrix.cwiseAbs().maxCoeff();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(matrix / scale,
                                                              Eigen::EigenvaluesOnly);
  const Eigen::Vector3d scaled_moments = solver.eigenvalues();  // ascending
  const Eigen::Vector3d moments = scaled_moments * scale;
  if (!(scaled_moments[0] > 16 * kEps * scaled_moments[2])) {
    return Error{field,
                 "is not positive definite: its principal moments are " + formatVector(moments) +
                     " kg m^2, the smallest not above the rounding of the largest (16 eps of it)"};
  }
  if (!std::isfinite(1.0 / moments[0])) {
    return Error{field, "is too small: 1 / its smallest principal moment " +
                            formatNumber(moments[0]) + " kg m^2 overflows"};
  }
  const double sum = scaled_moments.sum();
  if (!(scaled_moments[0] + scaled_moments[1] >= scaled_moments[2] - 16 * kEps * sum)) {
    return Error{field,
                 "breaks the triangle inequality of the principal moments: I1 + I2 = " +
                     formatNumber(moments[0] + moments[1]) + " < I3 = " + formatNumber(moments[2]) +
                     " kg m^2 (principal moments " + formatVector(moments) +
                     "); no body has it, as I1 + I2 - I3 = 2 integral of r3^2 dm >= 0 along the "
                     "third principal axis"};
  }
  return Ok{};
}

Eigen::Matrix3d worldInverseInertia(const Eigen::Matrix3d& inertia,
                                    const Eigen::Quaterniond& orientation) {
  const Eigen::Matrix3d rotation = orientation.normalized().toRotationMatrix();
  const Eigen::Matrix3d turned = rotation * inertia.inverse() * rotation.transpose();
  return 0.5 * (turned + turned.transpose());
}

}  // namespace collision_response::core
