// While the monitor's thread is blocked, every state received is used or counted with its reason
// (issue 41, item 2; doc/model.md, "Work per message, and threads").
//
// The test holds the monitor's thread itself: ImpactMonitorRos is given a node handle on a
// callback queue that the test does not service while it publishes 300 states of one ball at
// 200 Hz (as an update of 1.5 s would hold it), with ~queue_size 20, then one array of 700 states
// (~max_states 600). Then it services the queue. Counted exactly, since nothing of the queue is
// processed meanwhile: the intake receives all 1,000 states while the monitor is held
// (/diagnostics' `states received (total)`, `messages waiting` 20), the oldest 280 messages are
// dropped as `dropped: input queue full`, the 700 as `dropped: too many states in one message`
// (each state counted: it was 1 for the message), the newest 20 used.
//
// Before issue 41 the subscriptions' callbacks ran on that same queue: nothing was received
// while it was held, and roscpp's own queue (100) lost what did not fit, uncounted.
#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <map>
#include <string>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ros/impact_monitor_ros.h"

namespace collision_response {
namespace {

constexpr int kPublished = 300;
constexpr int kQueueSize = 20;
constexpr int kMaxStates = 600;
constexpr int kOversize = 700;  ///< the states of one array past ~max_states

core::Scene oneBallScene() {
  core::Scene scene;
  core::BodySpec ball;
  ball.id = "probe";
  ball.mass = 0.1;
  ball.radius = 0.05;
  ball.material = "tennis_ball";
  scene.bodies.push_back(ball);
  return scene;
}

std::map<std::string, std::string> diagnose(ImpactMonitorRos& monitor) {
  diagnostic_updater::DiagnosticStatusWrapper status;
  monitor.diagnose(status);
  std::map<std::string, std::string> values;
  for (const auto& value : status.values) values[value.key] = value.value;
  return values;
}

long valueOf(const std::map<std::string, std::string>& values, const std::string& key) {
  const auto found = values.find(key);
  return found == values.end() ? -1 : std::stol(found->second);
}

TEST(IntakeBlocked, WhileTheMonitorIsHeldEveryStateIsReceivedThenUsedOrCounted) {
  ros::NodeHandle node("intake_blocked");
  ros::CallbackQueue monitor_queue;  // the monitor's thread: serviced by the test only
  node.setCallbackQueue(&monitor_queue);
  MonitorParams params;
  params.queue_size = kQueueSize;
  params.max_states = kMaxStates;
  // The states keep the node's clock (stamped as published): their time line is the node's
  // clock at their arrival, however long they wait. Taken when processed, the hold below put
  // them further behind it than ~clock_jump_back and shifted their source onto a clock of its own.
  params.clock_jump_back = 0.25;
  ImpactMonitorRos monitor(node, oneBallScene(), params);

  ros::NodeHandle publisher_node;
  ros::Publisher publisher =
      publisher_node.advertise<BodyStateArray>("/intake_blocked/body_states", 1000);
  const ros::WallTime connecting = ros::WallTime::now();
  while (publisher.getNumSubscribers() == 0 && (ros::WallTime::now() - connecting).toSec() < 10) {
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_GT(publisher.getNumSubscribers(), 0u);
  ros::WallDuration(0.3).sleep();

  // A ball in free flight at 1 m/s, 300 states about 5 ms apart, each stamped as published.
  const ros::Time start = ros::Time::now();
  for (int k = 0; k < kPublished; ++k) {
    BodyStateArray array;
    array.header.stamp = ros::Time::now();
    BodyState state;
    state.header = array.header;
    state.header.frame_id = "world";
    state.id = "probe";
    state.pose.position.x = (array.header.stamp - start).toSec();
    state.pose.orientation.w = 1.0;
    state.twist.linear.x = 1.0;
    array.states.push_back(state);
    publisher.publish(array);
    ros::WallDuration(0.005).sleep();
  }
  // One array past ~max_states: refused whole, each of its states counted.
  BodyStateArray oversize;
  oversize.header.stamp = ros::Time::now();
  oversize.states.resize(kOversize);
  publisher.publish(oversize);
  const int received = kPublished + kOversize;

  // Held: every state is received, the newest 20 wait, the oldest are dropped and counted.
  std::map<std::string, std::string> held;
  const ros::WallTime waiting = ros::WallTime::now();
  do {
    ros::WallDuration(0.05).sleep();
    held = diagnose(monitor);
  } while (valueOf(held, "states received (total)") < received &&
           (ros::WallTime::now() - waiting).toSec() < 10);
  EXPECT_EQ(valueOf(held, "states received (total)"), received)
      << "states were lost before the node could count them";
  EXPECT_EQ(valueOf(held, "dropped: too many states in one message (total)"), kOversize);
  EXPECT_EQ(valueOf(held, "messages waiting"), kQueueSize);
  EXPECT_EQ(valueOf(held, "states used (total)"), 0);
  EXPECT_EQ(valueOf(held, "dropped: input queue full (total)"), kPublished - kQueueSize);

  // Held four times ~clock_jump_back longer, then released: the 20 are used, nothing else is
  // dropped, and their source keeps the node's clock.
  ros::WallDuration(1.0).sleep();
  const ros::WallTime releasing = ros::WallTime::now();
  std::map<std::string, std::string> done;
  do {
    monitor_queue.callAvailable(ros::WallDuration(0.05));
    done = diagnose(monitor);
  } while (valueOf(done, "messages waiting") != 0 &&
           (ros::WallTime::now() - releasing).toSec() < 10);
  EXPECT_EQ(valueOf(done, "messages waiting"), 0);
  EXPECT_EQ(valueOf(done, "states received (total)"), received);
  EXPECT_EQ(valueOf(done, "states used (total)"), kQueueSize);
  long dropped = 0;
  for (const auto& [key, value] : done) {
    if (key.rfind("dropped: ", 0) == 0) dropped += std::stol(value);
  }
  EXPECT_EQ(dropped, kPublished - kQueueSize + kOversize);
  EXPECT_EQ(valueOf(done, "states used (total)") + dropped,
            valueOf(done, "states received (total)"));
  for (const auto& [key, value] : done) {
    EXPECT_NE(key.rfind("clock offset of ", 0), 0u)
        << "a source that keeps the node's clock was shifted for waiting: " << key << " " << value;
  }
}

}  // namespace
}  // namespace collision_response

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "intake_blocked_test");
  ros::NodeHandle keep_alive;
  return RUN_ALL_TESTS();
}
