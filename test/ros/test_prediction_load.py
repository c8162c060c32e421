#!/usr/bin/python3
"""Expensive predictions never starve the monitor, and every state received is used or counted
(issue 41, items 1 and 2; doc/model.md, "Threads").

The node's scene: a concrete floor (z = 0), and beside it, 100 m away, a concrete floor as a mesh
of 180,000 triangles (1 cm cells over 3 m) written by the test. A probe ball (r = 0.05 m, e = 1 on
concrete) bounces on the plane floor from H = 0.2 m above contact: dropped from rest at its top
at t0, it meets the floor at t0 + tf + k T, tf = sqrt(2 H / g), T = 2 tf (e = 1: every flight
the same). The test publishes its closed-form state at 100 Hz for 8 s, each stamped with the
instant it describes, while three clients ask ~predict_impacts again and again for a tennis ball
rolling slowly across the mesh for 60 s with 10,000 samples (each request costs more than a
second of CPU without a budget; ~prediction_cpu_budget is 0.5 s here). Checked:

- every impact of the probe in the run is on /impacts, at its closed form (1e-6 s);
- /diagnostics, once the queue has drained: `states received (total)` is every state the test
  published, `states used (total)` the same, no state dropped;
- the predictions are answered, and those cut at the budget say so, naming the key, and are
  counted (`predictions cut short (total)`).

Before the fix, the predictions ran on the monitor's queue: the probe's states waited behind them
in roscpp's subscriber queue (100), lost there uncounted, and impacts were missed.
"""
import os
import shutil
import struct
import tempfile
import time
import unittest

import rospy
import rostest
from collision_response.msg import BodyStateArray
from collision_response.srv import PredictImpactsRequest

from probe_ball import (R, NodeListener, PredictionClients, check_bounces, play_probe,
                        start_node, stop_node, wait_for_subscribers)

RUN = 8.0
NODE = "prediction_load"


def write_grid_stl(path, cells, size):
    """A flat square of size x size m at z = 0, cells x cells squares of two triangles each."""
    step = size / cells
    with open(path, "wb") as stream:
        stream.write(b"\0" * 80)
        stream.write(struct.pack("<I", 2 * cells * cells))
        normal = struct.pack("<3f", 0.0, 0.0, 1.0)
        for i in range(cells):
            for j in range(cells):
                x, y = -size / 2 + i * step, -size / 2 + j * step
                a, b, c, d = (x, y, 0.0), (x + step, y, 0.0), (x + step, y + step, 0.0), \
                    (x, y + step, 0.0)
                for triangle in ((a, b, c), (a, c, d)):
                    stream.write(normal)
                    for vertex in triangle:
                        stream.write(struct.pack("<3f", *vertex))
                    stream.write(b"\0\0")


def expensive_request():
    request = PredictImpactsRequest()
    request.header.frame_id = "world"
    request.body.id = "tennis"
    request.body.mass = 0.057
    request.body.radius = 0.033
    request.body.material = "tennis_ball"
    request.body.position.x, request.body.position.z = 99.0, 1.0
    request.body.velocity.x = 0.04
    request.horizon = 60.0
    request.max_impacts = 1000
    request.sample_period = 0.006  # 10,000 samples
    request.effects = ["gravity"]
    return request


class PredictionLoad(unittest.TestCase):
    def test_probe_impacts_all_found_while_clients_hammer_predictions(self):
        folder = tempfile.mkdtemp(prefix="prediction_load_")
        mesh = os.path.join(folder, "fine_floor.stl")
        write_grid_stl(mesh, 300, 3.0)
        rospy.set_param("/%s/scene" % NODE, {
            "fixed_frame": "world", "detection": "continuous", "effects": ["gravity"],
            "materials": {"bouncy": {"restitution": 1.0}},
            "bodies": [{"id": "probe", "mass": 0.1, "radius": R, "material": "bouncy"}],
            "obstacles": [
                {"id": "floor", "type": "plane", "normal": [0, 0, 1], "offset": 0.0,
                 "material": "concrete"},
                {"id": "mesh_floor", "type": "mesh", "resource": "file://" + mesh,
                 "position": [100, 0, 0], "material": "concrete"}]})
        rospy.set_param("/%s/diagnostic_period" % NODE, 0.2)
        rospy.set_param("/%s/prediction_cpu_budget" % NODE, 0.5)
        node = start_node(NODE, ["body_states:=/load/body_states", "impacts:=/load/impacts"])
        try:
            self.run_probe(node)
        finally:
            stop_node(node)
            shutil.rmtree(folder, ignore_errors=True)

    def run_probe(self, node):
        service = "/%s/predict_impacts" % NODE
        rospy.wait_for_service(service, timeout=60.0)
        listener = NodeListener("/load/impacts", NODE)
        publisher = rospy.Publisher("/load/body_states", BodyStateArray, queue_size=1000)
        wait_for_subscribers([publisher])
        time.sleep(0.5)

        # The clients: one request after another until the probe has run.
        clients = PredictionClients(service, expensive_request, 3)
        time.sleep(1.0)  # the predictions are under way
        t0, last, published = play_probe(publisher, RUN)
        clients.stop()
        clients.join()
        values = listener.drained(published)
        self.assertTrue(node.poll() is None, "the node died")

        # Every impact of the probe within the run, at its closed form.
        check_bounces(self, listener, t0, last, 15)

        # Every state received, and every one used.
        self.assertEqual(int(values.get("states received (total)", "-1")), published, values)
        self.assertEqual(int(values.get("states used (total)", "-1")), published, values)
        drops = {key: value for key, value in values.items() if key.startswith("dropped:")}
        self.assertEqual(drops, {}, "states dropped")

        # The predictions were answered; a cut one names the budget's key and is counted.
        answers = clients.answered()
        self.assertGreater(len(answers), 0)
        self.assertTrue(all(success for success, _ in answers), answers[:3])
        cut = [message for _, message in answers if "~prediction_cpu_budget" in message]
        self.assertGreater(len(cut), 0, "no prediction was cut at its budget: %s" % answers[:3])
        self.assertIn("cut short:", cut[0])
        self.assertIn("~prediction_cpu_budget (0.5 s of CPU) ran out at", cut[0])
        self.assertGreaterEqual(int(values.get("predictions cut short (total)", "0")), len(cut),
                                values)


if __name__ == "__main__":
    rospy.init_node("prediction_load_test")
    rostest.rosrun("collision_response", "prediction_load_test", PredictionLoad)
