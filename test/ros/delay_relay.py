#!/usr/bin/python3
"""Holds each collision_response/ImpactArray heard on `in` for ~delay s (wall clock), then
publishes it on `out`: the node's answers as a busy machine delivers them, later than a period
(test/ros/paddle_arm_late.test, issue 41 item 10)."""
import threading

import rospy
from collision_response.msg import ImpactArray


def main():
    rospy.init_node("delay_relay")
    delay = rospy.get_param("~delay", 0.03)
    publisher = rospy.Publisher("out", ImpactArray, queue_size=100)

    def hold(message):
        threading.Timer(delay, publisher.publish, args=(message,)).start()

    rospy.Subscriber("in", ImpactArray, hold, queue_size=100)
    rospy.spin()


if __name__ == "__main__":
    main()
