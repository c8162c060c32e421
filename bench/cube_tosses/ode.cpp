// ODE replays the cube tosses (only in the benchmark; the product never links ODE): dWorldStep
// (its direct solver) at kStep with its default ERP 0.2 and CFM 1e-5, a box over a plane, up to
// four contact joints a step with Coulomb friction (dContactApprox1: the friction pyramid, mu a
// coefficient; without it mu is a force bound) and bounce = e at any speed (bounce_vel 0, as in
// the accuracy benchmark).
#include <ode/ode.h>

#include "cube_tosses.h"

namespace collision_response::bench::cube_tosses {
namespace {

struct OdeWorld {
  dWorldID world;
  dJointGroupID contacts;
  Contact contact;
};

void nearCallback(void* data, dGeomID first, dGeomID second) {
  auto* w = static_cast<OdeWorld*>(data);
  constexpr int kMaxContacts = 4;
  dContact contact[kMaxContacts];
  const int found = dCollide(first, second, kMaxContacts, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < found; ++i) {
    contact[i].surface.mode = dContactBounce | dContactApprox1;
    contact[i].surface.mu = w->contact.friction;
    contact[i].surface.bounce = w->contact.restitution;
    contact[i].surface.bounce_vel = 0;
    const dJointID joint = dJointCreateContact(w->world, w->contacts, &contact[i]);
    dJointAttach(joint, dGeomGetBody(first), dGeomGetBody(second));
  }
}

std::vector<Pose> play(const Contact& contact, const State& first, std::size_t samples) {
  static const bool initialised = (dInitODE2(0), true);
  (void)initialised;
  OdeWorld w{dWorldCreate(), dJointGroupCreate(0), contact};
  const dSpaceID space = dSimpleSpaceCreate(nullptr);
  dWorldSetGravity(w.world, 0, 0, -kGravity);
  dCreatePlane(space, 0, 0, 1, kTableTop);
  const dBodyID cube = dBodyCreate(w.world);
  dMass mass;
  dMassSetBoxTotal(&mass, kMass, kWidth, kWidth, kWidth);
  dBodySetMass(cube, &mass);
  const V& p = first.pose.position;
  dBodySetPosition(cube, p.x(), p.y(), p.z());
  const Q& q = first.pose.orientation;
  const dQuaternion turn = {q.w(), q.x(), q.y(), q.z()};
  dBodySetQuaternion(cube, turn);
  dBodySetLinearVel(cube, first.velocity.x(), first.velocity.y(), first.velocity.z());
  const V& w_world = first.angular_velocity;
  dBodySetAngularVel(cube, w_world.x(), w_world.y(), w_world.z());  // world frame
  const dGeomID geom = dCreateBox(space, kWidth, kWidth, kWidth);
  dGeomSetBody(geom, cube);

  std::vector<Pose> path;
  path.reserve(samples);
  for (std::size_t k = 0; k < samples; ++k) {
    if (k > 0) {
      for (int s = 0; s < kStepsPerSample; ++s) {
        dSpaceCollide(space, &w, &nearCallback);
        dWorldStep(w.world, kStep);
        dJointGroupEmpty(w.contacts);
      }
    }
    const dReal* at = dBodyGetPosition(cube);
    const dReal* r = dBodyGetQuaternion(cube);
    path.push_back(Pose{V(at[0], at[1], at[2]), Q(r[0], r[1], r[2], r[3]).normalized()});
  }
  dJointGroupDestroy(w.contacts);
  dSpaceDestroy(space);
  dWorldDestroy(w.world);
  return path;
}

}  // namespace

Peer odePeer() {
  return Peer{
      "ODE",
      std::string("ODE (") + (dCheckConfiguration("ODE_double_precision") ? "double" : "single") +
          " precision): dWorldStep, ERP 0.2, CFM 1e-5 (its defaults), up to 4 contacts, friction "
          "pyramid (dContactApprox1), bounce at any speed; 1036 Hz",
      true, [](const Contact& contact) -> Simulate {
        return [contact](const State& first, std::size_t samples) {
          return play(contact, first, samples);
        };
      }};
}

}  // namespace collision_response::bench::cube_tosses
