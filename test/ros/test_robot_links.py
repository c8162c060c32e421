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
import sys
import time
import unittest

LINKS = 2000
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
from collision_response.msg import BodyStateArray  # noqa: E402

from probe_ball import (NodeListener, check_bounces, check_links_untouched,  # noqa: E402
                        play_probe, static_link_frames, wait_for_subscribers)


class RobotLinks(unittest.TestCase):
    def test_two_thousand_links_cost_what_can_reach_the_probe(self):
        listener = NodeListener("/robot_links/impacts", NODE)
        broadcaster = tf2_ros.StaticTransformBroadcaster()
        broadcaster.sendTransform(static_link_frames(LINKS, link_name))
        probe = rospy.Publisher("/robot_links/body_states", BodyStateArray, queue_size=1000)
        wait_for_subscribers([probe])
        time.sleep(1.0)

        began = time.monotonic()
        t0, last, published = play_probe(probe, RUN, x=0.0)
        values = listener.drained(published, idle=False)

        expected, missing = check_bounces(self, listener, t0, last, 12)

        # Each update's obstacle work, as /diagnostics showed it from 1 s into the run.
        samples = listener.values_since(began + 1.0)
        check_links_untouched(self, samples)
        slowest = max(float(sample["processing time per update, max (ms)"]) for sample in samples)
        print("%d probe impacts found of %d; slowest update after 1 s: %.3f ms; diagnostics: %s"
              % (len(expected) - len(missing), len(expected), slowest, values))


if __name__ == "__main__":
    rospy.init_node("robot_links_test")
    rostest.rosrun("collision_response", "robot_links_test", RobotLinks)
