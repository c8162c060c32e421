#!/usr/bin/python3
"""The rospy example (examples/python_client.py) against a real node, in a rostest.

Expected values from closed forms (test/ros/head_on.yaml has the derivation of the impact):
- compute_collision, 2 kg at 3 m/s on 1 kg at -1 m/s, e = 0.5: v_a' = 1 m/s, v_b' = 3 m/s,
  impulse (1 + e) m_a m_b / (m_a + m_b) * 4 = 1.5 * 2/3 * 4 = 4 N s;
- estimate_restitution(1 m, 0.25 m): e = sqrt(0.25) = 0.5 exactly.
"""
import os
import sys
import unittest

import rospy
import rostest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples"))
import python_client  # noqa: E402  (the example itself)


class PythonClient(unittest.TestCase):
    # The scene player starts 4 s after launch: listen first, then the services.
    def test_1_listens_to_the_head_on_impact(self):
        impacts = python_client.listen_to_impacts(8.0)
        self.assertEqual(len(impacts), 1, [python_client.describe(i) for i in impacts])
        impact = impacts[0]
        after = {impact.body_a: impact.velocity_a_after.linear.x,
                 impact.body_b: impact.velocity_b_after.linear.x}
        self.assertEqual(set(after), {"heavy", "light"})
        self.assertAlmostEqual(after["heavy"], 1.0, delta=1e-12)
        self.assertAlmostEqual(after["light"], 3.0, delta=1e-12)
        self.assertEqual(impact.restitution, 0.5)
        self.assertAlmostEqual(impact.contact_point.x, 0.7, delta=1e-9)
        self.assertAlmostEqual(impact.impulse, 4.0, delta=1e-12)

    def test_2_computes_a_collision(self):
        response = python_client.compute_collision(python_client.head_on(2.0, 3.0, 1.0, -1.0, 0.5))
        self.assertTrue(response.success, response.message)
        self.assertAlmostEqual(response.velocity_a.x, 1.0, delta=1e-15)
        self.assertAlmostEqual(response.velocity_b.x, 3.0, delta=1e-15)
        self.assertAlmostEqual(response.impulse, 4.0, delta=4e-15)
        self.assertFalse(response.oblique)

    def test_3_refuses_a_bad_request_by_name(self):
        response = python_client.compute_collision(python_client.head_on(-2.0, 3.0, 1.0, -1.0, 0.5))
        self.assertFalse(response.success)
        self.assertIn("a.mass", response.message)

    def test_4_estimates_restitution(self):
        answer = python_client.estimate_restitution(1.0, 0.25)
        self.assertTrue(answer.success, answer.message)
        self.assertEqual(answer.restitution, 0.5)
        # The node's table holds the scene's materials too: its own "half" (0.5) is nearest.
        self.assertEqual(answer.nearest_material, "half")
        self.assertEqual(answer.nearest_material_restitution, 0.5)


if __name__ == "__main__":
    rospy.init_node("test_python_client")
    rostest.rosrun("collision_response", "python_client", PythonClient)
