#!/usr/bin/python3
"""The robot's half of collision_response: publish the bodies you track, apply their impacts.

A robot that tracks bodies with a camera publishes their states to the node, one stamped
collision_response/BodyStateArray per camera frame, in the camera's tf frame; the node answers on
`impacts` with every impact it finds, in the scene's fixed frame. This example is such a robot,
with a stand-in for its tracker: bodies that move in straight lines from the positions and
velocities given as parameters (in the camera frame). It

- broadcasts the camera's pose as a static tf transform (`~camera_pose`; a robot whose tf tree
  already has its camera, from its URDF or a calibration, leaves the parameter out);
- publishes the tracked states on `body_states` at `~rate` Hz: each state stamped with the
  instant it describes, `header.frame_id` the camera frame, the twist relative to the camera
  and expressed in it;
- applies each impact heard on `impacts` to its bodies from the instant of impact: the body
  goes on from where it was then with the velocity after, turned into the camera frame by tf.

    rosrun collision_response body_tracker.py _camera_pose:="[0, 0, 1, 0, 0, 0, 1]" \\
        _bodies:="[{id: ball, position: [0, 0, 0], velocity: [1, 0, 0]}]"

Parameters: `~bodies` (required: `id`, `position`, `velocity`, in m and m/s in the camera
frame; every id a body of the node's scene), `~camera_frame` (default `camera`),
`~camera_parent` (default `world`), `~camera_pose` ([x, y, z, qx, qy, qz, qw] of the camera in
`~camera_parent`), `~rate` (Hz, default 30), `~transform_timeout` (s, default 0.5).
The camera is taken to be still in its parent frame (as a static transform says): with a
moving camera, the velocity relative to it is the impact's velocity less the camera's own.
examples/body_tracker.cpp is the same robot in C++; launch/body_tracker.launch runs it
beside the node, and test/ros/body_tracker.test checks it there.
"""
import math
import sys
import threading

import rospy
import tf2_geometry_msgs
import tf2_ros
from geometry_msgs.msg import TransformStamped, Vector3Stamped

from collision_response.msg import BodyState, BodyStateArray, ImpactArray


class TrackedBody:
    """A body the stand-in tracker follows: a straight line from (stamp, position, velocity)."""

    def __init__(self, body_id, stamp, position, velocity):
        self.id = body_id
        self.stamp = stamp
        self.position = position
        self.velocity = velocity

    def position_at(self, stamp):
        dt = (stamp - self.stamp).to_sec()
        return [p + v * dt for p, v in zip(self.position, self.velocity)]

    def state_at(self, stamp, frame):
        state = BodyState()
        state.header.stamp = stamp
        state.header.frame_id = frame
        state.id = self.id
        (state.pose.position.x, state.pose.position.y,
         state.pose.position.z) = self.position_at(stamp)
        state.pose.orientation.w = 1.0
        state.twist.linear.x, state.twist.linear.y, state.twist.linear.z = self.velocity
        return state

    def change_velocity(self, stamp, velocity):
        """From `stamp` on, the body moves with `velocity` from where it was then."""
        self.position = self.position_at(stamp)
        self.stamp = stamp
        self.velocity = velocity


def read_vector(value, name):
    if (not isinstance(value, list) or len(value) != 3 or
            not all(isinstance(x, (int, float)) and math.isfinite(x) for x in value)):
        raise ValueError(f"{name}: must be a list of 3 finite numbers, got {value!r}")
    return [float(x) for x in value]


def read_bodies(value, name):
    if not isinstance(value, list) or not value:
        raise ValueError(f"{name}: must be a non-empty list of {{id, position, velocity}}")
    bodies = {}
    for index, entry in enumerate(value):
        field = f"{name}[{index}]"
        if not isinstance(entry, dict) or not isinstance(entry.get("id"), str) or not entry["id"]:
            raise ValueError(f"{field}/id: is required (a body id of the scene)")
        unknown = set(entry) - {"id", "position", "velocity"}
        if unknown:
            raise ValueError(f"{field}: unknown key(s) {sorted(unknown)}")
        if entry["id"] in bodies:
            raise ValueError(f"{field}/id: '{entry['id']}' is listed twice")
        bodies[entry["id"]] = (read_vector(entry.get("position"), f"{field}/position"),
                               read_vector(entry.get("velocity", [0, 0, 0]), f"{field}/velocity"))
    return bodies


def camera_transform(pose, parent, frame):
    """The static transform parent -> frame of a pose [x, y, z, qx, qy, qz, qw]."""
    name = rospy.resolve_name("~camera_pose")
    if (not isinstance(pose, list) or len(pose) != 7 or
            not all(isinstance(x, (int, float)) and math.isfinite(x) for x in pose)):
        raise ValueError(f"{name}: must be [x, y, z, qx, qy, qz, qw], got {pose!r}")
    norm = math.sqrt(sum(q * q for q in pose[3:]))
    if abs(norm - 1.0) > 1e-6:
        raise ValueError(f"{name}: the quaternion must be a unit one, its norm is {norm}")
    transform = TransformStamped()
    transform.header.stamp = rospy.Time.now()
    transform.header.frame_id = parent
    transform.child_frame_id = frame
    t, q = transform.transform.translation, transform.transform.rotation
    t.x, t.y, t.z = pose[:3]
    q.x, q.y, q.z, q.w = pose[3:]
    return transform


class BodyTracker:
    def __init__(self):
        self.camera_frame = rospy.get_param("~camera_frame", "camera")
        self.transform_timeout = rospy.Duration(rospy.get_param("~transform_timeout", 0.5))
        rate = rospy.get_param("~rate", 30.0)
        if not isinstance(rate, (int, float)) or not rate > 0:
            raise ValueError(f"{rospy.resolve_name('~rate')}: must be a number > 0 Hz, "
                             f"got {rate!r}")
        start = rospy.Time.now()
        bodies = read_bodies(rospy.get_param("~bodies", None), rospy.resolve_name("~bodies"))
        self.bodies = {body_id: TrackedBody(body_id, start, position, velocity)
                       for body_id, (position, velocity) in bodies.items()}
        self.lock = threading.Lock()
        if rospy.has_param("~camera_pose"):
            self.broadcaster = tf2_ros.StaticTransformBroadcaster()
            self.broadcaster.sendTransform(camera_transform(
                rospy.get_param("~camera_pose"), rospy.get_param("~camera_parent", "world"),
                self.camera_frame))
        self.tf_buffer = tf2_ros.Buffer()
        self.tf_listener = tf2_ros.TransformListener(self.tf_buffer)
        self.publisher = rospy.Publisher("body_states", BodyStateArray, queue_size=10)
        self.subscriber = rospy.Subscriber("impacts", ImpactArray, self.apply_impacts,
                                           queue_size=100)
        self.timer = rospy.Timer(rospy.Duration(1.0 / rate), self.publish_states)
        rospy.loginfo(f"body_tracker: {len(self.bodies)} bodies in frame {self.camera_frame}, "
                      f"{rate:g} Hz")

    def publish_states(self, _event):
        """One frame of the tracker: every body's state at this instant, in the camera frame."""
        stamp = rospy.Time.now()
        message = BodyStateArray()
        message.header.stamp = stamp
        message.header.frame_id = self.camera_frame
        with self.lock:
            message.states = [body.state_at(stamp, self.camera_frame)
                              for _, body in sorted(self.bodies.items())]
        self.publisher.publish(message)

    def to_camera(self, velocity, frame, stamp):
        """A velocity given in `frame` (an impact's), expressed in the camera frame."""
        vector = Vector3Stamped()
        vector.header.frame_id = frame
        vector.header.stamp = stamp
        vector.vector = velocity
        transform = self.tf_buffer.lookup_transform(self.camera_frame, frame, stamp,
                                                    self.transform_timeout)
        # A vector transforms by the rotation alone (tf2_geometry_msgs).
        v = tf2_geometry_msgs.do_transform_vector3(vector, transform).vector
        return [v.x, v.y, v.z]

    def apply_impacts(self, message):
        """Each impact, in order: the tracked bodies it names leave with their velocity after."""
        for impact in message.impacts:
            stamp, frame = impact.header.stamp, impact.header.frame_id
            for body_id, velocity in ((impact.body_a, impact.velocity_a_after.linear),
                                      (impact.body_b, impact.velocity_b_after.linear)):
                if body_id not in self.bodies:
                    continue  # an obstacle, or a body another source tracks
                try:
                    velocity_in_camera = self.to_camera(velocity, frame, stamp)
                except (tf2_ros.LookupException, tf2_ros.ConnectivityException,
                        tf2_ros.ExtrapolationException) as error:
                    rospy.logwarn_throttle(1.0, f"body_tracker: impact of '{body_id}' not "
                                                f"applied: no transform {frame} -> "
                                                f"{self.camera_frame}: {error}")
                    continue
                with self.lock:
                    self.bodies[body_id].change_velocity(stamp, velocity_in_camera)
                rospy.loginfo("body_tracker: %s after its impact at %.6f s: velocity "
                              "(%.6g, %.6g, %.6g) m/s in %s", body_id, stamp.to_sec(),
                              *velocity_in_camera, self.camera_frame)


def main():
    rospy.init_node("body_tracker")
    try:
        BodyTracker()
    except ValueError as error:
        rospy.logfatal(f"body_tracker: {error}")
        return 1
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
