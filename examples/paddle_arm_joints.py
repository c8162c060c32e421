#!/usr/bin/python3
"""Scripted joint states for urdf/paddle_arm.urdf (launch/paddle_arm.launch): the shoulder sways
about z by ~shoulder_amplitude rad and the elbow swings about y by ~elbow_amplitude rad, both at
~frequency Hz, published on joint_states at ~rate Hz for robot_state_publisher to turn into tf.
The rate is 1000 Hz: the node waits for the links' tf up to each state's stamp, so a slower joint
publisher delays its answers (at 200 Hz the scene player heard an impact after it had played
that instant)."""
import math

import rospy
from sensor_msgs.msg import JointState


def main():
    rospy.init_node("paddle_arm_joints")
    shoulder = rospy.get_param("~shoulder_amplitude", 0.05)
    elbow = rospy.get_param("~elbow_amplitude", 0.3)
    frequency = rospy.get_param("~frequency", 0.5)
    rate = rospy.Rate(rospy.get_param("~rate", 1000.0))
    publisher = rospy.Publisher("joint_states", JointState, queue_size=10)
    start = rospy.Time.now()
    while not rospy.is_shutdown():
        now = rospy.Time.now()
        phase = 2 * math.pi * frequency * (now - start).to_sec()
        state = JointState()
        state.header.stamp = now
        state.name = ["shoulder", "elbow"]
        state.position = [shoulder * math.sin(phase), elbow * math.sin(phase)]
        omega = 2 * math.pi * frequency
        state.velocity = [shoulder * omega * math.cos(phase), elbow * omega * math.cos(phase)]
        publisher.publish(state)
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
