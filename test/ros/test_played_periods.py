#!/usr/bin/python3
"""Issue 41, item 9: the scene player keeps up, or says it did not (README, "Parameters": the
scene player; doc/model.md, "The scene player and the scenes").

The load: the node and the player on test/ros/rough_pile_100.yaml (100 balls with friction and
spin dropped into a box: the exact model's collapse, then stepped clusters), at 100 Hz for 3 s.
Whatever the machine gives them, what the player published must be what it says it published:

- its last line (on /rosout) says how many periods it played, how many states it published and how
  many periods it skipped; the periods are the published and the skipped;
- every state heard on body_states is stamped at a period, k / rate s after the first, each period
  once, in order, and there are as many as it says it published;
- had it skipped any, it said so while it played (a warning "fell behind" with the figures).

Not a timed test: a slow machine may skip periods, but not without a word. Before (issue 41: 115
states in 90 s of a 100-ball pile, without a word), the player stamped its states at whatever
instant its timer fired and said nothing of the periods it missed.
"""
import re
import struct
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Log

RATE = 100.0


class PlayedPeriods(unittest.TestCase):
    def test_every_period_the_player_claims_was_published_or_said_skipped(self):
        stamps = []
        lines = []

        def on_states(message):
            # Only the header's stamp is read (seq, secs, nsecs): a pile's states are large.
            _, secs, nsecs = struct.unpack("<III", message._buff[:12])
            stamps.append(secs * 10**9 + nsecs)

        def on_log(log):
            if log.name.endswith("scene_player"):
                lines.append((log.level, log.msg))

        rospy.Subscriber("body_states", rospy.AnyMsg, on_states, queue_size=10000)
        rospy.Subscriber("/rosout", Log, on_log, queue_size=1000)
        summary = None
        deadline = rospy.get_rostime() + rospy.Duration(150)
        while not rospy.is_shutdown() and summary is None and rospy.get_rostime() < deadline:
            for _, text in lines:
                found = re.search(r"s played: (\d+) periods of [0-9.e-]+ s, (\d+) states "
                                  r"published, (\d+) periods skipped", text)
                if found:
                    summary = tuple(int(x) for x in found.groups())
            rospy.sleep(0.1)
        self.assertIsNotNone(summary, "the player never said what it played: %s" % lines[-3:])
        rospy.sleep(1.0)  # the last states on their way
        periods, published, skipped = summary
        self.assertEqual(periods, int(3 * RATE) + 1, "3 s at 100 Hz: the periods 0 to 300")
        self.assertEqual(published + skipped, periods)
        self.assertEqual(len(stamps), published, "states heard against states it says it published")
        first = stamps[0]
        indices = []
        for stamp in stamps:
            k = round((stamp - first) * RATE / 1e9)
            self.assertLessEqual(abs(stamp - first - k * 1e9 / RATE), 1, "stamp off its period")
            indices.append(k)
        self.assertEqual(indices, sorted(set(indices)), "each period once, in order")
        self.assertEqual(indices[-1], periods - 1)
        if skipped:
            self.assertTrue(any(level >= Log.WARN and "fell behind" in text
                                for level, text in lines), "periods skipped without a word")
        print("periods %d, published %d, skipped %d" % (periods, published, skipped))


if __name__ == "__main__":
    rospy.init_node("played_periods_test")
    rostest.rosrun("collision_response", "played_periods_test", PlayedPeriods)
