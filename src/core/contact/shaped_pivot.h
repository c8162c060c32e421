// A shaped body tipping over its corners on one flat face (issue 42, build step 6): a box (or a
// hull) that touches the face at one corner or along one edge, or rocks or spins on a face,
// pivoting under gravity until another corner reaches the face, it leaves the face and is clear
// of it, its corners all stick on a face (it rests), or a corner reaches a bounded face's edge.
// Each corner sticks (static friction within mu) or slides (Coulomb); the motion has no closed
// form (a heavy top about a fixed point, a physical pendulum about an edge) and is integrated to
// a stated tolerance (doc/model.md, "Tipping over a corner or an edge"). A cylinder on its rim or a
// capsule on one end moves by the same law, its point touching moving over the body.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/monitor.h"
#include "contact/shaped_lasting.h"

namespace collision_response::core {

/// m/s: a point's slip that falls to it has stopped: the point sticks where its force is within
/// the cone (the slip left taken out by a plastic impulse), else slips anew from Coulomb's onset
/// direction. Near 0 the slip's direction, and the friction with it, turns at |a| / |slip|: the
/// integration would crawl. Below it a slip just begun takes its friction's direction turned
/// continuously from its onset's to its own (doc/model.md, "Tipping over a corner or an edge").
constexpr double kPivotSlipStops = 1e-6;

/// Of the body's reach: a body whose last point leaves the face flies on, integrated, until its
/// lowest corner is this far above the face (or a corner lands): the certified first contact's
/// advancement, bounded by the body's turning, would crawl from a gap that opens from 0.
constexpr double kPivotClearance = 1e-5;

/// The most points a tipping may start on (a hull's face of many corners: each sticks, slides or
/// leaves as a box's four do).
constexpr std::size_t kPivotMaxPoints = 32;

/// The integrated path of a tipping body (pivotOnFace): dense output over [start, until].
class PivotPath : public LastingPath {
 public:
  struct Steps;
  explicit PivotPath(std::unique_ptr<Steps> steps);
  ~PivotPath() override;
  PivotPath(const PivotPath&) = delete;
  PivotPath& operator=(const PivotPath&) = delete;

  /// The state at `t` (clamped to [start, until]); the points touching exactly on the face.
  PathState stateAt(double t) const override;
  double start() const override;
  double until() const override;
  std::size_t steps() const override;

 private:
  std::unique_ptr<Steps> steps_;
};

/// The body touching `face` at `corners` (one to kPivotMaxPoints: a corner, an edge, a face; in its
/// principal frame, each within the settled band of the face) tipping under gravity, integrated
/// with the Dormand-Prince pair to `tolerance` (absolute and relative). At its start the normal
/// motion of the points (settled: kLastingSettled) and the slip of a point slower than
/// kLastingStillSpeed are taken out by a plastic impulse (energy lost, never gained). Then each
/// point sticks while the force that holds it is within mu of its normal force, and slides
/// (friction mu N against its slip) otherwise; a point whose normal force reaches 0 leaves (the
/// last one too: the body flies on, integrated, until kPivotClearance). The motion ends (`until`,
/// `ends`) where another corner of the body reaches the face or the flying body is clear of it
/// ("resumes": the body's events take over from the state there), where a face's corners all
/// stick ("stops": it rests), where a point reaches a bounded face's edge (not modelled yet), or
/// after `horizon` seconds ("stops": asked again from there).
Expected<LastingMotion> pivotOnFace(const LastingBody& body, const FlatFace& face,
                                    const std::vector<Eigen::Vector3d>& corners, double tolerance,
                                    double horizon = 10.0);

/// A box or a hull touching several fixed faces at once (`faces`, each its own mu; a floor and
/// a wall, a bin's corner): its corners touching each face (within the settled band of its
/// lowest one there, as lastingOnFace's manifold, and moving along the face's normal no faster
/// than a settled point does) each stick, slide or leave their face by pivotOnFace's law, all the
/// faces' forces solved together (least-norm). Another corner reaching any of the faces, or the
/// last point leaving them all, "resumes"; a point reaching a bounded face's edge ends it (not
/// modelled yet). Where the body is still and its points hold it (its accelerations within 1e-12
/// of gravity's, every sticking point's force within its cone) it rests: from the start for ever
/// (a closed form), after a motion "stops" there. A face it does not touch (within kLastingBand)
/// carries nothing, its events watching it. An Error names a face it is inside (`faces[i]`), one
/// whose every near point approaches or leaves it (`body.velocity`), or that it touches none
/// (`body.centre`).
Expected<LastingMotion> pivotOnFaces(const LastingBody& body, const std::vector<FlatFace>& faces,
                                     double tolerance, double horizon = 10.0);

/// A box or a cylinder on a bounded face's edge at any angle to it (issue 42, step 6;
/// doc/model.md, "At an angle to the edge"): its corners and its rims' lowest points on the face,
/// and its edges' or rims' crossings of the face's edges' lines (edge_crossing.h), each sticking,
/// sliding or leaving by pivotOnFace's law; a crossing that moves onto another edge of the body,
/// or a corner that passes the face's edge, changes the points touching there. It ends as
/// pivotOnFace's ("resumes" where it is clear of the face or another feature reaches it). Over the
/// face's corner, the corner on the body's flat side (a box's face, a can's cap) is a point too,
/// each of its own normal (the side's), sticking, sliding or leaving by the same law; a crossing
/// that reaches an end of the face's edge, or the corner leaving the side, changes the points
/// there. Refused by name: a hull or a capsule.
Expected<LastingMotion> pivotOverFaceEdge(const LastingBody& body, const FlatFace& face,
                                          double tolerance, double horizon = 10.0);

/// A cylinder leaning on a point of its rim, or a capsule on a point of one end, tipping, rolling
/// or sliding on `face` as pivotOnFace's corners do (the same law, events and ends), where the
/// point touching moves over the body: a rim's lowest point, an end's point under its centre.
/// `ends` says which touch (-1: the rim or end at -half_length along the body's z; 1: at
/// +half_length; both: a side's two ends); `lean` (principal frame, its part across z) is the
/// direction from a rim's centre to its point touching where the cap is flat on the face (a cap
/// tipping over its rim). It ends as pivotOnFace's, "resumes" where another rim or end reaches
/// the face or a touching rim's cap lands flat.
Expected<LastingMotion> pivotOnRound(const LastingBody& body, const FlatFace& face,
                                     const std::vector<int>& ends, const Eigen::Vector3d& lean,
                                     double tolerance, double horizon = 10.0);

/// A cylinder standing on its cap (`end`: -1 or 1, as pivotOnRound's) that spins about the
/// face's normal: its whole rim would slide, each point its own way. The cap's load is carried
/// at four points of its rim fixed in the body (along its x and y axes, the square the closed
/// forms' forces use), each sticking or sliding as pivotOnFace's corners; where fewer than three
/// are left, the cap tips over its rim (its lowest point, as pivotOnRound's), and where all stick
/// it rests ("stops": the closed forms take it). One documented choice where the pressure over a
/// cap is statically indeterminate (a drinks can stands on a ring).
Expected<LastingMotion> spinOnCap(const LastingBody& body, const FlatFace& face, int end,
                                  double tolerance, double horizon = 10.0);

}  // namespace collision_response::core
