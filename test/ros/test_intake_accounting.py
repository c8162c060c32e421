#!/usr/bin/python3
"""While an update blocks the monitor, every state received is used or counted with its reason
(issue 41, item 2; doc/model.md, "Threads").

The scene: 512 touching balls (an 8 x 8 x 8 lattice, r = 0.05 m, spacing 2 r) closing on the
centre at 1 m/s per m, swirling and spinning, with `friction` and `spin` (mu = 0.3, e = 0.5), as
in test_long_update.py: their second state starts an update of seconds. Beside them, 10 m away, a
probe ball whose states the test publishes at 100 Hz for 3 s from then on, in free flight. The
node's ~queue_size is 20. Checked:

- while that update runs, /diagnostics shows it (`update in progress (s)` > 0) with the probe's
  messages arriving (`states received (total)` past the lattice's two arrays) and waiting;
- once all is processed: `states received (total)` is every state published, and equals
  `states used (total)` plus the states dropped, each under its reason (here
  `dropped: input queue full`, the oldest waiting messages, of which there are some).

Before the fix the subscriptions' callbacks ran on the monitor's queue: during the update nothing
was received, roscpp's own queue (100 messages) lost the rest without a count.
"""
import random
import subprocess
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from collision_response.msg import BodyState, BodyStateArray

SIDE, R = 8, 0.05
NODE = "intake_accounting"


def lattice_bodies():
    random.seed(3)
    centre = R * (SIDE - 1)
    bodies = []
    for i in range(SIDE):
        for j in range(SIDE):
            for k in range(SIDE):
                p = [2 * R * i, 2 * R * j, 2 * R * k]
                d = [x - centre for x in p]
                v = [-d[0] - d[1], -d[1] + d[0], -d[2]]  # closing, and swirling about z
                w = [10 * random.uniform(-1, 1) for _ in range(3)]
                bodies.append({"id": "ball_%d%d%d" % (i, j, k), "mass": 0.1, "radius": R,
                               "material": "rough", "position": p, "velocity": v,
                               "angular_velocity": w})
    return bodies


def state(body_id, stamp, position, velocity, angular=(0.0, 0.0, 0.0)):
    message = BodyState()
    message.id = body_id
    message.header.stamp = stamp
    message.header.frame_id = "world"
    message.pose.orientation.w = 1.0
    message.pose.position.x, message.pose.position.y, message.pose.position.z = position
    message.twist.linear.x, message.twist.linear.y, message.twist.linear.z = velocity
    message.twist.angular.x, message.twist.angular.y, message.twist.angular.z = angular
    return message


class IntakeAccounting(unittest.TestCase):
    def test_received_is_used_plus_counted_drops_while_an_update_blocks_the_monitor(self):
        bodies = lattice_bodies()
        scene = {"fixed_frame": "world", "detection": "continuous",
                 "effects": ["friction", "spin"],
                 "materials": {"rough": {"restitution": 0.5, "friction": 0.3}},
                 "bodies": bodies + [{"id": "probe", "mass": 0.1, "radius": R,
                                      "material": "rough"}]}
        rospy.set_param("/%s/scene" % NODE, scene)
        rospy.set_param("/%s/diagnostic_period" % NODE, 0.2)
        rospy.set_param("/%s/queue_size" % NODE, 20)
        node = subprocess.Popen(["rosrun", "collision_response", "collision_response_node",
                                 "__name:=" + NODE, "body_states:=/accounting/body_states"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
        try:
            self.run_checks(node, bodies)
        finally:
            if node.poll() is None:
                node.send_signal(2)
                try:
                    node.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    node.kill()

    def run_checks(self, node, bodies):
        rospy.wait_for_service("/%s/compute_collision" % NODE, timeout=60.0)
        reports = []
        rospy.Subscriber("/diagnostics", DiagnosticArray,
                         lambda message: reports.extend(
                             {v.key: v.value for v in s.values}
                             for s in message.status if s.name.startswith(NODE)))
        publisher = rospy.Publisher("/accounting/body_states", BodyStateArray, queue_size=1000)
        deadline = time.monotonic() + 30
        while publisher.get_num_connections() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)

        start = rospy.Time.now()
        published = 0
        for t in (0.0, 0.01):
            array = BodyStateArray()
            array.header.stamp = start + rospy.Duration(t)
            for body in bodies:
                p = [x + t * v for x, v in zip(body["position"], body["velocity"])]
                array.states.append(state(body["id"], array.header.stamp, p, body["velocity"],
                                          body["angular_velocity"]))
            publisher.publish(array)
            published += len(array.states)
            time.sleep(0.1)
        # The probe in free flight (no gravity in the scene): straight along x, 10 m away.
        began = time.monotonic()
        rate = rospy.Rate(100)
        while time.monotonic() - began < 3.0:
            now = rospy.Time.now()
            t = (now - start).to_sec()
            array = BodyStateArray()
            array.header.stamp = now
            array.states.append(state("probe", now, (10.0 + 0.1 * t, 0.0, 0.0), (0.1, 0.0, 0.0)))
            publisher.publish(array)
            published += 1
            rate.sleep()

        # While the update ran: received kept counting, messages waited.
        during = [r for r in reports if float(r.get("update in progress (s)", "0")) > 0]
        self.assertTrue(during, "no /diagnostics during the update (is it too short?)")
        lattice = 2 * len(bodies)
        self.assertTrue(any(int(r.get("states received (total)", "0")) > lattice + 10 and
                            int(r.get("messages waiting", "0")) > 0 for r in during),
                        "no probe state counted as received while the update ran: %s" % during)

        # Drained: the node has received every state, and each is used or dropped with a reason.
        deadline = time.monotonic() + 60
        last = {}
        while time.monotonic() < deadline:
            time.sleep(0.5)
            if reports:
                last = reports[-1]
                if (last.get("messages waiting") == "0"
                        and float(last.get("update in progress (s)", "1")) == 0
                        and int(last.get("states received (total)", "0")) >= published):
                    break
        self.assertTrue(node.poll() is None, "the node died")
        received = int(last.get("states received (total)", "-1"))
        used = int(last.get("states used (total)", "-1"))
        drops = {key: int(value) for key, value in last.items() if key.startswith("dropped:")}
        self.assertEqual(received, published, last)
        self.assertEqual(received, used + sum(drops.values()), last)
        self.assertGreater(drops.get("dropped: input queue full (total)", 0), 0, last)


if __name__ == "__main__":
    rospy.init_node("intake_accounting_test")
    rostest.rosrun("collision_response", "intake_accounting_test", IntakeAccounting)
