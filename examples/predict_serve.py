#!/usr/bin/python3
"""Where will the ball go? A rospy client of ~predict_impacts, as a catching or hitting robot uses
it: from the first state of `~body` it hears on body_states, it asks the node for the next impacts,
the path and the crossing of the robot's plane x = ~plane_x, prints them, and draws the predicted
path in rviz (topic predicted_path: a line strip, a sphere at each impact) beside the path played
(a second line strip). At the end it prints each played impact beside the predicted one.

    roslaunch collision_response predict_demo.launch         # the serve of config/scenes/serve.yaml
    rosrun collision_response predict_serve.py _body:=ball _horizon:=1.2 _plane_x:=1.6
"""
import rospy
from geometry_msgs.msg import Point, Vector3
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from collision_response.msg import Body, BodyStateArray, ImpactArray
from collision_response.srv import PredictImpacts, PredictImpactsRequest

NODE = "/collision_response"


def request_from(state, horizon, max_impacts, sample_period, plane_x):
    """A prediction request for the body of `state` (a BodyState), as the scene defines it."""
    request = PredictImpactsRequest()
    request.header = state.header
    request.body = Body(id=state.id, mass=0.0, position=state.pose.position,
                        velocity=state.twist.linear, angular_velocity=state.twist.angular)
    request.horizon = horizon
    request.max_impacts = max_impacts
    request.sample_period = sample_period
    request.crossing_normal = Vector3(1.0, 0.0, 0.0)
    request.crossing_point = Point(plane_x, 0.0, 0.0)
    return request


def predict(request, node=NODE, timeout=10.0):
    """Calls ~predict_impacts; returns the response (check .success and .message)."""
    name = node + "/predict_impacts"
    rospy.wait_for_service(name, timeout)
    return rospy.ServiceProxy(name, PredictImpacts)(request)


def line(marker_id, namespace, points, frame, rgb):
    marker = Marker(type=Marker.LINE_STRIP, action=Marker.ADD, id=marker_id, ns=namespace)
    marker.header.frame_id = frame
    marker.pose.orientation.w = 1.0
    marker.scale.x = 0.006
    marker.color = ColorRGBA(rgb[0], rgb[1], rgb[2], 1.0)
    marker.points = points
    return marker


def impact_markers(response, frame):
    markers = []
    for i, impact in enumerate(response.impacts):
        marker = Marker(type=Marker.SPHERE, action=Marker.ADD, id=100 + i, ns="predicted impacts")
        marker.header.frame_id = frame
        marker.pose.position = impact.contact_point
        marker.pose.orientation.w = 1.0
        marker.scale = Vector3(0.03, 0.03, 0.03)
        marker.color = ColorRGBA(1.0, 0.4, 0.0, 1.0)
        markers.append(marker)
    return markers


def main():
    rospy.init_node("predict_serve")
    body = rospy.get_param("~body", "ball")
    horizon = rospy.get_param("~horizon", 1.2)
    plane_x = rospy.get_param("~plane_x", 1.6)
    duration = rospy.get_param("~duration", 2.0)
    first, played, played_impacts = [], [], []

    def on_states(array):
        for state in array.states:
            if state.id == body:
                if not first:
                    first.append(state)
                played.append(state.pose.position)

    rospy.Subscriber("body_states", BodyStateArray, on_states)
    rospy.Subscriber("impacts", ImpactArray,
                     lambda array: played_impacts.extend(
                         i for i in array.impacts if i.body_a == body))
    markers = rospy.Publisher("predicted_path", MarkerArray, queue_size=1, latch=True)
    waiting_since = rospy.get_time()
    said = waiting_since
    while not rospy.is_shutdown() and not first:
        rospy.sleep(0.001)
        if rospy.get_time() - said >= 3.0:
            said = rospy.get_time()
            rospy.logwarn("predict_serve: no state of '%s' on %s for %.0f s: is a scene playing "
                          "(roslaunch collision_response predict_demo.launch), and is ~body the "
                          "id of one of its bodies?", body, rospy.resolve_name("body_states"),
                          said - waiting_since)
    if rospy.is_shutdown():
        return
    start = first[0]
    response = predict(request_from(start, horizon, 3, 0.01, plane_x))
    if not response.success:
        rospy.logerr("predict_impacts refused: %s", response.message)
        return
    t0 = start.header.stamp
    print(f"predicted from {body}'s state at {t0.to_sec():.6f} s: {response.message}", flush=True)
    for impact in response.impacts:
        p, v = impact.contact_point, impact.velocity_a_after.linear
        print(f"  impact on {impact.body_b} at +{(impact.header.stamp - t0).to_sec():.9f} s at "
              f"({p.x:.6f}, {p.y:.6f}, {p.z:.6f}) m, leaves at ({v.x:.6f}, {v.y:.6f}, {v.z:.6f}) "
              "m/s", flush=True)
    if response.crossed:
        c = response.crossing
        print(f"  crosses x = {plane_x} at +{(c.header.stamp - t0).to_sec():.9f} s at "
              f"({c.pose.position.x:.6f}, {c.pose.position.y:.6f}, {c.pose.position.z:.6f}) m, "
              f"moving ({c.twist.linear.x:.6f}, {c.twist.linear.y:.6f}, {c.twist.linear.z:.6f}) "
              "m/s", flush=True)
    frame = response.final_state.header.frame_id
    predicted = [s.pose.position for s in response.samples]
    end = rospy.Time.now() + rospy.Duration(duration)
    while not rospy.is_shutdown() and rospy.Time.now() < end:
        markers.publish(MarkerArray(markers=[line(0, "predicted", predicted, frame, (1.0, 0.4, 0.0)),
                                             line(1, "played", list(played), frame, (0.1, 0.5, 1.0))]
                                    + impact_markers(response, frame)))
        rospy.sleep(0.1)
    for predicted_impact, played_impact in zip(response.impacts, played_impacts):
        difference = (played_impact.header.stamp - predicted_impact.header.stamp).to_sec()
        print(f"  played impact on {played_impact.body_b} {difference * 1e6:+.3f} us from the "
              "predicted one", flush=True)


if __name__ == "__main__":
    main()
