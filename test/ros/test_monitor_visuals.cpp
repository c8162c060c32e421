// Markers, diagnostics and dynamic_reconfigure of the node, over a real master.
//
// Closed forms. a (tennis ball) at x = t, b (billiard ball) at x = 1 - t, both 1 kg, radius
// 0.1 m, y = 0, z = 1: the gap 0.8 m closes at 2 m/s, contact at t = 0.4 s at x = 0.5. The pair
// is unmeasured; the scene's rule min gives e = min(0.712, 0.804) = 0.712. Equal masses: the
// normal impulse is (1 + e) m v_rel / 2 = 1.712 * 2 / 2 = 1.712 N s; with the default scale of
// 0.2 m per N s the arrow runs from (0.5, 0, 1) to (0.5 + 0.3424, 0, 1).
// After the tuning to rule max, c and d do the same 2 s later: e = max(0.712, 0.804) = 0.804.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <visualization_msgs/MarkerArray.h>

#include <functional>
#include <map>

#include "monitor_harness.h"

namespace collision_response::testing {
namespace {

class Visuals : public ::testing::Test {
 protected:
  void SetUp() override {
    markers_ = harness_.node().subscribe<visualization_msgs::MarkerArray>(
        "markers", 100, [this](const visualization_msgs::MarkerArray::ConstPtr& array) {
          for (const auto& marker : array->markers) markers_received_.push_back(marker);
        });
    diagnostics_ = harness_.node().subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
          for (const auto& status : array->status) {
            if (status.name.find("impact monitor") != std::string::npos)
              statuses_.push_back(status);
          }
        });
    ASSERT_TRUE(harness_.connect());
    ASSERT_TRUE(MonitorHarness::waitFor([this] { return markers_.getNumPublishers() > 0; }, 20));
  }

  /// Publishes the pair (first, second) as in the closed form, from `start` + `offset`.
  void collide(const std::string& first, const std::string& second, double y,
               const ros::Time& start) {
    for (int k = 0; k <= 10; ++k) {
      const double t = 0.1 * k;
      harness_.publish(
          start + ros::Duration(0, 100000000 * k),
          {StateSpec{first, Eigen::Vector3d(t, y, 1), Eigen::Vector3d(1, 0, 0)},
           StateSpec{second, Eigen::Vector3d(1 - t, y, 1), Eigen::Vector3d(-1, 0, 0)}});
      ros::WallDuration(0.02).sleep();
      ros::spinOnce();
    }
  }

  std::vector<visualization_msgs::Marker> markersIn(const std::string& ns) const {
    std::vector<visualization_msgs::Marker> found;
    for (const auto& marker : markers_received_) {
      if (marker.ns == ns) found.push_back(marker);
    }
    return found;
  }

  static std::string value(const diagnostic_msgs::DiagnosticStatus& status,
                           const std::string& key) {
    for (const auto& pair : status.values) {
      if (pair.key == key) return pair.value;
    }
    return "<missing>";
  }

  /// Waits for a status for which `done` holds; it is left in `found`.
  bool waitForStatus(const std::function<bool(const diagnostic_msgs::DiagnosticStatus&)>& done,
                     diagnostic_msgs::DiagnosticStatus& found, double timeout = 10.0) {
    return MonitorHarness::waitFor(
        [&] {
          for (const auto& status : statuses_) {
            if (done(status)) {
              found = status;
              return true;
            }
          }
          return false;
        },
        timeout);
  }

  dynamic_reconfigure::Config reconfigure(
      const std::vector<std::pair<std::string, std::string>>& strings,
      const std::vector<std::pair<std::string, double>>& doubles) {
    dynamic_reconfigure::Reconfigure call;
    for (const auto& [name, text] : strings) {
      dynamic_reconfigure::StrParameter parameter;
      parameter.name = name;
      parameter.value = text;
      call.request.config.strs.push_back(parameter);
    }
    for (const auto& [name, number] : doubles) {
      dynamic_reconfigure::DoubleParameter parameter;
      parameter.name = name;
      parameter.value = number;
      call.request.config.doubles.push_back(parameter);
    }
    EXPECT_TRUE(ros::service::waitForService("/collision_response/set_parameters", 20000));
    EXPECT_TRUE(ros::service::call("/collision_response/set_parameters", call));
    return call.response.config;
  }

  static std::string stringOf(const dynamic_reconfigure::Config& config, const std::string& name) {
    for (const auto& parameter : config.strs) {
      if (parameter.name == name) return parameter.value;
    }
    return "<missing>";
  }
  static double doubleOf(const dynamic_reconfigure::Config& config, const std::string& name) {
    for (const auto& parameter : config.doubles) {
      if (parameter.name == name) return parameter.value;
    }
    return NAN;
  }

  MonitorHarness harness_;
  ros::Subscriber markers_;
  ros::Subscriber diagnostics_;
  std::vector<visualization_msgs::Marker> markers_received_;
  std::vector<diagnostic_msgs::DiagnosticStatus> statuses_;
};

TEST_F(Visuals, MarkersDiagnosticsAndLiveTuning) {
  const ros::Time start = baseStamp();
  collide("a", "b", 0.0, start);
  ASSERT_TRUE(harness_.waitForImpact("a"));
  ASSERT_TRUE(MonitorHarness::waitFor([this] { return !markersIn("impacts").empty(); }, 5));

  // The impact: an arrow along the normal, as long as the impulse says, and a contact point.
  const auto arrows = markersIn("impacts");
  ASSERT_EQ(arrows.size(), 1u);
  const auto& arrow = arrows[0];
  EXPECT_EQ(arrow.type, visualization_msgs::Marker::ARROW);
  EXPECT_EQ(arrow.header.frame_id, "world");
  EXPECT_NEAR((arrow.header.stamp - start).toSec(), 0.4, 1e-9);
  ASSERT_EQ(arrow.points.size(), 2u);
  EXPECT_NEAR(arrow.points[0].x, 0.5, 1e-9);
  EXPECT_NEAR(arrow.points[0].z, 1.0, 1e-9);
  EXPECT_NEAR(arrow.points[1].x - arrow.points[0].x, 0.2 * 1.712, 1e-9);
  EXPECT_NEAR(arrow.points[1].y - arrow.points[0].y, 0.0, 1e-12);
  EXPECT_NEAR(arrow.points[1].z - arrow.points[0].z, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(arrow.lifetime.toSec(), 0.5);
  const auto contacts = markersIn("contacts");
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].id, arrow.id);
  EXPECT_NEAR(contacts[0].pose.position.x, 0.5, 1e-9);
  EXPECT_DOUBLE_EQ(contacts[0].lifetime.toSec(), 0.5);

  // Bodies: spheres of their diameter, ids by sorted id (a 0, b 1), coloured by material.
  const auto bodies = markersIn("bodies");
  ASSERT_FALSE(bodies.empty());
  std::map<int, visualization_msgs::Marker> last;
  for (const auto& marker : bodies) last[marker.id] = marker;
  ASSERT_EQ(last.count(0), 1u);
  ASSERT_EQ(last.count(1), 1u);
  for (const int id : {0, 1}) {
    EXPECT_EQ(last[id].type, visualization_msgs::Marker::SPHERE);
    EXPECT_EQ(last[id].action, visualization_msgs::Marker::ADD);
    EXPECT_DOUBLE_EQ(last[id].scale.x, 0.2);
    EXPECT_EQ(last[id].color.a, 1.0f);
  }
  EXPECT_EQ(last[0].text, "a");
  EXPECT_EQ(last[1].text, "b");
  EXPECT_TRUE(last[0].color.r != last[1].color.r || last[0].color.g != last[1].color.g ||
              last[0].color.b != last[1].color.b)
      << "a tennis ball and a billiard ball share a colour";
  // c and d have sent no state: not drawn (deleted).
  ASSERT_EQ(last.count(2), 1u);
  EXPECT_EQ(last[2].action, visualization_msgs::Marker::DELETE);

  // Obstacles: the floor a thin square whose z axis is its normal, the boulder a sphere.
  const auto obstacles = markersIn("obstacles");
  std::map<int, visualization_msgs::Marker> shapes;
  for (const auto& marker : obstacles) shapes[marker.id] = marker;
  ASSERT_EQ(shapes.size(), 4u);
  const auto& boulder = shapes[0];  // "boulder" < "floor"
  EXPECT_EQ(boulder.text, "boulder");
  EXPECT_EQ(boulder.type, visualization_msgs::Marker::SPHERE);
  EXPECT_DOUBLE_EQ(boulder.pose.position.x, 5.0);
  EXPECT_DOUBLE_EQ(boulder.scale.x, 1.0);
  const auto& floor = shapes[1];
  EXPECT_EQ(floor.type, visualization_msgs::Marker::CUBE);
  EXPECT_DOUBLE_EQ(floor.pose.orientation.w, 1.0);  // normal +z: no turn
  EXPECT_LT(floor.scale.z, floor.scale.x);
  EXPECT_EQ(floor.color.r, floor.color.g);  // concrete is grey
  // A capsule (ids in name order: boulder, floor, rod, table): its segment a cylinder along z,
  // its ends a sphere list.
  const auto& rod = shapes[2];
  EXPECT_EQ(rod.text, "rod");
  EXPECT_EQ(rod.type, visualization_msgs::Marker::CYLINDER);
  EXPECT_DOUBLE_EQ(rod.scale.x, 0.1);
  EXPECT_DOUBLE_EQ(rod.scale.z, 0.4);
  EXPECT_DOUBLE_EQ(rod.pose.position.x, -2.0);
  const auto ends = markersIn("obstacle_ends");
  ASSERT_FALSE(ends.empty());
  ASSERT_EQ(ends.back().points.size(), 2u);
  EXPECT_DOUBLE_EQ(ends.back().points[0].z, 1.2);
  EXPECT_DOUBLE_EQ(ends.back().points[1].z, 0.8);
  EXPECT_DOUBLE_EQ(ends.back().scale.x, 0.1);
  // A box turned a quarter about z: a cube of its size, turned with it.
  const auto& table = shapes[3];
  EXPECT_EQ(table.type, visualization_msgs::Marker::CUBE);
  EXPECT_DOUBLE_EQ(table.scale.x, 1.0);
  EXPECT_DOUBLE_EQ(table.scale.y, 0.6);
  EXPECT_DOUBLE_EQ(table.scale.z, 0.05);
  EXPECT_DOUBLE_EQ(table.pose.position.z, 0.725);
  EXPECT_NEAR(table.pose.orientation.z, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(table.pose.orientation.w, std::sqrt(0.5), 1e-15);

  // Diagnostics: the node's health, with what it tracks and what it dropped.
  diagnostic_msgs::DiagnosticStatus status;
  ASSERT_TRUE(waitForStatus(
      [](const auto& s) { return value(s, "impacts published (total)") == "1"; }, status));
  EXPECT_EQ(value(status, "bodies in the scene"), "4");
  EXPECT_EQ(value(status, "bodies tracked"), "2");
  EXPECT_EQ(value(status, "detection"), "continuous");
  EXPECT_EQ(value(status, "combine rule"), "min");
  harness_.publish(start + ros::Duration(1.5),
                   {StateSpec{"ghost", Eigen::Vector3d(0, 0, 5), Eigen::Vector3d::Zero()}});
  ASSERT_TRUE(waitForStatus(
      [](const auto& s) {
        return s.level == diagnostic_msgs::DiagnosticStatus::WARN &&
               s.message.find("unknown id") != std::string::npos;
      },
      status));
  EXPECT_EQ(value(status, "dropped: unknown id (total)"), "1");

  // Live tuning: refused values are named and the values in use kept.
  auto config = reconfigure({{"detection", "sideways"}}, {});
  EXPECT_EQ(stringOf(config, "detection"), "continuous");
  EXPECT_TRUE(harness_.waitForWarning({"detection", "sideways"}));
  config = reconfigure({}, {{"restitution_threshold", -1.0}});
  EXPECT_EQ(doubleOf(config, "restitution_threshold"), 0.0);
  EXPECT_TRUE(harness_.waitForWarning({"restitution_threshold", "-1"}));
  config = reconfigure({{"restitution_combine", "max"}}, {});
  EXPECT_EQ(stringOf(config, "restitution_combine"), "max");
  statuses_.clear();
  ASSERT_TRUE(
      waitForStatus([](const auto& s) { return value(s, "combine rule") == "max"; }, status));

  // And the new rule acts: c and d meet with e = max(0.712, 0.804).
  collide("c", "d", 3.0, start + ros::Duration(2.0));
  ASSERT_TRUE(harness_.waitForImpact("c"));
  const Impact impact = harness_.impactsOf("c").at(0);
  EXPECT_EQ(impact.restitution, 0.804);
  EXPECT_NEAR(impact.impulse, 1.804, 1e-9);
}

}  // namespace
}  // namespace collision_response::testing

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "monitor_visuals_test");
  ros::NodeHandle node;
  return RUN_ALL_TESTS();
}
