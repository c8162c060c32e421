// A shaped body tipping over a bounded face's edge (issue 42, build step 6): a box or a can that
// slides or rests on a table with its centre of pressure at the table's edge turns over that
// edge, its own face pivoting on the edge's line, sticking there or sliding along its face
// (Coulomb), until it leaves the edge or its face passes it. The motion is planar (the edge's
// line a principal axis of the body, no motion along it) and integrated to a stated tolerance
// (doc/model.md, "Tipping over the face's edge").
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "collision_response/core/expected.h"
#include "contact/edge_crossing.h"
#include "contact/shaped_lasting.h"

namespace collision_response::core {

/// A bounded face's four edges, each with the bound it is: the face's axis (0: along_u, 1:
/// along_v) and side (-1, 1).
struct BoundEdge {
  FaceEdge edge;
  int axis = 0;
  double side = 1.0;
};
std::array<BoundEdge, 4> edgesOf(const FlatFace& face);

/// The body, its own flat face (its outward normal -`up`: a box's or a hull's face, a
/// cylinder's cap) on `edge` of `face`, flat on the face with its centre of pressure at or past the
/// edge or already turned over it, turning over the edge under gravity: its face pivots on the
/// edge's line at s = the centre's foot's distance past the line along its face, the chord of
/// its face on the line sharing the force. The edge sticks while the friction it needs is within
/// mu of the normal force and slides (Coulomb) otherwise; integrated with the Dormand-Prince
/// pair to `tolerance` (absolute and relative). Ends (`until`, `ends`): the body leaves the edge
/// (its normal force reaches 0; it flies on, in closed form, until it is kPivotClearance of its
/// reach clear of the edge) or its face passes the edge, or its face turns back flat onto the
/// face ("resumes": its events take over), or `horizon` ("stops"). Refused by name (`contact:
/// not yet: ...`): motion along the edge, gravity along it, a turn about another axis, the
/// edge's line not a principal axis of the body, the centre of mass past an end of the chord
/// (the body would turn out of its plane), Painleve's paradox.
Expected<LastingMotion> tipOverFaceEdge(const LastingBody& body, const FlatFace& face,
                                        const FaceEdge& edge, const Eigen::Vector3d& up,
                                        double tolerance, double horizon = 10.0);

/// The edge of the bounded `face` that `body` is turned over, its own flat face (a box's or a
/// hull's face, a cylinder's cap) on the edge's line within the touching band and turned past
/// the face's plane towards the edge's out (as a tracker sees a box halfway over a table's
/// edge), with that face's inward normal: what tipOverFaceEdge takes. Empty where it is not so.
std::optional<std::pair<FaceEdge, Eigen::Vector3d>> tiltedOverEdge(const LastingBody& body,
                                                                   const FlatFace& face);

/// The body `tau` seconds after `there` in free flight under `gravity`: its centre's parabola,
/// its turn at its constant w (a turn about a principal axis, as a body leaving an edge has),
/// sliding, no forces.
PathState flownFrom(const PathState& there, const Eigen::Vector3d& gravity, double tau);

/// s: where a body flying off an edge is first `clearance` from it, `gap(tau)` its distance
/// `tau` seconds on: the first of doubling spans from 1e-6 s at which the gap is `clearance`,
/// with no return to the edge on the way (the gap > 0 at 64 instants of the span); empty where
/// it comes back.
std::optional<double> clearAfter(const std::function<double(double)>& gap, double clearance);

/// The distance of a body (`shape`) flying from `there` (flownFrom, under `gravity`) to the edge's
/// line through `point` along `along` (its part within the body's reach), `tau` seconds on (GJK).
double gapToEdge(const ConvexShape& shape, const Eigen::Vector3d& point,
                 const Eigen::Vector3d& along, const Eigen::Vector3d& gravity,
                 const PathState& there, double tau);

}  // namespace collision_response::core
