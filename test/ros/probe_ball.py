"""A probe ball for the node's load tests (prediction_load, robot_links, fast_bag, under_load):
its closed form, its states, and what the node says of it.

The probe (r = R, e = 1 on concrete) bounces on the floor z = 0 from H above contact: dropped from
rest at its top at t0, it meets the floor at t0 + TF + k T, TF = sqrt(2 H / g), T = 2 TF (e = 1:
every flight the same). The tests publish its closed-form state at 100 Hz, stamped with the
node's clock, and check that the node finds each of those impacts at its instant.
"""
import math
import subprocess
import threading
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TransformStamped
from collision_response.msg import BodyState, BodyStateArray, ImpactArray

G, R, H = 9.81, 0.05, 0.2
TF = math.sqrt(2 * H / G)
T = 2 * TF


def probe_state(t0, t):
    """The probe at t (s after t0 on the same clock): height and vertical speed in closed form."""
    tau = math.fmod(t - t0 + TF, T) - TF  # time since the top of its current flight
    return R + H - 0.5 * G * tau * tau, -G * tau


def ball_state(body, stamp, x, z, vz):
    """A ball's state in the world frame: at (x, 0, z), moving at vz along z."""
    message = BodyState()
    message.header.stamp = stamp
    message.header.frame_id = "world"
    message.id = body
    message.pose.position.x, message.pose.position.z = x, z
    message.pose.orientation.w = 1.0
    message.twist.linear.z = vz
    return message


def bounce_instants(t0, last):
    """The probe's impacts from t0 to 20 ms before its last state (the node's answer to that one
    may still be on its way)."""
    instants, k = [], 0
    while t0 + TF + k * T < last - 0.02:
        instants.append(t0 + TF + k * T)
        k += 1
    return instants


def missing_instants(expected, found, tolerance=1e-6):
    return [t for t in expected if not any(abs(f - t) < tolerance for f in found)]


def check_bounces(test, listener, t0, last, at_least, dropped=0):
    """Each of the probe's impacts from t0 to its last state is on the node's impacts at its
    closed form (1e-6 s), and there are at least `at_least` of them; with `dropped` states
    counted as dropped, at most that many may be missing. Returns (expected, missing)."""
    expected = bounce_instants(t0, last)
    found = listener.impact_instants("probe")
    test.assertGreaterEqual(len(expected), at_least)
    missing = missing_instants(expected, found)
    test.assertLessEqual(len(missing), dropped,
                         "probe impacts not found (%d of %d found, %d states dropped; found: %s)"
                         % (len(expected) - len(missing), len(expected), dropped, found))
    return expected, missing


def check_links_untouched(test, samples):
    """Each update, as /diagnostics showed it: at most 8 link frames looked up (static ones once,
    then 8 an update in turn) and none placed again (no link is near a body)."""
    test.assertGreater(len(samples), 5)
    for sample in samples:
        test.assertLessEqual(int(sample["obstacle frames looked up, last update"]), 8, sample)
        test.assertEqual(int(sample["obstacle placements, last update"]), 0, sample)


def static_link_frames(count, name):
    """`count` frames on a grid 10 m and more from the probe (50 along x, 0.2 m apart), for
    /tf_static: the links of a robot that no body reaches."""
    frames = []
    for i in range(count):
        frame = TransformStamped()
        frame.header.stamp = rospy.Time.now()
        frame.header.frame_id = "world"
        frame.child_frame_id = name(i)
        frame.transform.translation.x = 10.0 + 0.2 * (i % 50)
        frame.transform.translation.y = 0.2 * (i // 50)
        frame.transform.translation.z = 0.5
        frame.transform.rotation.w = 1.0
        frames.append(frame)
    return frames


def wait_for_subscribers(publishers, timeout=30.0):
    deadline = time.monotonic() + timeout
    while (any(p.get_num_connections() == 0 for p in publishers)
           and time.monotonic() < deadline):
        time.sleep(0.05)


class NodeListener:
    """The node's impacts (on `impacts_topic`) and its /diagnostics (statuses named `node...`),
    each sample with the monotonic instant it came."""

    def __init__(self, impacts_topic, node):
        self.lock = threading.Lock()
        self.impacts = []
        self.samples = []
        rospy.Subscriber(impacts_topic, ImpactArray, self._on_impacts, queue_size=1000)
        rospy.Subscriber("/diagnostics", DiagnosticArray,
                         lambda message: self._on_diagnostics(message, node))

    def _on_impacts(self, message):
        with self.lock:
            self.impacts.extend(message.impacts)

    def _on_diagnostics(self, message, node):
        with self.lock:
            self.samples.extend((time.monotonic(), {v.key: v.value for v in s.values})
                                for s in message.status if s.name.startswith(node))

    def impact_instants(self, body):
        with self.lock:
            return sorted(i.header.stamp.to_sec() for i in self.impacts
                          if body in (i.body_a, i.body_b))

    def values_since(self, began):
        with self.lock:
            return [values for at, values in self.samples if at > began]

    def drained(self, published, timeout=20.0, idle=True):
        """The last /diagnostics once nothing waits (and, with `idle`, no update runs) and every
        one of the `published` states was received; the last seen after `timeout` s."""
        deadline = time.monotonic() + timeout
        values = {}
        while time.monotonic() < deadline:
            time.sleep(0.5)
            with self.lock:
                if self.samples:
                    values = self.samples[-1][1]
            if (values.get("messages waiting") == "0"
                    and (not idle or float(values.get("update in progress (s)", "1")) == 0)
                    and int(values.get("states received (total)", "0")) >= published):
                break
        return values


def play_probe(publisher, run, x=-2.0, each=None):
    """Publishes the probe's closed-form state at 100 Hz for `run` s, each in a BodyStateArray
    stamped with the node's clock, and calls `each(now, t0)` after each (another source's
    states, say). Returns t0, the last state's instant and how many states were published."""
    t0 = rospy.Time.now().to_sec()
    published, last = 0, t0
    rate = rospy.Rate(100)
    while rospy.Time.now().to_sec() - t0 < run:
        now = rospy.Time.now()
        z, vz = probe_state(t0, now.to_sec())
        array = BodyStateArray()
        array.header.stamp = now
        array.states.append(ball_state("probe", now, x, z, vz))
        publisher.publish(array)
        published += 1
        last = now.to_sec()
        if each is not None:
            published += each(now, t0)
        rate.sleep()
    return t0, last, published


class PredictionClients:
    """`count` clients asking `service` for `request()` one after another until stopped: each
    answer's success and message kept."""

    def __init__(self, service, request, count):
        from collision_response.srv import PredictImpacts

        self.lock = threading.Lock()
        self.answers = []
        self.stop_event = threading.Event()

        def client():
            call = rospy.ServiceProxy(service, PredictImpacts)
            while not self.stop_event.is_set():
                answer = call(request())
                with self.lock:
                    self.answers.append((answer.success, answer.message))

        self.threads = [threading.Thread(target=client, daemon=True) for _ in range(count)]
        for thread in self.threads:
            thread.start()

    def stop(self):
        self.stop_event.set()

    def join(self, timeout=30.0):
        for thread in self.threads:
            thread.join(timeout=timeout)

    def answered(self):
        with self.lock:
            return list(self.answers)


def start_node(name, remaps):
    """The node, as `rosrun` starts it, named `name` (its scene already on the parameter server)."""
    return subprocess.Popen(["rosrun", "collision_response", "collision_response_node",
                             "__name:=" + name] + remaps,
                            stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)


def stop_node(node):
    """SIGINT, then a kill if it is still there after 10 s."""
    if node.poll() is None:
        node.send_signal(2)
        try:
            node.wait(timeout=10)
        except subprocess.TimeoutExpired:
            node.kill()
