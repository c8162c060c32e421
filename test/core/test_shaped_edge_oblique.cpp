// A box or a can going over a table's edge at an angle to it (src/core/contact/edge_crossing.h,
// pivotOverFaceEdge in shaped_pivot.h; doc/model.md, "At an angle to the edge"): before, held
// where it reached the edge ("not yet: sliding off the face's edge along it too").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "collision_response/core/monitor.h"
#include "contact/shaped_lasting.h"
#include "contact/shaped_pivot.h"
#include "lasting_bodies.h"
#include "scene_builders.h"
#include "shaped_scenes.h"

namespace collision_response::core {
namespace {

using lasting_bodies::box;
using lasting_bodies::errorOf;
using lasting_bodies::Q;
using lasting_bodies::tableTop;
using lasting_bodies::V;
using shaped_scenes::floorScene;
using shaped_scenes::impactsOf;
using shaped_scenes::kG;
using shaped_scenes::momentsOf;
using shaped_scenes::outlineOf;
using shaped_scenes::play;
using shaped_scenes::Played;
using shaped_scenes::tableScene;

/// The scene's body 0 (its lowest face or cap on the frictionless table top z = 0.5, x <= 0.5,
/// its centre `height` above it, at x = 0.25) slid at (u, w, 0): as the header of the test says.
void expectObliqueAsSquare(const Scene& scene, double height, double inertia, double within,
                           double turned) {
  const double m = scene.bodies[0].mass, u = 0.5, w = 0.2;
  BodyStateSample state;
  state.body = 0;
  state.position = V(0.25, 0, 0.5 + height);
  state.velocity = V(u, w, 0);
  const Played oblique = play(scene, state, 0.005, 1.0);
  state.velocity = V(u, 0, 0);
  const Played square = play(scene, state, 0.005, 1.0);
  for (const auto* run : {&oblique, &square}) {
    for (const StepReport& report : run->reports) {
      for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << c.what;
    }
  }
  const std::vector<ImpactRecord> impacts = impactsOf(oblique.reports);
  ASSERT_FALSE(impacts.empty());
  EXPECT_EQ(impacts.front().other, 0u);  // the floor
  EXPECT_GT(impacts.front().time, 0.5);
  const double start = 0.5 * m * (u * u + w * w) + m * kG * (0.5 + height);
  const std::vector<V> outline = outlineOf(scene.bodies[0]);
  ASSERT_EQ(oblique.times.size(), square.times.size());
  std::size_t over = 0;
  for (std::size_t i = 0; i < oblique.times.size(); ++i) {
    const double t = oblique.times[i];
    if (t >= impacts.front().time) break;
    const V& c = oblique.centres[i];
    EXPECT_NEAR(oblique.velocities[i].y(), w, 1e-12) << t;
    EXPECT_NEAR(c.y(), w * t, 1e-9) << t;
    EXPECT_NEAR(c.x(), square.centres[i].x(), within) << t;
    EXPECT_NEAR(c.z(), square.centres[i].z(), within) << t;
    EXPECT_LT(oblique.orientations[i].angularDistance(square.orientations[i]), turned) << t;
    // The body turns about y alone: its spin is about y, (1/2) J w^2 its turning's energy.
    const double energy = 0.5 * m * oblique.velocities[i].squaredNorm() +
                          0.5 * inertia * oblique.spins[i].squaredNorm() + m * kG * c.z();
    EXPECT_NEAR(energy, start, 1e-7 * m * kG * (0.5 + height)) << t;
    const Eigen::Matrix3d r = oblique.orientations[i].toRotationMatrix();
    for (const V& p : outline) {
      const V at = c + r * p;
      EXPECT_GE(std::max(at.x() - 0.5, at.z() - 0.5), -1e-9) << "inside the table at " << t;
    }
    if (c.x() > 0.5 && c.z() < 0.5 + height - 1e-3) ++over;
  }
  EXPECT_GT(over, 5u);  // it turned over the edge on the way
}

// A cube (edge 0.125 m, 2 kg) sliding on a frictionless table at (0.5, 0.2) m/s towards its edge
// x = 0.5 at an angle to it. Frictionless, every force on it is at right angles to the edge's
// direction y (the table's top along z; its edge's crossings along t x y, t the cube's edge),
// so its velocity along y stays 0.2 m/s and its centre's y is 0.2 t, exactly; in x and z it moves
// as the same cube slid square to the edge (the shape it rests on, the table's top cut by a
// line along y, does not change along y): the square slide's path, which the planar model
// ("Over a table's edge") gives. Its energy is kept until the floor; never inside the table.
TEST(ShapedEdgeOblique, AFrictionlessCubeSlidingOffAtAnAngleMovesAsSquareToItAndAlongIt) {
  const V half(0.0625, 0.0625, 0.0625);
  const double m = 2.0;
  Scene scene = tableScene(0.5, half, m);
  expectObliqueAsSquare(scene, half.z(), m * 4 * half.x() * half.x() / 6, 1e-9, 1e-8);
}

// The same for a can standing on its cap (r = 0.05 m, 0.15 m tall, 0.4 kg): its cap's rim
// crosses the edge's line at two points, each pressed along t x y; it moves as square to the edge
// (the planar model's cap over the edge) and along it at 0.2 m/s, its turning about y (J =
// m (3 r^2 + L^2) / 12). Where its chord on the edge shrinks to a point (the rim passing the
// edge: the planar model's end), its two ends' forces grow ill-conditioned (the moment they hold
// costs forces as 1 / its length squared) and lose their symmetry on rounding: both leave where
// one does, 1.8 us before the chord vanishes, and the flight after is within 2e-8 m/s and
// 5e-7 rad/s of the planar model's (1e-8 m and 3e-7 rad by the floor).
TEST(ShapedEdgeOblique, AFrictionlessCanSlidingOffAtAnAngleMovesAsSquareToItAndAlongIt) {
  const double r = 0.05, length = 0.15, m = 0.4;
  Scene scene = tableScene(0.5, V(0.05, 0.05, 0.05), m);
  scene.bodies[0].shape = BodyShape::kCylinder;
  scene.bodies[0].size = V::Zero();
  scene.bodies[0].radius = r;
  scene.bodies[0].length = length;
  expectObliqueAsSquare(scene, length / 2, m * (3 * r * r + length * length) / 12, 1e-8, 3e-7);
}

// A box of three different sides (half sizes 0.1, 0.06, 0.04 m, 2 kg) turned by 0.4 rad about the
// vertical, at rest flat on the table with its centre s = 0.01 m past the edge x = 1: the edge's
// line (y) is not a principal axis of the body, which the planar model refuses. Where its
// face's chord on the edge sticks at both ends (mu = 5), the line is fixed in the body and it
// turns about it as a compound pendulum: with I_E = y.I_c y + m rho^2 (I_c the world's tensor
// about the centre), rho^2 = s^2 + h^2, tan beta = s / h, the energy integral
// I_E phi'^2 / 2 = m g rho (cos beta - cos(phi + beta)); its centre stays rho from the line and
// at its y. Then it slips and leaves, never inside the table, never gaining energy.
TEST(ShapedEdgeOblique, ABoxTurnedOnTheEdgeTurnsAboutItAsACompoundPendulumWhileItSticks) {
  const double m = 2, h = 0.04, s = 0.01, yaw = 0.4;
  const V half(0.1, 0.06, h);
  const Q turn(Eigen::AngleAxisd(yaw, V::UnitZ()));
  const LastingBody body = box(half, m, V(1 + s, 0.05, 0.7 + h), turn);
  const FlatFace table = tableTop(5);
  const auto tips = lastingOnFace(body, table);
  ASSERT_TRUE(tips.ok()) << errorOf(tips);
  ASSERT_TRUE(tips->pivot);
  const Eigen::Matrix3d r = turn.toRotationMatrix();
  const Eigen::Matrix3d inertia = r * body.moments.asDiagonal() * r.transpose();
  const double rho = std::hypot(s, h), beta = std::atan2(s, h);
  const double i_e = V::UnitY().dot(inertia * V::UnitY()) + m * rho * rho;
  double sticking = tips->start;
  while (sticking < tips->until && tips->stateAt(sticking + 1e-3) == ContactState::kRolling) {
    sticking += 1e-3;
  }
  ASSERT_GT(sticking, tips->start + 0.05);
  // The integration's tolerance (1e-9 on w) against the largest phi'^2 of the span.
  const double largest = tips->angularVelocityAt(sticking).squaredNorm();
  for (int k = 1; k <= 50; ++k) {
    const double t = tips->start + (sticking - tips->start) * k / 50.0;
    const V c = tips->centreAt(t);
    const double phi = Eigen::AngleAxisd(tips->orientationAt(t) * turn.conjugate()).angle();
    const double rate2 = 2 * m * kG * rho * (std::cos(beta) - std::cos(phi + beta)) / i_e;
    const V w = tips->angularVelocityAt(t);
    EXPECT_NEAR(w.squaredNorm(), rate2, 1e-8 * largest) << t;
    EXPECT_NEAR(w.normalized().dot(V::UnitY()), 1.0, 1e-9) << t;
    EXPECT_NEAR(std::hypot(c.x() - 1, c.z() - 0.7), rho, 1e-10) << t;
    EXPECT_NEAR(c.y(), 0.05, 1e-10) << t;
  }
  // Two points on the edge's line, each within its cone, carrying the weight's part.
  for (const SupportForce& f : tips->forcesAt(0.5 * (tips->start + sticking))) {
    EXPECT_NEAR(f.point.x(), 1.0, 1e-12);
    EXPECT_NEAR(f.point.z(), 0.7, 1e-12);
    EXPECT_GT(f.normal_force, 0.0);
    EXPECT_LE(f.friction_force.norm(), 5 * f.normal_force * (1 + 1e-9));
  }
  EXPECT_EQ(tips->forcesAt(0.5 * (tips->start + sticking)).size(), 2u);
}

// 40 boxes of random sides (0.03 to 0.1 m half sizes) turned at random about the vertical, and 20
// cans (r 0.03 to 0.06 m, 0.08 to 0.25 m tall) standing on their caps, sliding on a table (mu and
// e in [0, 1] for it and for the floor) at 0.5 to 2 m/s towards its edge at up to 60 degrees
// from square; then 4 boxes and 2 cans spinning at up to 5 rad/s about the vertical as well.
// Through the monitor for 1 s (over the edge, off it, onto the floor, tumbling and sliding
// there): nothing unmodelled, no corner (or rim point) inside the table or below the floor
// (1e-9 m), no energy gained from one sample to the next (1e-8 J: the integration's tolerance).
TEST(ShapedEdgeOblique, RandomSlidesOffAtAnAngleNeverGoInsideNorGainEnergy) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int off = 0;
  for (int k = 0; k < 66; ++k) {
    std::mt19937 random(2026 + k);
    const bool spins = k >= 60, can = (k >= 40 && k < 60) || k >= 64;
    const double m = 0.2 + unit(random);
    Scene scene = floorScene(unit(random), V(0.05, 0.05, 0.05), m);
    scene.materials = MaterialTable{};
    ASSERT_TRUE(
        scene.materials.addMaterial("block", Material{unit(random), unit(random)}, "m").ok());
    ASSERT_TRUE(
        scene.materials.addMaterial("concrete", Material{unit(random), unit(random)}, "m").ok());
    BodySpec& body = scene.bodies[0];
    const double height = shaped_scenes::randomBlock(body, can, random);
    scene.obstacles.push_back(
        scene_builders::box("table", V(0, 0, 0.25), V(1.0, 4.0, 0.5), "concrete"));
    const double angle = (2 * unit(random) - 1) * M_PI / 3, speed = 0.5 + 1.5 * unit(random);
    BodyStateSample state;
    state.body = 0;
    state.position = V(0.3, 0, 0.5 + height);
    state.orientation = Q(Eigen::AngleAxisd(2 * M_PI * unit(random), V::UnitZ()));
    state.velocity = speed * V(std::cos(angle), std::sin(angle), 0);
    state.angular_velocity = V(0, 0, spins ? 5 * (2 * unit(random) - 1) : 0.0);
    const Played played = play(scene, state, 0.005, 1.0);
    for (const StepReport& report : played.reports) {
      for (const UnmodelledContact& c : report.unmodelled) ADD_FAILURE() << k << ": " << c.what;
    }
    shaped_scenes::expectOutsideAndNotGaining(played, body, k, [](const V& at) {
      return std::min(std::max({at.x() - 0.5, at.z() - 0.5, std::abs(at.y()) - 2.0}), at.z());
    });
    for (const V& c : played.centres) off += c.z() < 0.5 ? 1 : 0;
  }
  EXPECT_GT(off, 1000);  // they went off the table
}

}  // namespace
}  // namespace collision_response::core
