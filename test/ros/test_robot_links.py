#!/usr/bin/python3
"""A robot of any size costs what can reach a body (issue 41, item 3; README, "Finite obstacles").

The node's scene (robot_links.test): a concrete floor (z = 0), a probe ball (r = 0.05 m, e = 1
on concrete) and a robot of LINKS links, each a sphere of radius 0.05 m on its own frame, from
the URDF this script prints with --urdf. The test publishes each link's frame on /tf_static, in
one message, on a grid 10 m and more from the probe. The probe bounces on the floor from H = 0.2 m
above contact: dropped from rest at its top at t0, it meets the floor at t0 + tf + k T, tf =
sqrt(2 H / g), T = 2 tf (e = 1: every flight the same); the test publishes its closed-form state
at 100 Hz for RUN s, stamped with the node's clock. Checked:

- every impact of the probe in the run is on /impacts at its closed form (1e-6 s): before the
  fix each update looked up and placed all 2,000 links again every 1 ms of it, updates grew
  from 0.1 s to seconds and most impacts were lost;
- /diagnostics, from 1 s into the run: each update looked up at most 8 link frames (static ones
  are looked up once, and 8 an update again in turn) and placed none again.
"""
import math
import sys
import threading
import time
import unittest

LINKS = 2000
G, R, H = 9.81, 0.05, 0.2
TF = math.sqrt(2 * H / G)
T = 2 * TF
RUN = 5.0
NODE = "robot_links_monitor"


def link_name(i):
    return "link_%04d" % i


def urdf():
    """LINKS links with a sphere each, fixed to a base (the frames come from the test's tf)."""
    parts = ['<?xml version="1.0"?>', '<robot name="big">', '<link name="base"/>']
    for i in range(LINKS):
        parts.append('<link name="%s"><collision><geometry><sphere radius="0.05"/></geometry>'
                     '</collision></link>' % link_name(i))
        parts.append('<joint name="j%d" type="fixed"><parent link="base"/><child link="%s"/>'
                     '</joint>' % (i, link_name(i)))
    parts.append("</robot>")
    return "\n".join(parts)


if __name__ == "__main__" and "--urdf" in sys.argv:
    print(urdf())
    sys.exit(0)

import rospy  # noqa: E402
import rostest  # noqa: E402
import tf2_ros  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import TransformStamped  # noqa: E402
from collision_response.msg import BodyState, BodyStateArray, ImpactArray  # noqa: E402


def probe_state(t0, t):
    """The probe at t (s after t0 on the same clock): height and vertical speed in closed form."""
    tau = math.fmod(t - t0 + TF, T) - TF  # time since the top of its current flight
    return R + H - 0.5 * G * tau * tau, -G * tau


class RobotLinks(unittest.TestCase):
    def test_two_thousand_links_cost_what_can_reach_the_probe(self):
        impacts, lock = [], threading.Lock()

        def on_impacts(message):
            with lock:
                impacts.extend(message.impacts)

        rospy.Subscriber("/robot_links/impacts", ImpactArray, on_impacts, queue_size=1000)
        diagnostics, diagnostics_lock = [], threading.Lock()

        def on_diagnostics(message):
            with diagnostics_lock:
                diagnostics.extend((time.monotonic(), s) for s in message.status
                                   if s.name.startswith(NODE))

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
        broadcaster = tf2_ros.StaticTransformBroadcaster()
        frames = []
        for i in range(LINKS):
            frame = TransformStamped()
            frame.header.stamp = rospy.Time.now()
            frame.header.frame_id = "world"
            frame.child_frame_id = link_name(i)
            frame.transform.translation.x = 10.0 + 0.2 * (i % 50)
            frame.transform.translation.y = 0.2 * (i // 50)
            frame.transform.translation.z = 0.5
            frame.transform.rotation.w = 1.0
            frames.append(frame)
        broadcaster.sendTransform(frames)
        probe = rospy.Publisher("/robot_links/body_states", BodyStateArray, queue_size=1000)
        deadline = time.monotonic() + 30
        while probe.get_num_connections() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)

        t0 = rospy.Time.now().to_sec()
        began = time.monotonic()
        published = 0
        rate = rospy.Rate(100)
        while rospy.Time.now().to_sec() - t0 < RUN:
            now = rospy.Time.now()
            z, vz = probe_state(t0, now.to_sec())
            array = BodyStateArray()
            array.header.stamp = now
            message = BodyState()
            message.header.stamp = now
            message.header.frame_id = "world"
            message.id = "probe"
            message.pose.position.z = z
            message.pose.orientation.w = 1.0
            message.twist.linear.z = vz
            array.states.append(message)
            probe.publish(array)
            published += 1
            last = now.to_sec()
            rate.sleep()

        deadline = time.monotonic() + 20
        values = {}
        while time.monotonic() < deadline:
            time.sleep(0.5)
            with diagnostics_lock:
                if diagnostics:
                    values = {v.key: v.value for v in diagnostics[-1][1].values}
            if (values.get("messages waiting") == "0"
                    and int(values.get("states received (total)", "0")) >= published):
                break

        expected = []
        k = 0
        while t0 + TF + k * T < last - 0.02:
            expected.append(t0 + TF + k * T)
            k += 1
        with lock:
            found = sorted(i.header.stamp.to_sec() for i in impacts
                           if "probe" in (i.body_a, i.body_b))
        self.assertGreaterEqual(len(expected), 12)
        missing = [t for t in expected if not any(abs(f - t) < 1e-6 for f in found)]
        self.assertEqual(missing, [], "probe impacts not found (%d of %d found; found: %s)"
                         % (len(expected) - len(missing), len(expected), found))

        # Each update's obstacle work, as /diagnostics showed it from 1 s into the run.
        with diagnostics_lock:
            samples = [{v.key: v.value for v in s.values} for at, s in diagnostics
                       if at > began + 1.0]
        self.assertGreater(len(samples), 5)
        slowest = 0.0
        for sample in samples:
            self.assertLessEqual(int(sample["obstacle frames looked up, last update"]), 8, sample)
            self.assertEqual(int(sample["obstacle placements, last update"]), 0, sample)
            slowest = max(slowest, float(sample["processing time per update, max (ms)"]))
        print("%d probe impacts found of %d; slowest update after 1 s: %.3f ms; diagnostics: %s"
              % (len(expected) - len(missing), len(expected), slowest, values))


if __name__ == "__main__":
    rospy.init_node("robot_links_test")
    rostest.rosrun("collision_response", "robot_links_test", RobotLinks)
