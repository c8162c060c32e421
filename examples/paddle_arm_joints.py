#!/usr/bin/python3
"""Scripted joint states for urdf/paddle_arm.urdf (launch/paddle_arm.launch): the shoulder sways
about z by ~shoulder_amplitude rad and the elbow swings about y by ~elbow_amplitude rad, both at
~frequency Hz, published on joint_states at ~rate Hz for robot_state_publisher to turn into tf.
The rate is 1000 Hz: the node waits for the links' tf up to each state's stamp, so a slower joint
publisher delays its answers (at 200 Hz the scene player heard an impact after it had played
that instant).

The swing starts with the ball: the arm is held at rest (both joints at 0) until the scene
player's first state on ~start_topic (default body_states; empty: at once), and the swing's
phase is counted from that state's stamp, the instant the ball leaves. So every run meets the
ball at the same instant of the swing (0.846 s after the start for config/scenes/paddle_arm.yaml,
test/ros/test_paddle_arm.cpp), whatever the machine's load."""
import math

import rospy
from sensor_msgs.msg import JointState

from collision_response.msg import BodyStateArray


def main():
    rospy.init_node("paddle_arm_joints")
    shoulder = rospy.get_param("~shoulder_amplitude", 0.05)
    elbow = rospy.get_param("~elbow_amplitude", 0.3)
    frequency = rospy.get_param("~frequency", 0.5)
    rate = rospy.Rate(rospy.get_param("~rate", 1000.0))
    start_topic = rospy.get_param("~start_topic", "body_states")
    publisher = rospy.Publisher("joint_states", JointState, queue_size=10)
    start = [None if start_topic else rospy.Time.now()]

    def on_first_state(array):
        if start[0] is None:
            start[0] = array.header.stamp

    subscriber = None
    if start_topic:
        subscriber = rospy.Subscriber(start_topic, BodyStateArray, on_first_state, queue_size=1)
    omega = 2 * math.pi * frequency
    while not rospy.is_shutdown():
        now = rospy.Time.now()
        state = JointState()
        state.header.stamp = now
        state.name = ["shoulder", "elbow"]
        if start[0] is None or now < start[0]:
            state.position = [0.0, 0.0]  # at rest until the ball leaves
            state.velocity = [0.0, 0.0]
        else:
            if subscriber is not None:
                subscriber.unregister()
                subscriber = None
            phase = omega * (now - start[0]).to_sec()
            state.position = [shoulder * math.sin(phase), elbow * math.sin(phase)]
            state.velocity = [shoulder * omega * math.cos(phase), elbow * omega * math.cos(phase)]
        publisher.publish(state)
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
