// The prediction of a shaped body (issue 42, build step 7, first part): a box, cylinder or
// capsule (or a sphere given a tensor) predicted among the scene's obstacles by its exact flight
// (its centre's parabola, its torque-free rotation: free_rotation.h), its certified first
// contacts (tumbling_contact.h) and its impacts with rotation (rigid_impact.h), until it would
// come into lasting contact, which is not modelled yet for a shaped body: the prediction ends
// there and says so. The monitor itself still moves spheres only.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/prediction.h"
#include "geometry/convex_distance.h"

namespace collision_response::core {

/// A body in its principal frame: its shape about its centre of mass, along the axes of its
/// principal moments, and where that frame is in the body's own.
struct PrincipalBody {
  ConvexShape shape;
  Eigen::Vector3d moments = Eigen::Vector3d::Ones();  ///< kg m^2, about the frame's x, y, z
  double mass = 0.0;                                  ///< kg
  /// The body's frame from the principal frame (a rotation), and the centre of mass in the
  /// body's frame.
  Eigen::Quaterniond body_from_principal = Eigen::Quaterniond::Identity();
  Eigen::Vector3d centre_of_mass = Eigen::Vector3d::Zero();
};

/// A shaped body's principal frame from its shape and mass (bodyMassProperties). A tensor with
/// products of inertia turns the frame: a box then becomes the hull of its corners; a cylinder
/// or a capsule given such a tensor is refused (`field`.inertia: not yet). A mesh body is
/// refused (`field`.shape: not yet predicted).
Expected<PrincipalBody> principalBody(const BodySpec& body, const std::string& field);

/// The request's checks that only a shaped body has: drag and magnus are not yet modelled for
/// it (`effects`); its shape and tensor (checkBodyShape, principalBody); its orientation.
Status checkShapedRequest(const PredictionRequest& request);

/// The prediction of a shaped body: `model` holds the scene ahead (the obstacles where they
/// are placed, the ids of the answer); `began` the budget's clock at the start. The reasons it
/// was cut short are appended to `cut`.
Expected<Prediction> runShapedPrediction(const PredictionStart& start,
                                         const PredictionBudget& budget, double began,
                                         std::shared_ptr<ImpactMonitor> model,
                                         std::vector<std::string>& cut);

}  // namespace collision_response::core
