// seed_examples: calls the node's services on the examples of the seed's slides and prints the
// answers beside the closed forms. Used by the demo (launch/demo.launch).
#include <ros/ros.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>

#include "collision_response/ComputeCollision.h"
#include "collision_response/EstimateRestitution.h"

namespace {

using collision_response::ComputeCollision;
using collision_response::EstimateRestitution;

collision_response::Body body(const std::string& id, double mass, double velocity_x,
                              double velocity_y, const std::string& material, double position_x) {
  collision_response::Body result;
  result.id = id;
  result.mass = mass;
  result.radius = 0.03;
  result.material = material;
  result.position.x = position_x;
  result.velocity.x = velocity_x;
  result.velocity.y = velocity_y;
  return result;
}

std::string vectorText(const geometry_msgs::Vector3& v) {
  std::ostringstream out;
  out << std::setprecision(6) << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return out.str();
}

void printCollision(ros::ServiceClient& client, const std::string& title, ComputeCollision& call,
                    const std::string& expected) {
  std::cout << "\n== " << title << "\n";
  const auto& a = call.request.a;
  const auto& b = call.request.b;
  std::cout << "   a: " << a.id << ", m = " << a.mass << " kg, v = " << vectorText(a.velocity)
            << (a.material.empty() ? "" : ", " + a.material) << "\n";
  std::cout << "   b: " << b.id << ", m = " << b.mass << " kg, v = " << vectorText(b.velocity)
            << (b.material.empty() ? "" : ", " + b.material) << "\n";
  if (!client.call(call)) {
    std::cout << "   service call failed (is the node running?)\n";
    return;
  }
  const auto& r = call.response;
  if (!r.success) {
    std::cout << "   refused: " << r.message << "\n";
    return;
  }
  std::cout << "   e = " << r.restitution << ", normal " << vectorText(r.normal)
            << (r.oblique ? ", oblique" : ", direct") << "\n";
  std::cout << "   a' = " << vectorText(r.velocity_a) << " m/s, b' = " << vectorText(r.velocity_b)
            << " m/s\n";
  std::cout << "   impulse " << r.impulse << " N s, energy lost " << r.energy_lost << " J\n";
  std::cout << "   closed form: " << expected << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "seed_examples");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  const std::string service_ns =
      private_node.param<std::string>("service_ns", "collision_response");
  const std::string compute_name = service_ns + "/compute_collision";
  const std::string estimate_name = service_ns + "/estimate_restitution";
  if (!ros::service::waitForService(compute_name, ros::Duration(30.0)) ||
      !ros::service::waitForService(estimate_name, ros::Duration(30.0))) {
    std::cerr << "seed_examples: the services under " << service_ns << " did not come up\n";
    return 1;
  }
  ros::ServiceClient compute = node.serviceClient<ComputeCollision>(compute_name, true);
  ros::ServiceClient estimate = node.serviceClient<EstimateRestitution>(estimate_name, true);
  const double inf = std::numeric_limits<double>::infinity();
  std::cout << "Calling " << compute_name << " and " << estimate_name
            << " on the seed's examples.\n";

  ComputeCollision direct;
  direct.request.a = body("cue", 0.17, 2.0, 0.0, "billiard_ball", 0.0);
  direct.request.b = body("object", 0.17, 0.0, 0.0, "billiard_ball", 0.06);
  printCollision(compute, "Direct impact, equal billiard balls (pair coefficient, rule min)",
                 direct, "a' = (1 - e) v / 2 = 0.196, b' = (1 + e) v / 2 = 1.804");

  ComputeCollision combined;
  combined.request.a = body("a", 2.0, 3.0, 0.0, "", 0.0);
  combined.request.b = body("b", 1.0, -1.0, 0.0, "", 0.06);
  combined.request.restitution = 0.5;
  printCollision(compute, "Combined formulas, m_a = 2, m_b = 1, e = 0.5", combined,
                 "a' = (m_a v_a + m_b v_b + e m_b (v_b - v_a)) / (m_a + m_b) = 1, b' = 3");

  ComputeCollision wall;
  wall.request.a = body("tennis", 0.057, 10.0, 0.0, "tennis_ball", 0.0);
  wall.request.b = body("wall", inf, 0.0, 0.0, "concrete", 0.06);
  printCollision(compute, "Immovable wall (m_b = inf), tennis ball on concrete", wall,
                 "a' = -e v = -7.12 exactly");

  ComputeCollision plastic = combined;
  plastic.request.restitution = 0.0;
  printCollision(compute, "Totally plastic, e = 0", plastic,
                 "a' = b' = (m_a v_a + m_b v_b) / (m_a + m_b) = 5/3");

  ComputeCollision elastic = combined;
  elastic.request.restitution = 1.0;
  printCollision(compute, "Totally elastic, e = 1", elastic, "a' = 1/3, b' = 13/3, energy lost 0");

  ComputeCollision oblique;
  oblique.request.a = body("a", 1.0, 3.0, 4.0, "", 0.0);
  oblique.request.b = body("b", 1.0, 0.0, 0.0, "", 0.06);
  oblique.request.restitution = 1.0;
  printCollision(compute, "Oblique impact, line of impact x", oblique,
                 "only x changes: a' = (0, 4, 0), b' = (3, 0, 0)");

  ComputeCollision bad = combined;
  bad.request.a.mass = -1.0;
  printCollision(compute, "A bad request: negative mass", bad, "refused, naming a.mass");

  EstimateRestitution drop;
  drop.request.drop_height = 1.0;
  drop.request.bounce_height = 0.712 * 0.712;
  std::cout << "\n== e from a drop test: h = 1 m, h' = 0.506944 m\n";
  if (estimate.call(drop)) {
    std::cout << "   "
              << (drop.response.success ? drop.response.message
                                        : "refused: " + drop.response.message)
              << "\n   closed form: e = sqrt(h'/h) = 0.712, a tennis ball\n";
  } else {
    std::cout << "   service call failed\n";
  }
  return 0;
}
