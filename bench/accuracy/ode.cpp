// ODE on the benchmark's scenes (only in the benchmark; the product never links ODE).
#include <ode/ode.h>

#include <list>
#include <map>

#include "collision_response/core/triangle_mesh.h"
#include "harness.h"

namespace collision_response::bench {
namespace {

struct OdeWorld {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  const core::Scene* scene;
  std::map<dGeomID, std::string> material;
};

void nearCallback(void* data, dGeomID first, dGeomID second) {
  auto* w = static_cast<OdeWorld*>(data);
  dContact contact[4];
  const int found = dCollide(first, second, 4, &contact[0].geom, sizeof(dContact));
  if (found == 0) return;
  const double e = *w->scene->materials.restitution(w->material.at(first), w->material.at(second));
  for (int i = 0; i < found; ++i) {
    contact[i].surface.mode = dContactBounce;
    contact[i].surface.mu = 0;
    contact[i].surface.bounce = e;
    contact[i].surface.bounce_vel = 0;
    const dJointID joint = dJointCreateContact(w->world, w->contacts, &contact[i]);
    dJointAttach(joint, dGeomGetBody(first), dGeomGetBody(second));
  }
}

}  // namespace

Engine odeEngine() {
  return [](const core::Scene& scene, const Play& play) {
    static const bool initialised = (dInitODE2(0), true);
    (void)initialised;
    OdeWorld w{dWorldCreate(), dHashSpaceCreate(nullptr), dJointGroupCreate(0), &scene, {}};
    const V g = scene.effects.gravity ? scene.gravity : V::Zero();
    dWorldSetGravity(w.world, g.x(), g.y(), g.z());
    std::vector<dBodyID> bodies;
    for (const core::BodySpec& spec : scene.bodies) {
      const dBodyID body = dBodyCreate(w.world);
      dMass mass;
      dMassSetSphereTotal(&mass, spec.mass, spec.radius);
      dBodySetMass(body, &mass);
      dBodySetPosition(body, spec.position.x(), spec.position.y(), spec.position.z());
      dBodySetLinearVel(body, spec.velocity.x(), spec.velocity.y(), spec.velocity.z());
      dBodySetAutoDisableFlag(body, 0);
      const dGeomID geom = dCreateSphere(w.space, spec.radius);
      dGeomSetBody(geom, body);
      w.material[geom] = spec.material;
      bodies.push_back(body);
    }
    std::list<std::pair<std::vector<double>, std::vector<dTriIndex>>> trimesh_arrays;
    std::vector<dTriMeshDataID> trimesh_data;
    for (std::size_t o = 0; o < scene.obstacles.size(); ++o) {
      const core::ObstacleSpec& spec = scene.obstacles[o];
      dGeomID geom;
      if (spec.shape == core::ObstacleShape::kPlane) {
        const V n = spec.normal.normalized();
        geom = dCreatePlane(w.space, n.x(), n.y(), n.z(), spec.offset);
      } else if (spec.shape == core::ObstacleShape::kMesh) {
        // dGeomTriMesh over the mesh's triangles (its data kept until the run ends).
        auto& [vertices, indices] = trimesh_arrays.emplace_back();
        for (const V& p : spec.mesh->vertices())
          vertices.insert(vertices.end(), {p.x(), p.y(), p.z()});
        for (const auto& t : spec.mesh->triangles()) {
          indices.insert(indices.end(), {static_cast<dTriIndex>(t[0]), static_cast<dTriIndex>(t[1]),
                                         static_cast<dTriIndex>(t[2])});
        }
        const dTriMeshDataID data = dGeomTriMeshDataCreate();
        dGeomTriMeshDataBuildDouble(data, vertices.data(), 3 * sizeof(double),
                                    static_cast<int>(vertices.size() / 3), indices.data(),
                                    static_cast<int>(indices.size()), 3 * sizeof(dTriIndex));
        trimesh_data.push_back(data);
        geom = dCreateTriMesh(w.space, data, nullptr, nullptr, nullptr);
      } else if (spec.shape == core::ObstacleShape::kBox) {  // along the axes
        geom = dCreateBox(w.space, spec.size.x(), spec.size.y(), spec.size.z());
        dGeomSetPosition(geom, spec.position.x(), spec.position.y(), spec.position.z());
      } else {
        geom = dCreateSphere(w.space, spec.radius);
        dGeomSetPosition(geom, spec.position.x(), spec.position.y(), spec.position.z());
      }
      w.material[geom] = spec.material;
      if (o < play.obstacle_velocities.size() && play.obstacle_velocities[o] != V::Zero()) {
        // A kinematic body carries it at its velocity.
        const dBodyID carrier = dBodyCreate(w.world);
        dBodySetKinematic(carrier);
        dBodySetPosition(carrier, spec.position.x(), spec.position.y(), spec.position.z());
        const V& v = play.obstacle_velocities[o];
        dBodySetLinearVel(carrier, v.x(), v.y(), v.z());
        dGeomSetBody(geom, carrier);
      }
    }

    Run run;
    const auto updates = static_cast<long>(std::llround(play.duration * play.rate));
    const double dt = 1.0 / play.rate;
    std::vector<V> positions(bodies.size()), velocities(bodies.size());
    for (long k = 0; k <= updates; ++k) {
      if (k > 0) {
        dSpaceCollide(w.space, &w, &nearCallback);
        dWorldStep(w.world, dt);
        dJointGroupEmpty(w.contacts);
      }
      for (std::size_t i = 0; i < bodies.size(); ++i) {
        const dReal* p = dBodyGetPosition(bodies[i]);
        const dReal* v = dBodyGetLinearVel(bodies[i]);
        positions[i] = V(p[0], p[1], p[2]);
        velocities[i] = V(v[0], v[1], v[2]);
      }
      run.record(play, static_cast<double>(k) * dt, positions, velocities);
    }
    dJointGroupDestroy(w.contacts);
    dSpaceDestroy(w.space);
    for (const dTriMeshDataID data : trimesh_data) dGeomTriMeshDataDestroy(data);
    dWorldDestroy(w.world);
    return run;
  };
}

}  // namespace collision_response::bench
