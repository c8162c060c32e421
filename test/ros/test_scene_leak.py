#!/usr/bin/python3
"""Scenes never leak between launches on one master (a running roscore).

`rosparam load` merges a file into the parameters already there: without `clear_params`, a
scene that says nothing about effects would run with the effects of the scene launched before
it. For each launch file of the package this test starts it with test/ros/leak_first.yaml,
stops it, starts it with test/ros/leak_second.yaml on the same master, and checks that the
second run's parameters are exactly the second file's (the node reads nothing else), and that
the node runs with the defaults the second file leaves to it (README, "Scene file": detection
continuous, restitution_threshold 0, restitution_combine min), as its live tuning writes them.
"""
import os
import signal
import subprocess
import unittest

import rospy
import rostest
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
FIRST = os.path.join(HERE, "leak_first.yaml")
SECOND = os.path.join(HERE, "leak_second.yaml")
NODE = "/collision_response"


def scene_of(path):
    with open(path) as stream:
        return yaml.safe_load(stream)


class Launch:
    """roslaunch of one of the package's launch files on this test's master."""

    def __init__(self, launch_file, scene_file, *args):
        command = ["roslaunch", "collision_response", launch_file, "scene_file:=" + scene_file]
        self.process = subprocess.Popen(command + list(args), stdout=subprocess.DEVNULL,
                                        stderr=subprocess.STDOUT)

    def wait_until_serving(self):
        # The node advertises its services after it has read its scene and set its live values.
        rospy.wait_for_service(NODE + "/compute_collision", timeout=60.0)

    def stop(self):
        self.process.send_signal(signal.SIGINT)
        self.process.wait(timeout=60)


class SceneLeak(unittest.TestCase):
    def check_two_launches(self, launch_file, *args, player=False):
        first = Launch(launch_file, FIRST, *args)
        try:
            first.wait_until_serving()
            # The first scene is there: the leak, if any, is to come.
            self.assertEqual(rospy.get_param(NODE + "/scene/effects"), ["gravity", "friction"])
        finally:
            first.stop()

        second = Launch(launch_file, SECOND, *args)
        try:
            second.wait_until_serving()
            expected = scene_of(SECOND)
            self.assertEqual(rospy.get_param(NODE + "/scene"), expected["scene"])
            # The values the node runs with, written back by its live tuning.
            self.assertEqual(rospy.get_param(NODE + "/detection"), "continuous")
            self.assertEqual(rospy.get_param(NODE + "/restitution_threshold"), 0.0)
            self.assertEqual(rospy.get_param(NODE + "/restitution_combine"), "min")
            if player:
                self.assertEqual(rospy.get_param("/scene_player/scene"), expected["scene"])
                self.assertFalse(rospy.has_param("/scene_player/player"))
        finally:
            second.stop()

    def test_node(self):
        self.check_two_launches("collision_response.launch")

    def test_nodelet(self):
        self.check_two_launches("collision_response_nodelet.launch")

    def test_demo(self):
        self.check_two_launches("demo.launch", "duration:=0", player=True)


if __name__ == "__main__":
    rospy.init_node("test_scene_leak")
    rostest.rosrun("collision_response", "scene_leak", SceneLeak)
