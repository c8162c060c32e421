// node_benchmark: drives a running collision_response node over ROS and measures it.
//   ~mode: "load"    publishes every body of ~scene (a gas) in one BodyStateArray at ~rate Hz
//                    for ~seconds, applying the impacts the node publishes (the scene player's
//                    loop), and reports the node's CPU share (from /proc/~pid/stat), the latency
//                    from publishing a state array to receiving the impacts it revealed
//                    (p50, p99), and the node's resident memory every ~memory_every s;
//          "service" calls ~service (a compute_collision service) and the empty service alternately
//          ~calls times
//                    each over persistent connections and reports both round trips.
//          "predict" calls ~service (a predict_impacts service, default
//                    /collision_response/predict_impacts, its node on config/scenes/serve.yaml)
//                    and empty_service's ~echo_prediction (the same bytes, no physics)
//                    alternately ~calls times each with the serve's request, over persistent
//                    connections; reports both round trips, both messages' sizes, the CPU per
//                    call of the node's main thread (which answers; ~pid, if given) and the cost
//                    of the answer in this process (the core's prediction on the node's scene,
//                    read from its ~scene).
//          "burden"  the work of one hard message (issue 13, item 9), ~kind: "stamps" publishes
//                    every body of ~scene in one array whose states' stamps are 10 us apart
//                    (~messages such arrays); "cluster" publishes the bodies of ~scene (a lattice
//                    of touching balls closing on its centre) twice, 0.01 s apart. It reports
//                    the CPU per message of the node's main thread (the monitor's; from
//                    /proc/~pid/task/~pid/stat, until it is idle again) and the worst round trip of
//                    ~service (compute_collision) called without pause from another thread
//                    meanwhile.
//          "startup" the scene loader and the monitor's construction (the node's start-up,
//                    parameters aside) for gases of 1,000 to 30,000 bodies, in this process.
// Results as JSON on stdout (scripts/performance.sh).
#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>

#include <time.h>
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ComputeCollision.h"
#include "collision_response/ImpactArray.h"
#include "collision_response/PredictImpacts.h"
#include "collision_response/core/materials.h"
#include "collision_response/core/playback.h"
#include "collision_response/core/prediction.h"
#include "collision_response/ros/collision_services.h"
#include "collision_response/ros/conversions.h"
#include "collision_response/ros/monitor_cycle.h"
#include "collision_response/ros/prediction_service.h"
#include "collision_response/ros/scene_loader.h"
#include "seed_request.h"

namespace {

using namespace collision_response;

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(fraction * static_cast<double>(values.size() - 1))];
}

/// CPU seconds (user + system) used so far by process `pid`, or by its thread `thread`.
double cpuSeconds(int pid, int thread = 0) {
  std::ifstream file(thread ? "/proc/" + std::to_string(pid) + "/task/" + std::to_string(thread) +
                                  "/stat"
                            : "/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(file, line);
  std::istringstream in(line.substr(line.rfind(')') + 2));
  std::string field;
  std::vector<std::string> fields;
  while (in >> field) fields.push_back(field);
  // After the command: state is field 3 of the whole line; utime and stime are 14 and 15.
  const double ticks = std::stod(fields.at(11)) + std::stod(fields.at(12));
  return ticks / static_cast<double>(sysconf(_SC_CLK_TCK));
}

double residentMegabytes(int pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/statm");
  double size = 0, resident = 0;
  file >> size >> resident;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1e6;
}

int load(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  XmlRpc::XmlRpcValue value;
  if (!private_node.getParam("scene", value)) return 2;
  auto scene = loadScene(value, private_node.resolveName("scene"));
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.error().message().c_str());
    return 2;
  }
  const double rate = private_node.param("rate", 100.0);
  const double seconds = private_node.param("seconds", 10.0);
  const double memory_every = private_node.param("memory_every", 10.0);
  const int pid = private_node.param("pid", 0);
  core::Playback playback(*scene, 1e-9, 0.0);
  ros::Publisher states = node.advertise<BodyStateArray>("body_states", 10);
  std::map<ros::Time, ros::WallTime> published;
  std::vector<double> latencies;
  std::size_t impacts = 0;
  ros::Time start;
  // The scene player's loop: each impact applied through the core (Playback::applyImpact with
  // the monitor's indexing of the bodies).
  const bool exact_contact = scene->detection == core::Detection::kContinuous;
  const core::ImpactMonitor indexing(*scene, core::MonitorSettings{});
  ros::Subscriber subscriber =
      node.subscribe<ImpactArray>("impacts", 100, [&](const ImpactArray::ConstPtr& message) {
        const auto sent = published.find(message->header.stamp);
        if (sent != published.end())
          latencies.push_back((ros::WallTime::now() - sent->second).toSec());
        for (const Impact& impact : message->impacts) {
          const auto record =
              toImpactRecord(impact, indexing, (impact.header.stamp - start).toSec());
          if (record) playback.applyImpact(indexing, *record, exact_contact);
          ++impacts;
        }
      });
  // The node's own view, from /diagnostics: mean and max from a message's arrival to the
  // publication of its impacts, per diagnostics period.
  std::vector<double> node_means, node_maxima;
  ros::Subscriber diagnostics = node.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        for (const auto& status : array->status) {
          if (status.name.find("impact monitor") == std::string::npos) continue;
          for (const auto& pair : status.values) {
            if (pair.key == "arrival to publication, mean (ms)")
              node_means.push_back(std::stod(pair.value));
            if (pair.key == "arrival to publication, max (ms)")
              node_maxima.push_back(std::stod(pair.value));
          }
        }
      });
  while (ros::ok() && states.getNumSubscribers() == 0) ros::WallDuration(0.05).sleep();
  ros::WallDuration(1.0).sleep();
  BodyStateArray array;
  array.states.resize(scene->bodies.size());
  for (std::size_t i = 0; i < scene->bodies.size(); ++i) {
    array.states[i].id = scene->bodies[i].id;
    array.states[i].pose.orientation.w = 1.0;
  }
  start = ros::Time::now();
  const double cpu_start = pid ? cpuSeconds(pid) : 0.0;
  const ros::WallTime wall_start = ros::WallTime::now();
  std::vector<std::pair<double, double>> memory;
  double next_memory = 0;
  const auto ticks = static_cast<long>(seconds * rate);
  for (long k = 0; k < ticks && ros::ok(); ++k) {
    const ros::WallTime due = wall_start + ros::WallDuration(static_cast<double>(k) / rate);
    while (ros::WallTime::now() < due) {
      ros::spinOnce();
      ros::WallDuration(0.0002).sleep();
    }
    const ros::Time stamp = start + ros::Duration(static_cast<double>(k) / rate);
    const double t = (stamp - start).toSec();
    array.header.stamp = stamp;
    for (std::size_t i = 0; i < array.states.size(); ++i) {
      BodyState& state = array.states[i];
      state.header.stamp = stamp;
      state.pose.position = toPointMsg(playback.position(i, t));
      state.twist.linear = toVector3Msg(playback.velocity(i, t));
    }
    published[stamp] = ros::WallTime::now();
    states.publish(array);
    if (pid && (ros::WallTime::now() - wall_start).toSec() >= next_memory) {
      memory.emplace_back((ros::WallTime::now() - wall_start).toSec(), residentMegabytes(pid));
      next_memory += memory_every;
    }
  }
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(0.5);
  while (ros::WallTime::now() < end) {
    ros::spinOnce();
    ros::WallDuration(0.001).sleep();
  }
  const double wall = (ros::WallTime::now() - wall_start).toSec();
  // Periods before the first state array report no latency (0): skip those.
  std::vector<double> means, maxima;
  for (std::size_t i = 0; i < node_means.size(); ++i) {
    if (node_maxima.at(i) > 0) {
      means.push_back(node_means[i]);
      maxima.push_back(node_maxima[i]);
    }
  }
  const double node_latency_mean = percentile(means, 0.5) * 1e-3;
  const double node_latency_max =
      maxima.empty() ? NAN : *std::max_element(maxima.begin(), maxima.end()) * 1e-3;
  const double cpu = pid ? cpuSeconds(pid) - cpu_start : NAN;
  std::printf(
      "{\"bodies\": %zu, \"rate\": %g, \"seconds\": %g, \"updates\": %ld, \"impacts\": %zu, "
      "\"cpu_share\": %g, \"latency_p50\": %g, \"latency_p99\": %g, \"latency_samples\": %zu, "
      "\"node_latency_median_of_means\": %g, \"node_latency_max\": %g, "
      "\"memory\": [",
      scene->bodies.size(), rate, seconds, ticks, impacts, cpu / wall, percentile(latencies, 0.5),
      percentile(latencies, 0.99), latencies.size(), node_latency_mean, node_latency_max);
  for (std::size_t i = 0; i < memory.size(); ++i) {
    std::printf("%s[%g, %g]", i ? ", " : "", memory[i].first, memory[i].second);
  }
  std::printf("]}\n");
  return 0;
}

int service(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  const int calls = private_node.param("calls", 2000);
  const std::string service_name =
      private_node.param<std::string>("service", "/collision_response/compute_collision");
  ros::ServiceClient compute = node.serviceClient<ComputeCollision>(service_name, true);
  ros::ServiceClient empty = node.serviceClient<std_srvs::Empty>("/empty_service/empty", true);
  if (!compute.waitForExistence(ros::Duration(20)) || !empty.waitForExistence(ros::Duration(20)))
    return 2;
  ComputeCollision collision;
  collision.request = testing::seedHeadOnRequest();
  std_srvs::Empty nothing;
  std::vector<double> compute_times, empty_times;
  using Clock = std::chrono::steady_clock;
  // The first 100 calls of each warm up; the order alternates so that neither service always
  // follows the other.
  for (int i = 0; i < 2 * (calls + 100); ++i) {
    const bool call_compute = (i % 4 == 0) || (i % 4 == 3);
    const auto t0 = Clock::now();
    if (call_compute ? !compute.call(collision) || !collision.response.success
                     : !empty.call(nothing)) {
      return 3;
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (i < 200) continue;
    (call_compute ? compute_times : empty_times).push_back(seconds);
  }
  const auto mean = [](const std::vector<double>& v) {
    double sum = 0;
    for (const double x : v) sum += x;
    return sum / static_cast<double>(v.size());
  };
  // Where the time goes: the node's own work per call, in this process (deserialising the
  // request, answering it, serialising the answer), against the whole round trip.
  const auto request_bytes = ros::serialization::serializeMessage(collision.request);
  const core::MaterialTable materials = core::MaterialTable::seed();
  constexpr int kInProcess = 100000;
  const auto w0 = Clock::now();
  std::size_t response_size = 0;
  for (int i = 0; i < kInProcess; ++i) {
    ComputeCollision::Request request;
    ros::serialization::IStream in(request_bytes.message_start,
                                   static_cast<std::uint32_t>(request_bytes.num_bytes - 4));
    ros::serialization::deserialize(in, request);
    ComputeCollision::Response response;
    answerComputeCollision(request, materials, response);
    const auto bytes = ros::serialization::serializeMessage(response);
    response_size = bytes.num_bytes;
  }
  const double in_process =
      std::chrono::duration<double>(Clock::now() - w0).count() / static_cast<double>(kInProcess);
  std::printf(
      "{\"calls\": %d, \"compute_mean\": %g, \"compute_p50\": %g, \"compute_p99\": %g, "
      "\"empty_mean\": %g, \"empty_p50\": %g, \"empty_p99\": %g, \"in_process\": %g, "
      "\"request_bytes\": %zu, \"response_bytes\": %zu}\n",
      calls, mean(compute_times), percentile(compute_times, 0.5), percentile(compute_times, 0.99),
      mean(empty_times), percentile(empty_times, 0.5), percentile(empty_times, 0.99), in_process,
      static_cast<std::size_t>(request_bytes.num_bytes), response_size);
  return 0;
}

/// CPU seconds (user + system) used so far by the calling thread.
double threadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

double average(const std::vector<double>& values) {
  double sum = 0;
  for (const double x : values) sum += x;
  return sum / static_cast<double>(values.size());
}

/// The serve of config/scenes/serve.yaml asked of ~predict_impacts: the scene's ball (mass 0)
/// from its initial state, its first two impacts (both on the table) within 1.2 s.
PredictImpacts::Request serveRequest() {
  PredictImpacts::Request request;
  request.header.frame_id = "world";
  request.body.id = "ball";
  request.body.position.x = -1.2;
  request.body.position.z = 1.0;
  request.body.velocity.x = 3.75;
  request.body.velocity.y = 0.25;
  request.body.velocity.z = -2.25;
  request.body.angular_velocity.y = 150.0;
  request.horizon = 1.2;
  request.max_impacts = 2;
  return request;
}

template <typename Message>
std::size_t serializedBytes(const Message& message) {
  return ros::serialization::serializationLength(message);
}

int predict(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  const int calls = private_node.param("calls", 2000);
  const std::string service_name =
      private_node.param<std::string>("service", "/collision_response/predict_impacts");
  ros::ServiceClient predictor = node.serviceClient<PredictImpacts>(service_name, true);
  ros::ServiceClient echo =
      node.serviceClient<PredictImpacts>("/empty_service/echo_prediction", true);
  if (!predictor.waitForExistence(ros::Duration(20)) || !echo.waitForExistence(ros::Duration(20)))
    return 2;
  // The node's scene, from its ~scene (the service's namespace), for the answer in this process.
  XmlRpc::XmlRpcValue value;
  const std::string scene_parameter = ros::names::parentNamespace(service_name) + "/scene";
  if (!node.getParam(scene_parameter, value)) {
    std::fprintf(stderr, "no scene at %s\n", scene_parameter.c_str());
    return 2;
  }
  const auto scene = loadScene(value, scene_parameter);
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.error().message().c_str());
    return 2;
  }
  const int pid = private_node.param("pid", 0);
  PredictImpacts prediction, echoed;
  prediction.request = echoed.request = serveRequest();
  std::vector<double> predict_times, echo_times;
  using Clock = std::chrono::steady_clock;
  // The first 100 calls of each warm up; the order alternates so that neither service always
  // follows the other. The node's main thread is idle but for the calls.
  double node_cpu = 0.0;
  for (int i = 0; i < 2 * (calls + 100); ++i) {
    if (i == 200 && pid) node_cpu = -cpuSeconds(pid, pid);
    const bool call_predict = (i % 4 == 0) || (i % 4 == 3);
    const auto t0 = Clock::now();
    if (call_predict ? !predictor.call(prediction) || !prediction.response.success
                     : !echo.call(echoed) || !echoed.response.success) {
      std::fprintf(stderr, "call %d failed: %s\n", i,
                   (call_predict ? prediction : echoed).response.message.c_str());
      return 3;
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (i < 200) continue;
    (call_predict ? predict_times : echo_times).push_back(seconds);
  }
  // JSON's null without ~pid.
  char node_cpu_per_call[32] = "null";
  if (pid) {
    std::snprintf(node_cpu_per_call, sizeof node_cpu_per_call, "%g",
                  (node_cpu + cpuSeconds(pid, pid)) / static_cast<double>(calls));
  }

  // The answer in this process (this thread's CPU), 10,000 times in five batches of each, the
  // two kinds alternating; the best batch of each stands for it (the machine is shared: a batch
  // slowed by another process's load is not the answer's cost).
  //   core:   core::predictImpacts on the node's scene, with the node's defaults (MonitorParams)
  //           and no live monitor (the node has had no body state);
  //   answer: the node's whole answer: deserialising the request, answerPredictImpacts on a cycle
  //           of the same scene (the request in the fixed frame), serialising the answer.
  core::PredictionRequest core_request;
  const auto body = std::find_if(scene->bodies.begin(), scene->bodies.end(),
                                 [&](const core::BodySpec& spec) { return spec.id == "ball"; });
  if (body == scene->bodies.end()) {
    std::fprintf(stderr, "the scene at %s has no body 'ball'\n", scene_parameter.c_str());
    return 2;
  }
  core_request.body = *body;
  core_request.state.position = toEigen(prediction.request.body.position);
  core_request.state.velocity = toEigen(prediction.request.body.velocity);
  core_request.state.angular_velocity = toEigen(prediction.request.body.angular_velocity);
  core_request.horizon = prediction.request.horizon;
  core_request.max_impacts = prediction.request.max_impacts;
  core_request.effects = scene->effects;
  const MonitorParams params;
  const core::MonitorSettings settings{params.contact_tolerance, params.body_timeout};
  const MonitorCycle cycle(*scene, params);
  const tf2::BufferCore tf;
  const auto request_bytes = ros::serialization::serializeMessage(prediction.request);
  constexpr int kBatches = 5, kBatch = 2000;
  std::size_t core_impacts = 0;
  double in_process = INFINITY, in_process_answer = INFINITY;
  for (int batch = 0; batch < kBatches; ++batch) {
    const double c0 = threadCpuSeconds();
    for (int i = 0; i < kBatch; ++i) {
      const auto answer = core::predictImpacts(*scene, nullptr, settings, core_request);
      if (!answer) {
        std::fprintf(stderr, "%s\n", answer.error().message().c_str());
        return 3;
      }
      core_impacts = answer->impacts.size();
    }
    in_process = std::min(in_process, (threadCpuSeconds() - c0) / kBatch);
    const double a0 = threadCpuSeconds();
    for (int i = 0; i < kBatch; ++i) {
      PredictImpacts::Request request;
      ros::serialization::IStream in(request_bytes.message_start,
                                     static_cast<std::uint32_t>(request_bytes.num_bytes - 4));
      ros::serialization::deserialize(in, request);
      PredictImpacts::Response response;
      answerPredictImpacts(request, cycle, tf, ros::Time(1.0), response);
      if (!response.success) {
        std::fprintf(stderr, "%s\n", response.message.c_str());
        return 3;
      }
      ros::serialization::serializeMessage(response);
    }
    in_process_answer = std::min(in_process_answer, (threadCpuSeconds() - a0) / kBatch);
  }
  std::printf(
      "{\"calls\": %d, \"predict_mean\": %g, \"predict_p50\": %g, \"predict_p99\": %g, "
      "\"echo_mean\": %g, \"echo_p50\": %g, \"echo_p99\": %g, \"in_process\": %g, "
      "\"in_process_answer\": %g, \"node_cpu_per_call\": %s, \"impacts\": %zu, "
      "\"core_impacts\": %zu, "
      "\"predict_request_bytes\": %zu, \"predict_response_bytes\": %zu, "
      "\"echo_request_bytes\": %zu, \"echo_response_bytes\": %zu, \"message\": \"%s\"}\n",
      calls, average(predict_times), percentile(predict_times, 0.5),
      percentile(predict_times, 0.99), average(echo_times), percentile(echo_times, 0.5),
      percentile(echo_times, 0.99), in_process, in_process_answer, node_cpu_per_call,
      prediction.response.impacts.size(), core_impacts, serializedBytes(prediction.request),
      serializedBytes(prediction.response), serializedBytes(echoed.request),
      serializedBytes(echoed.response), prediction.response.message.c_str());
  return 0;
}

/// Calls `service` (compute_collision, the seed's request) without pause until stopped, keeping
/// the worst round trip.
class ServiceProbe {
 public:
  ServiceProbe(ros::NodeHandle& node, const std::string& service)
      : client_(node.serviceClient<ComputeCollision>(service, true)) {}
  bool ready() { return client_.waitForExistence(ros::Duration(20)); }
  void start() {
    thread_ = std::thread([this] {
      ComputeCollision call;
      call.request = testing::seedHeadOnRequest();
      using Clock = std::chrono::steady_clock;
      while (!stop_) {
        const auto t0 = Clock::now();
        const bool ok = client_.call(call) && call.response.success;
        const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        std::lock_guard<std::mutex> lock(mutex_);
        if (!ok) ++failures_;
        worst_ = std::max(worst_, seconds);
        ++calls_;
      }
    });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  double worst() const { return worst_; }
  std::size_t calls() const { return calls_; }
  std::size_t failures() const { return failures_; }

 private:
  ros::ServiceClient client_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  double worst_ = 0.0;
  std::size_t calls_ = 0, failures_ = 0;
};

/// Waits until the main thread of process `pid` (the monitor's: the services have a thread of
/// their own) has used no CPU for `quiet` s; its CPU seconds then.
double waitIdle(int pid, double quiet = 0.5, double timeout = 900.0) {
  const auto cpuSeconds = [](int process) { return ::cpuSeconds(process, process); };
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  double last = cpuSeconds(pid);
  ros::WallTime still = ros::WallTime::now();
  while (ros::ok() && ros::WallTime::now() < end) {
    ros::WallDuration(0.05).sleep();
    ros::spinOnce();
    const double now = cpuSeconds(pid);
    if (now > last) {
      last = now;
      still = ros::WallTime::now();
    } else if ((ros::WallTime::now() - still).toSec() >= quiet) {
      return now;
    }
  }
  return last;
}

int burden(ros::NodeHandle& node, ros::NodeHandle& private_node) {
  XmlRpc::XmlRpcValue value;
  if (!private_node.getParam("scene", value)) return 2;
  auto scene = loadScene(value, private_node.resolveName("scene"));
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.error().message().c_str());
    return 2;
  }
  const std::string kind = private_node.param<std::string>("kind", "stamps");
  const int messages = kind == "cluster" ? 1 : private_node.param("messages", 5);
  const int pid = private_node.param("pid", 0);
  const std::string service =
      private_node.param<std::string>("service", "/collision_response/compute_collision");
  ros::Publisher states = node.advertise<BodyStateArray>("body_states", 10);
  std::size_t impacts = 0;
  ros::Subscriber subscriber = node.subscribe<ImpactArray>(
      "impacts", 100, [&](const ImpactArray::ConstPtr& m) { impacts += m->impacts.size(); });
  while (ros::ok() && states.getNumSubscribers() == 0) ros::WallDuration(0.05).sleep();
  ros::WallDuration(1.0).sleep();
  ServiceProbe probe(node, service);
  if (!probe.ready() || pid == 0) return 2;
  const core::Playback playback(*scene, 1e-9, 0.0);
  const auto array_at = [&](const ros::Time& stamp, double t, double spacing) {
    BodyStateArray array;
    array.header.stamp = stamp;
    array.states.resize(scene->bodies.size());
    for (std::size_t i = 0; i < scene->bodies.size(); ++i) {
      BodyState& state = array.states[i];
      state.id = scene->bodies[i].id;
      state.header.stamp = stamp + ros::Duration(spacing * static_cast<double>(i));
      state.header.frame_id = scene->fixed_frame;
      state.pose.orientation.w = 1.0;
      const double at = t + spacing * static_cast<double>(i);
      state.pose.position = toPointMsg(playback.position(i, at));
      state.twist.linear = toVector3Msg(playback.velocity(i, at));
    }
    return array;
  };
  const ros::Time start = ros::Time::now();
  if (kind == "cluster") {
    // The tracks first (no step yet), then the step that meets the whole cluster at its start.
    states.publish(array_at(start, 0.0, 0.0));
    waitIdle(pid);
  }
  probe.start();
  const double cpu_before = waitIdle(pid);
  const ros::WallTime began = ros::WallTime::now();
  for (int m = 0; m < messages; ++m) {
    const double t = kind == "cluster" ? 0.01 : 0.5 * (m + 1);
    states.publish(array_at(start + ros::Duration(t), t, kind == "cluster" ? 0.0 : 1e-5));
    ros::WallDuration(0.2).sleep();
  }
  const double cpu_after = waitIdle(pid);
  const double wall = (ros::WallTime::now() - began).toSec();
  probe.stop();
  std::printf(
      "{\"kind\": \"%s\", \"bodies\": %zu, \"messages\": %d, \"cpu_per_message\": %g, "
      "\"wall\": %g, \"impacts\": %zu, \"service_calls\": %zu, \"service_failures\": %zu, "
      "\"service_worst\": %g}\n",
      kind.c_str(), scene->bodies.size(), messages, (cpu_after - cpu_before) / messages, wall,
      impacts, probe.calls(), probe.failures(), probe.worst());
  return 0;
}

/// A gas of `count` bodies as the scene file would give it, with six walls.
XmlRpc::XmlRpcValue gasScene(int count) {
  XmlRpc::XmlRpcValue scene;
  scene["fixed_frame"] = "world";
  scene["materials"]["elastic"]["restitution"] = 1.0;
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count))));
  for (int i = 0; i < count; ++i) {
    XmlRpc::XmlRpcValue body;
    body["id"] = "gas_" + std::to_string(1000000 + i);
    body["mass"] = 0.1;
    body["radius"] = 0.05;
    body["material"] = "elastic";
    body["position"][0] = 0.25 + 0.5 * (i % side);
    body["position"][1] = 0.25 + 0.5 * ((i / side) % side);
    body["position"][2] = 0.25 + 0.5 * (i / (side * side));
    scene["bodies"][i] = body;
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      XmlRpc::XmlRpcValue wall;
      wall["id"] = "wall_" + std::to_string(axis) + (sign > 0 ? "_low" : "_high");
      wall["type"] = "plane";
      for (int k = 0; k < 3; ++k) wall["normal"][k] = k == axis ? sign : 0.0;
      wall["offset"] = sign > 0 ? 0.0 : -0.5 * side;
      wall["material"] = "elastic";
      scene["obstacles"][scene["obstacles"].getType() == XmlRpc::XmlRpcValue::TypeArray
                             ? scene["obstacles"].size()
                             : 0] = wall;
    }
  }
  return scene;
}

int startup(ros::NodeHandle& private_node) {
  const int repeats = private_node.param("repeats", 3);
  std::printf("{\"startup\": [");
  bool first = true;
  for (const int count : {1000, 3000, 10000, 30000}) {
    const XmlRpc::XmlRpcValue value = gasScene(count);
    double best = INFINITY;
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto scene = loadScene(value, "/startup/scene");
      if (!scene) {
        std::fprintf(stderr, "%s\n", scene.error().message().c_str());
        return 2;
      }
      const MonitorCycle cycle(*scene, MonitorParams{});
      best = std::min(best,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("%s[%d, %g]", first ? "" : ", ", count, best);
    first = false;
  }
  std::printf("]}\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "node_benchmark");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  const std::string mode = private_node.param<std::string>("mode", "load");
  if (mode == "service") return service(node, private_node);
  if (mode == "predict") return predict(node, private_node);
  if (mode == "burden") return burden(node, private_node);
  if (mode == "startup") return startup(private_node);
  return load(node, private_node);
}
