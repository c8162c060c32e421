#!/usr/bin/python3
"""A rospy client of collision_response: calls both services and listens to impacts.

    rosrun collision_response python_client.py                 # against a running node
    rosrun collision_response python_client.py _listen:=5.0    # and print impacts for 5 s

The functions are the example; main() strings them together. test/ros/test_python_client.py
runs them against a real node in a rostest.
"""
import math

import rospy
from geometry_msgs.msg import Point, Vector3

from collision_response.msg import Body, ImpactArray
from collision_response.srv import ComputeCollision, ComputeCollisionRequest, EstimateRestitution

NODE = "/collision_response"


def head_on(mass_a, speed_a, mass_b, speed_b, restitution):
    """A request for a head-on impact along x: a at the origin, b 1 m further on."""
    request = ComputeCollisionRequest()
    request.a = Body(id="a", mass=mass_a, velocity=Vector3(speed_a, 0.0, 0.0))
    request.b = Body(id="b", mass=mass_b, position=Point(1.0, 0.0, 0.0),
                     velocity=Vector3(speed_b, 0.0, 0.0))
    request.restitution = restitution
    return request


def compute_collision(request, node=NODE, timeout=10.0):
    """Calls ~compute_collision; returns the response (check .success and .message)."""
    name = node + "/compute_collision"
    rospy.wait_for_service(name, timeout)
    return rospy.ServiceProxy(name, ComputeCollision)(request)


def estimate_restitution(drop_height, bounce_height, node=NODE, timeout=10.0):
    """Calls ~estimate_restitution: e = sqrt(bounce / drop) and the nearest seed material."""
    name = node + "/estimate_restitution"
    rospy.wait_for_service(name, timeout)
    return rospy.ServiceProxy(name, EstimateRestitution)(drop_height=drop_height,
                                                           bounce_height=bounce_height)


def listen_to_impacts(seconds, topic="impacts"):
    """Every Impact published on `topic` for `seconds` (ROS time), in order of arrival."""
    impacts = []
    subscriber = rospy.Subscriber(topic, ImpactArray, lambda array: impacts.extend(array.impacts))
    deadline = rospy.Time.now() + rospy.Duration(seconds)
    while not rospy.is_shutdown() and rospy.Time.now() < deadline:
        rospy.sleep(0.05)
    subscriber.unregister()
    return impacts


def describe(impact):
    v = impact.velocity_a_after.linear
    return (f"{impact.body_a} -> {impact.body_b} at {impact.header.stamp.to_sec():.6f} s: "
            f"e {impact.restitution:.3f}, impulse {impact.impulse:.4g} N s, "
            f"{impact.body_a} leaves at ({v.x:.4g}, {v.y:.4g}, {v.z:.4g}) m/s")


def main():
    rospy.init_node("python_client", anonymous=True)
    node = rospy.get_param("~node", NODE)
    try:
        # 2 kg at 3 m/s meets 1 kg at -1 m/s, e = 0.5: v_a' = 1 m/s, v_b' = 3 m/s.
        response = compute_collision(head_on(2.0, 3.0, 1.0, -1.0, 0.5), node)
        # A ball dropped from 1 m bounces to 0.25 m: e = 0.5.
        answer = estimate_restitution(1.0, 0.25, node)
    except rospy.ROSException as error:  # wait_for_service's time-out: no node serves it
        print(f"python_client: {error}: is the node running? Start it with "
              f"'rosrun collision_response collision_response_node' (or a launch file), "
              f"or give its name with _node:=/its_name")
        return 1
    print(f"compute_collision: success {response.success}, {response.message}: "
          f"v_a' {response.velocity_a.x:g} m/s, v_b' {response.velocity_b.x:g} m/s")
    print(f"estimate_restitution: success {answer.success}, e {answer.restitution:g}, "
          f"nearest {answer.nearest_material}")
    seconds = rospy.get_param("~listen", 0.0)
    if seconds > 0:
        for impact in listen_to_impacts(seconds):
            print(describe(impact))
    return 0 if response.success and answer.success and math.isfinite(answer.restitution) else 1


if __name__ == "__main__":
    raise SystemExit(main())
