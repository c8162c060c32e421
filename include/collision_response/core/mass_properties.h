// A rigid body's mass properties (issue 42, build step 2): its volume, centre of mass and inertia
// tensor about the centre of mass in its own frame, for a uniform solid of each shape a body may
// have (a sphere, a box, a cylinder, a capsule, the convex hull of a mesh), and the checks of a
// tensor given instead (URDF's `{ixx, iyy, izz, ixy, ixz, iyz}`).
//
// The tensor's entries are the tensor's own: I = integral of (|r|^2 1 - r r^T) dm, so a product
// of inertia is ixy = -integral of x y dm (URDF's convention, and Eberly's; some texts list the
// integral itself, with the opposite sign).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/friction.h"
#include "collision_response/core/shape.h"

namespace collision_response::core {

/// A symmetric inertia tensor by its six entries, kg m^2, about the centre of mass in the body's
/// frame, named as URDF's `inertia` element names them (the off-diagonal entries are the tensor's).
struct InertiaTensor {
  double ixx = 0.0, iyy = 0.0, izz = 0.0;
  double ixy = 0.0, ixz = 0.0, iyz = 0.0;

  Eigen::Matrix3d matrix() const;
  static InertiaTensor fromMatrix(const Eigen::Matrix3d& matrix);
};

/// What a body's shape and mass give: kg, m^3, m (in the shape's frame), kg m^2 (about the
/// centre of mass, along the shape's axes).
struct MassProperties {
  double mass = 0.0;
  double volume = 0.0;
  Eigen::Vector3d centre_of_mass = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

// The closed forms of the uniform solids (every text on rigid bodies; e.g. Goldstein, Classical
// Mechanics, and for the capsule the hemisphere's 83/320 m r^2 about its own centre of mass,
// shifted by the parallel-axis theorem). Each about its centre, its axes the shape's, for a
// finite mass m > 0 (an immovable body turns by no inertia of its own).

/// A sphere of radius r: I = k m r^2 1, k = 2/5 solid, 2/3 hollow (a thin shell), the factors
/// of friction.h's spinFactor (1/k). Its volume is the solid's, 4/3 pi r^3, either way.
MassProperties sphereMassProperties(double mass, double radius, Inertia inertia);
/// A box of edges (a, b, c) = 2 half_size: I = m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2).
MassProperties solidMassProperties(const Cuboid& box, double mass);
/// A cylinder of radius r and length h = 2 half_length along z: I_zz = m r^2 / 2,
/// I_xx = I_yy = m (3 r^2 + h^2) / 12.
MassProperties solidMassProperties(const Cylinder& cylinder, double mass);
/// A capsule: the cylinder of radius r and length h = 2 half_length along z and two hemispheres,
/// the mass shared by volume (m_c = m h / (h + 4 r / 3), m_s = m - m_c). I_zz = m_c r^2 / 2 +
/// 2/5 m_s r^2; I_xx = I_yy = m_c (3 r^2 + h^2) / 12 + m_s (2/5 r^2 + h^2 / 4 + 3 h r / 8), each
/// hemisphere's 83/320 m r^2 about its centre of mass (3 r / 8 from its flat face) shifted by
/// (h / 2 + 3 r / 8)^2 to the capsule's centre (83/320 + 9/64 = 2/5).
MassProperties solidMassProperties(const Capsule& capsule, double mass);

/// A closed polyhedron by its triangles.
struct Polyhedron {
  std::vector<Eigen::Vector3d> vertices;
  /// Vertex indices, counter-clockwise seen from outside (their normals point outwards).
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// The convex hull of `points` (m), its triangles wound outwards, its vertices those of the
/// points that are corners of the hull (qhull's Quickhull: Barber, Dobkin and Huhdanpaa, "The
/// Quickhull algorithm for convex hulls", ACM TOMS 22(4), 1996). Refused by name (`field`): a
/// point that is not finite (`field`[i]), fewer than four points, points that span no volume
/// (all on one plane, on one line or at one point) or that qhull cannot hull for another reason
/// (its message quoted).
Expected<Polyhedron> convexHull(const std::vector<Eigen::Vector3d>& points,
                                const std::string& field);

/// m^2: the total area of the polyhedron's triangles.
double surfaceArea(const Polyhedron& polyhedron);

/// m^2: a shape's mean cross-section, the area of its shadow averaged over every orientation: for
/// a convex body a quarter of its surface (Cauchy's surface-area formula; Santalo, "Integral
/// Geometry and Geometric Probability", 1976): pi r^2 for a sphere, 2 (x y + y z + z x)
/// for a box of half sizes x, y, z, pi r (r + 2 h) / 2 for a cylinder and pi r (r + h) for a
/// capsule of half length h, a mesh's convex hull's surface / 4. 0 for a plane, a mesh with no
/// triangles or one whose hull is refused (convexHull).
double meanCrossSection(const Shape& shape);

/// A uniform solid polyhedron of `mass` (finite, > 0) bounded by closed, outward-wound triangles:
/// its volume, centroid and inertia tensor by the divergence theorem, each volume integral of
/// 1, x, y, z, x^2, ..., zx turned into sums over the triangles (Mirtich, "Fast and accurate
/// computation of polyhedral mass properties", J. Graphics Tools 1(2), 1996; in the form for
/// triangles of Eberly, "Polyhedral Mass Properties (Revisited)", Geometric Tools, 2002). The
/// vertices are first taken relative to their mean, so that a body far from its frame's origin
/// loses no digits to its position. Refused by name (`field`): a vertex that is not finite, an
/// index out of range, a polyhedron that encloses no volume (or is wound inwards: its volume
/// comes out negative).
Expected<MassProperties> polyhedronMassProperties(const Polyhedron& polyhedron, double mass,
                                                  const std::string& field);

/// A uniform solid of `mass` of a body's shape, in the shape's frame: a sphere (`sphere_inertia`
/// solid or hollow; its centre is its centre of mass), a box, a cylinder, a capsule, or the
/// convex hull of a mesh's vertices (a mesh body is its convex hull). Refused by name (`field`):
/// a plane (no body is unbounded), a mass that is not finite and > 0, a shape of no volume (a
/// zero edge, radius or hull; a cylinder of zero length is a disc and has none either).
Expected<MassProperties> uniformMassProperties(const Shape& shape, double mass,
                                               Inertia sphere_inertia, const std::string& field);

/// I^-1 in the world (the common frame) of a body turned by `orientation` (world from body, of
/// unit length to checkOrientation's tolerance; normalised here): R I^-1 R^T, with I the tensor
/// about the centre of mass in the body's own frame (positive definite: a uniform solid's, or
/// one checkInertiaTensor accepted). Symmetric to the bit (its two triangles averaged).
Eigen::Matrix3d worldInverseInertia(const Eigen::Matrix3d& inertia,
                                    const Eigen::Quaterniond& orientation);

/// A tensor a user gives (`field`.ixx, ... name its entries): every entry finite; positive
/// definite (each moment > 0, each 2 x 2 minor ixx iyy - ixy^2 ... > 0, naming the product that
/// breaks it, and the smallest principal moment above the rounding of the largest, 16 eps I_max,
/// where the sign of a smaller one is not known); and the principal moments' triangle
/// inequality I1 + I2 >= I3 (for each order), which holds for every body because
/// I1 + I2 - I3 = 2 integral of r3^2 dm >= 0 along the third principal axis (a flat body meets
/// it with equality: allowed to the same rounding, 16 eps (I1 + I2 + I3)). A moment whose
/// inverse overflows (a moment below about 5.6e-309 kg m^2) is refused as too small.
Status checkInertiaTensor(const InertiaTensor& tensor, const std::string& field);

}  // namespace collision_response::core
