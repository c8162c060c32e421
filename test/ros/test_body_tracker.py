#!/usr/bin/python3
"""The robot's half (examples/body_tracker.py and body_tracker.cpp) against a real node.

The tracker publishes two balls in its camera frame, 1, 2, 0.5 m from world and turned 90
degrees about z (camera x is world y: examples/tracked_balls_tracker.yaml);
examples/tracked_balls_scene.yaml derives the impact in the camera frame. In world: the line
of impact is +y, the contact point (1, 2 + 14.875, 0.5), the velocities before (0, 3, 0) and
(0, -1, 0), after (0, 1, 0) and (0, 3, 0), the impulse 4 N s.
After it, the tracker's states in the camera frame carry the velocities after, (1, 0, 0) and
(3, 0, 0), from the positions at the instant of impact, x = 14.775 and 15.075.
"""
import threading
import time
import unittest

import rospy
import rostest

from collision_response.msg import BodyStateArray, ImpactArray

CONTACT_WORLD = (1.0, 2.0 + 14.875, 0.5)
AT_IMPACT_CAMERA = {"heavy": 14.775, "light": 15.075}
AFTER_CAMERA = {"heavy": 1.0, "light": 3.0}


class BodyTracker(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.impacts = []
        self.states = []  # every BodyState received, in order
        self.impact_subscriber = rospy.Subscriber("impacts", ImpactArray, self.on_impacts)
        self.state_subscriber = rospy.Subscriber("body_states", BodyStateArray, self.on_states)

    def on_impacts(self, message):
        with self.lock:
            self.impacts.extend(message.impacts)

    def on_states(self, message):
        with self.lock:
            self.states.extend(message.states)

    def wait_for(self, condition, seconds):
        deadline = time.time() + seconds
        while time.time() < deadline and not rospy.is_shutdown():
            with self.lock:
                if condition():
                    return True
            time.sleep(0.05)
        return False

    def assertVector(self, vector, expected, delta, what):
        for axis, value in zip("xyz", expected):
            self.assertAlmostEqual(getattr(vector, axis), value, delta=delta,
                                   msg=f"{what}.{axis}: {vector}")

    def test_tracked_states_meet_and_the_tracker_applies_the_impact(self):
        self.assertTrue(self.wait_for(lambda: self.impacts, 60.0), "no impact on /impacts")
        instant = self.impacts[0].header.stamp
        # States stamped a second after the impact: the tracker has heard it by then.
        self.assertTrue(self.wait_for(
            lambda: sum(1 for s in self.states if (s.header.stamp - instant).to_sec() > 1.0) >= 10,
            20.0), "no states from the tracker after the impact")
        with self.lock:
            impacts, states = list(self.impacts), list(self.states)

        # The node: one impact, at the closed-form place, with the closed-form velocities.
        self.assertEqual(len(impacts), 1, impacts)
        impact = impacts[0]
        self.assertEqual((impact.body_a, impact.body_b), ("heavy", "light"))
        self.assertEqual(impact.header.frame_id, "world")
        self.assertVector(impact.normal, (0.0, 1.0, 0.0), 1e-12, "normal")
        self.assertVector(impact.contact_point, CONTACT_WORLD, 1e-9, "contact_point")
        self.assertVector(impact.velocity_a_before.linear, (0.0, 3.0, 0.0), 1e-12, "heavy before")
        self.assertVector(impact.velocity_b_before.linear, (0.0, -1.0, 0.0), 1e-12, "light before")
        self.assertVector(impact.velocity_a_after.linear, (0.0, 1.0, 0.0), 1e-12, "heavy after")
        self.assertVector(impact.velocity_b_after.linear, (0.0, 3.0, 0.0), 1e-12, "light after")
        self.assertEqual(impact.restitution, 0.5)
        self.assertAlmostEqual(impact.impulse, 4.0, delta=1e-12)

        # The instant agrees with the tracker's own states before it: from any pair of states
        # of one frame, contact comes (gap - 0.3 m) / 4 m/s later.
        frames = {}
        for state in states:
            if state.header.stamp < instant:
                frames.setdefault(state.header.stamp, {})[state.id] = state.pose.position.x
        self.assertTrue(frames, "no states before the impact")
        stamp, x = max((s, f) for s, f in frames.items() if len(f) == 2)
        predicted = stamp.to_sec() + (x["light"] - x["heavy"] - 0.3) / 4.0
        self.assertAlmostEqual(instant.to_sec(), predicted, delta=1e-6)

        # The tracker applied it: in the camera frame, each body goes on from where it was at
        # the instant of impact with its velocity after.
        later = [s for s in states if (s.header.stamp - instant).to_sec() > 1.0]
        for state in later:
            self.assertEqual(state.header.frame_id, "camera")
            dt = (state.header.stamp - instant).to_sec()
            self.assertVector(state.twist.linear, (AFTER_CAMERA[state.id], 0.0, 0.0), 1e-9,
                              f"{state.id} twist")
            self.assertVector(state.pose.position,
                              (AT_IMPACT_CAMERA[state.id] + AFTER_CAMERA[state.id] * dt, 0.0, 0.0),
                              1e-8, f"{state.id} position {dt:.3f} s after the impact")
        self.assertEqual({s.id for s in later}, {"heavy", "light"})


if __name__ == "__main__":
    rospy.init_node("test_body_tracker")
    rostest.rosrun("collision_response", "body_tracker", BodyTracker)
