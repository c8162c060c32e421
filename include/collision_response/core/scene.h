// A scene: what the monitor watches (bodies, immovable obstacles) and how (detection, effects,
// threshold, materials). Read from the scene file by the ROS layer; validated here.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/friction.h"
#include "collision_response/core/mass_properties.h"
#include "collision_response/core/materials.h"
#include "collision_response/core/shape.h"

namespace collision_response::core {

/// `discrete`: overlap tested at each received instant. `continuous`: the exact instant of first
/// contact along the motion predicted from each body's last state.
enum class Detection { kContinuous, kDiscrete };
Expected<Detection> parseDetection(const std::string& name, const std::string& field);
const char* toString(Detection detection);

/// The effects a scene may turn on; none is the seed's model.
struct Effects {
  bool gravity = false;
  bool friction = false;
  bool spin = false;
  /// Quadratic air drag on a body in flight, F = -1/2 rho C_d A |v| v (doc/model.md, "Air").
  bool drag = false;
  /// The Magnus force of a spinning body in flight, F = 1/2 rho C_L A |v| (w/|w| x v); needs spin.
  bool magnus = false;
  /// Drag or Magnus: flight has no closed form and is integrated.
  bool air() const { return drag || magnus; }
};
/// Adds the effect `name` ("gravity" | "friction" | "spin" | "drag" | "magnus") to `effects`;
/// unknown or repeated names are errors naming `field`.
Status addEffect(const std::string& name, const std::string& field, Effects& effects);
std::string toString(const Effects& effects);

/// The air's defaults (doc/model.md, "Air"): a smooth sphere's drag coefficient between Reynolds
/// numbers 1e3 and 2e5; a lift coefficient of a ball spinning at a spin parameter r|w|/|v| of
/// about 0.2 (Nathan, "The effect of spin on the flight of a baseball", Am. J. Phys. 76, 119,
/// 2008); dry air at 20 degrees C and sea level.
inline constexpr double kDefaultDragCoefficient = 0.47;
inline constexpr double kDefaultLiftCoefficient = 0.2;
inline constexpr double kDefaultAirDensity = 1.204;

/// A body's shape (issue 42): a sphere, a box, a cylinder or a capsule about its origin (the
/// latter two along its z), or the convex hull of a mesh in its own frame.
enum class BodyShape { kSphere, kBox, kCylinder, kCapsule, kMesh };

/// A body the monitor tracks. `position` and `velocity` are its initial state for the scene
/// player; the monitor takes states from topics.
struct BodySpec {
  std::string id;
  double mass = 1.0;     ///< kg, or +inf: an immovable body whose motion comes from its states
  double radius = 0.0;   ///< m
  std::string material;  ///< required
  std::string topic;     ///< its own BodyState topic; empty: only `body_states`
  Inertia inertia = Inertia::kSolid;  ///< with the spin effect: I = 2/5 m r^2 or 2/3 m r^2
  /// C_d of F = -1/2 rho C_d A |v| v (drag effect): a smooth sphere's, subcritical (0.47).
  double drag_coefficient = kDefaultDragCoefficient;
  /// C_L of F = 1/2 rho C_L A |v| (w/|w| x v) (magnus effect), taken as constant.
  double lift_coefficient = kDefaultLiftCoefficient;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m, initial, in the fixed frame
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< m/s, initial, in the fixed frame
  /// rad/s, initial, in the fixed frame; nonzero only with the spin effect (without it the
  /// model has no spin to give it)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  /// Initial, world from body, a unit quaternion: the body's first state's (a shaped body's
  /// motion starts from it; a ball's does not matter).
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// Its shape: a sphere of `radius` by default; a box of edges `size`, a cylinder or a capsule
  /// of `radius` and `length` (between the caps; of the capsule's segment), or the convex hull of
  /// `mesh` (loaded from `resource`, scaled by `scale`, as an obstacle's). The monitor moves a
  /// box, cylinder, capsule or mesh (its hull).
  BodyShape shape = BodyShape::kSphere;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  ///< box: edge lengths, m
  double length = 0.0;                             ///< cylinder, capsule: m
  std::shared_ptr<const TriangleMesh> mesh;
  std::string resource;
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  /// Given: the tensor about the centre of mass in the body's frame (`inertia: {ixx, ...}`),
  /// instead of the uniform solid of its shape (`inertia: solid`, or `hollow` for a sphere).
  std::optional<InertiaTensor> inertia_tensor;
};

enum class ObstacleShape { kPlane, kSphere, kBox, kCylinder, kCapsule, kMesh };

/// An immovable obstacle: a plane {x : normal.x = offset} whose free side is the one `normal`
/// points to, a sphere, or a box, cylinder or capsule centred at `position` and turned by
/// `orientation` (a cylinder's and a capsule's axis its z). Given in `frame` (empty: the fixed
/// frame); a frame that moves makes a moving obstacle.
struct ObstacleSpec {
  std::string id;
  ObstacleShape shape = ObstacleShape::kPlane;
  std::string material;  ///< required
  std::string frame;     ///< tf frame the geometry is given in; empty: the fixed frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< plane: unit (normalised on load)
  double offset = 0.0;                                 ///< plane: m, normal.x = offset
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< sphere, box, ...: centre, m
  double radius = 0.0;                                 ///< sphere, cylinder, capsule: m
  Eigen::Vector3d size = Eigen::Vector3d::Zero();      ///< box: edge lengths, m
  double length = 0.0;  ///< cylinder: between the caps; capsule: of its segment (m)
  /// box, cylinder, capsule, mesh: from the frame's axes to the shape's
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// mesh: its triangles, scaled, in the shape's frame (the ROS layer loads them from
  /// `resource`, a package:// or file:// address, scaled by `scale` along the mesh's axes)
  std::shared_ptr<const TriangleMesh> mesh;
  std::string resource;
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
};

struct Scene {
  std::string fixed_frame = "world";
  Detection detection = Detection::kContinuous;
  Effects effects;
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.81);  ///< m/s^2, with the effect only
  double restitution_threshold = 0.0;  ///< m/s: slower approaches do not bounce (e = 0)
  /// Curved lasting contact (a ball rolling on a sphere) is integrated: the error allowed per
  /// integrator step, absolute (m, m/s, rad/s) and relative.
  double contact_integration_tolerance = 1e-9;
  /// kg/m^3: the air's density, for the drag and magnus effects.
  double air_density = kDefaultAirDensity;
  /// Flight under drag or Magnus is integrated (Dormand-Prince): the error allowed per step,
  /// absolute (m, m/s) and relative.
  double flight_integration_tolerance = 1e-9;
  /// Stepped clusters (gravity; doc/model.md, "Lasting contact"): a connected set of at least
  /// this many bodies near each other (within what they can move in a sub-step) is advanced by time
  /// steps instead of event by event; 0: never (every contact exact, at whatever cost).
  int stepped_cluster_min_bodies = 32;
  /// s: the longest sub-step; each update's interval is split into equal sub-steps no longer.
  double stepped_cluster_time_step = 0.01;
  /// Stepped clusters' other way in (gravity, stepping not off): what the exact model may spend
  /// on one body in one update (World::work: each instant its motion changes, each solve of its
  /// curved lasting contact's integration) before that body and the bodies near it are advanced
  /// by time steps, from that instant until they part (doc/model.md, "Lasting contact"); 0: no
  /// budget.
  int exact_work_budget = 1024;
  MaterialTable materials = MaterialTable::seed();
  std::vector<BodySpec> bodies;
  std::vector<ObstacleSpec> obstacles;
};

/// Which bodies a scene may move: spheres only (a ball's prediction, whose other bodies are held
/// as spheres), any shape (a shaped body's prediction: src/core/monitor/shaped_prediction.h), or
/// the monitor's: spheres, and boxes, cylinders, capsules and meshes of finite mass under gravity
/// alone (an immovable shaped body, drag or magnus with a shaped body: "not yet").
enum class MovingShapes { kSpheresOnly, kAny, kMonitored };

/// Every value and cross-reference of a scene: ids unique among bodies and obstacles, masses,
/// radii, known materials, finite vectors, nonzero plane normals, each body's shape and inertia
/// (checkBodyShape), and last, with kSpheresOnly, that every body is a sphere
/// (checkOnlySpheresMove: "not yet"), with kMonitored, that every shaped body is one the monitor
/// moves. Fields are named as scene file keys under `prefix` ("~scene/bodies[2]/mass"). Start-up
/// cost: O(n log n) in the bodies, plus one check per pair of distinct materials.
Status validateScene(const Scene& scene, const std::string& prefix,
                     MovingShapes moving = MovingShapes::kMonitored);

/// A warning for each body whose scene `position` lies inside a fixed obstacle (one without a
/// `frame`: tf places the others at run time) by more than the touching band, naming both and
/// the depth: "body 'ball' at [0, 0, 0.7] starts 0.05 m inside obstacle 'table'". The monitor
/// and the scene player run such a scene (a state inside is no impact: its impact was when it
/// began), but the user most likely placed it wrongly. For a scene validateScene accepted. A ball
/// only: a shaped body (its sizes are not its radius) is looked at by the monitor, which holds a
/// state inside an obstacle and reports it (StepReport::unmodelled).
std::vector<std::string> bodiesStartingInside(const Scene& scene);

/// A warning for each obstacle (but a plane) whose position has a coordinate at or beyond 2^47
/// times its bounding radius (checkResolvableObstaclePosition): a body near it touches it from
/// as far as the obstacle is large, as a ball of radius r is coarse from |x| = 2^47 r on (README,
/// "Bad input on the topics"). Named as scene keys under `prefix`: "~scene/obstacles[0]/position.x:
/// 1e+300 m is beyond where a contact with this obstacle resolves (...)".
std::vector<std::string> obstaclesBeyondResolution(const Scene& scene, const std::string& prefix);

/// Scales every plane's normal to unit length without under- or overflow (a normal of length
/// 1e-200 or 1e200 is as good as any other nonzero one). For a scene validateScene accepted.
void normalizePlanes(Scene& scene);

}  // namespace collision_response::core
