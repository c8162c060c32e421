#!/usr/bin/python3
"""Drives one joint (~joint: `slide` of test/ros/slider_paddle.urdf, `hinge` of
hinge_paddle.urdf) on joint_states: still at ~start (m or rad) until the scene player's first
state, then at ~velocity (m/s or rad/s) from that state's stamp, at 1000 Hz, so that
robot_state_publisher moves the paddle's tf frame at a constant (linear or angular) velocity."""
import rospy
from sensor_msgs.msg import JointState
from collision_response.msg import BodyStateArray


def main():
    rospy.init_node("slide_joint")
    start = rospy.get_param("~start", 0.8)
    velocity = rospy.get_param("~velocity", -0.5)
    joint = rospy.get_param("~joint", "slide")
    origin = []
    rospy.Subscriber("body_states", BodyStateArray,
                     lambda states: origin or origin.append(states.header.stamp))
    publisher = rospy.Publisher("joint_states", JointState, queue_size=10)
    rate = rospy.Rate(1000)
    while not rospy.is_shutdown():
        now = rospy.Time.now()
        state = JointState()
        state.header.stamp = now
        state.name = [joint]
        moved = (now - origin[0]).to_sec() if origin and now > origin[0] else 0.0
        state.position = [start + velocity * moved]
        state.velocity = [velocity if moved > 0 else 0.0]
        publisher.publish(state)
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
