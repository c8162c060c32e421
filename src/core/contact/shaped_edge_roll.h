// A cylinder or a capsule rolling off a bounded face's edge on its side (issue 42, build step 6):
// a can rolling across a table, its axis along the table's edge, goes on over the edge, its side
// turning on the edge's line, rolling there or sliding (Coulomb), until it leaves the edge and
// flies. The motion is planar (the axis along the edge, no motion along it) and integrated to a
// stated tolerance (doc/model.md, "Over a table's edge").
#pragma once

#include <Eigen/Core>
#include <optional>

#include "collision_response/core/expected.h"
#include "contact/shaped_edge_tip.h"
#include "contact/shaped_lasting.h"

namespace collision_response::core {

/// rad: how near the edge's line a side's axis must lie to roll over it.
constexpr double kSideAlongEdge = 1e-9;

/// The body, a cylinder or a capsule whose side touches `edge` of `face` along its axis (the axis
/// along the edge's line, its distance from the line the radius r), rolling or sliding over the
/// edge under gravity: its centre on the circle of radius r about the edge's line at the angle
/// theta from the face's normal towards the edge's out, its turn psi about its axis. With I its
/// moment about the axis, the edge's normal force N and friction F (along the circle's tangent):
/// N = -m (g.u + r theta'^2); rolling (its point on the edge still, psi' = theta'),
/// (I + m r^2) theta'' = m r g.t; sliding, F = -sigma mu N, m r theta'' = m g.t + F and
/// I psi'' = -r F (sigma the sign of the slip r (theta' - psi')). Integrated with the
/// Dormand-Prince pair to `tolerance`. Ends (`until`, `ends`): it leaves the edge (N reaches 0:
/// it flies on, in closed form, until it is kPivotClearance of its reach clear of the edge, then
/// "resumes"), or it rolls back onto the face (theta back to 0, turning back: "resumes"), or
/// `horizon` ("stops"). Refused by name (`contact: not yet: ...`): the axis not along the edge,
/// motion along the edge, a turn about another axis, gravity along the edge, the side's middle
/// past an end of the edge.
Expected<LastingMotion> rollOverFaceEdge(const LastingBody& body, const FlatFace& face,
                                         const FaceEdge& edge, double tolerance,
                                         double horizon = 10.0);

/// The edge of the bounded `face` whose line a cylinder's or a capsule's side lies on, its axis
/// along it (within kSideAlongEdge) at r from the line (within the touching band), its centre at or
/// past the line (towards the edge's out, within the band) and moving out, or past it: what
/// rollOverFaceEdge takes. Empty where it is not so (a box, a side square to no edge, a side
/// well on the face or rolling back onto it).
std::optional<FaceEdge> sideOnEdge(const LastingBody& body, const FlatFace& face);

}  // namespace collision_response::core
