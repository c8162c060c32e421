#!/usr/bin/env python3
"""Draws a recorded scene: each body's path (from /body_states) and each impact (from /impacts).

usage: plot_bag.py BAG PNG [TITLE] [--scene SCENE_YAML]

The two axes along which the bodies moved most are drawn (x-y for a table, x-z for a drop).
Each body has its own colour (and, past ten bodies, a dashed line) in both panels, a label at
the end of its path, and an entry in the legend beside the speeds; a body whose speeds are those
of another (a mirror image in a symmetric scene) is dotted over that body's speed line, and its
legend entry names the other. With the scene file, each
body is drawn at its start and its end as a disc of its radius (a box body as the outline of its
corners at its recorded orientation, faintly also along its path), and the fixed obstacles are
drawn too: a plane across the drawing plane as a line (the billiards table's cushions, the drop
test's floor), a sphere as a circle, a box along the axes as a rectangle (obstacles on tf frames,
a robot's links among them, are not drawn: their impacts are). Impacts are marked at their contact points, with a short
line along the normal. A prediction recorded beside them (/predicted_path, the markers of
examples/predict_serve.py) is drawn as a dashed orange line, its impacts as orange circles.
"""
import argparse
import collections
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import rosbag  # noqa: E402
import yaml  # noqa: E402

AXES = "xyz"


def body_styles(ids):
    """A colour and line style for each body: tab20's ten dark shades, then its ten light ones
    dashed, so that a light shade is never mistaken for its dark twin."""
    palette = plt.get_cmap("tab20").colors
    colours = list(palette[0::2]) + list(palette[1::2])
    return {body: (colours[i % 20], "-" if i % 20 < 10 else "--") for i, body in enumerate(ids)}


def same_speeds(speeds, drawn):
    """The id of a drawn body whose speeds are these (to 1e-9 of the largest), or None."""
    scale = 1e-9 * max(max(speeds), 1.0)
    for body, other in drawn.items():
        if len(other) == len(speeds) and all(abs(a - b) <= scale for a, b in zip(other, speeds)):
            return body
    return None


def read_bag(bag_path):
    paths = collections.defaultdict(list)  # id -> [(t, x, y, z, speed)]
    impacts = []
    predicted = {"path": [], "impacts": []}  # the last prediction drawn: points
    with rosbag.Bag(bag_path) as bag:
        for topic, message, _ in bag.read_messages(
                topics=["/body_states", "/impacts", "/predicted_path"]):
            if topic == "/predicted_path":
                for marker in message.markers:
                    points = [(p.x, p.y, p.z) for p in marker.points]
                    if marker.ns == "predicted":
                        predicted["path"] = points
                    elif marker.ns == "predicted impacts":
                        p = marker.pose.position
                        predicted["impacts"].append((p.x, p.y, p.z))
                predicted["impacts"] = list(dict.fromkeys(predicted["impacts"]))
            elif topic == "/body_states":
                for state in message.states:
                    p, v, q = state.pose.position, state.twist.linear, state.pose.orientation
                    speed = math.sqrt(v.x ** 2 + v.y ** 2 + v.z ** 2)
                    paths[state.id].append((state.header.stamp.to_sec(), p.x, p.y, p.z, speed,
                                            (q.x, q.y, q.z, q.w)))
            else:
                impacts.extend(message.impacts)
    return paths, impacts, predicted


def read_scene(scene_path):
    """The balls' radii, the box bodies' edges, and the obstacles."""
    if not scene_path:
        return {}, {}, []
    with open(scene_path) as stream:
        scene = (yaml.safe_load(stream) or {}).get("scene", {})
    bodies = scene.get("bodies", [])
    radii = {body["id"]: float(body["radius"]) for body in bodies
             if body.get("shape", "sphere") == "sphere"}
    boxes = {body["id"]: [float(c) for c in body["size"]] for body in bodies
             if body.get("shape") == "box"}
    return radii, boxes, scene.get("obstacles", [])


def box_outline(centre, quaternion, size, axes):
    """The outline of a box's eight corners in the drawing plane (their convex hull, in order):
    corner = centre + R (+-a, +-b, +-c) / 2, R the rotation of the unit quaternion (x, y, z, w)."""
    x, y, z, w = quaternion
    norm = math.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    rotation = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    points = []
    for sx in (-0.5, 0.5):
        for sy in (-0.5, 0.5):
            for sz in (-0.5, 0.5):
                local = (sx * size[0], sy * size[1], sz * size[2])
                corner = [centre[i] + sum(rotation[i][j] * local[j] for j in range(3))
                          for i in range(3)]
                points.append((corner[axes[0]], corner[axes[1]]))
    # Andrew's monotone chain.
    points = sorted(set(points))

    def half(chain_points):
        chain = []
        for p in chain_points:
            while len(chain) >= 2 and ((chain[-1][0] - chain[-2][0]) * (p[1] - chain[-2][1]) -
                                       (chain[-1][1] - chain[-2][1]) * (p[0] - chain[-2][0])) <= 0:
                chain.pop()
            chain.append(p)
        return chain[:-1]

    return half(points) + half(points[::-1])


def turned(obstacle):
    """Whether a box is turned from its frame's axes (such a box is not drawn)."""
    quaternion = [float(c) for c in obstacle.get("orientation", [0, 0, 0, 1])]
    angles = [float(c) for c in obstacle.get("rpy", [0, 0, 0])]
    return quaternion[:3] != [0.0, 0.0, 0.0] or any(angles)


def view_box(paths, axes, radii, obstacles, boxes=None):
    """The drawn region: every path with its discs (a box body's half diagonal), and the planes
    close to it."""
    lows, highs = [], []
    reaches = list(radii.values()) + [0.5 * math.sqrt(sum(c * c for c in size))
                                      for size in (boxes or {}).values()]
    for k in axes:
        values = [p[k + 1] for path in paths.values() for p in path]
        pad = max(reaches, default=0.0)
        lows.append(min(values) - pad)
        highs.append(max(values) + pad)
    for obstacle in obstacles:
        if obstacle.get("type") != "plane":
            continue
        normal, offset = [float(c) for c in obstacle["normal"]], float(obstacle.get("offset", 0.0))
        length = math.sqrt(sum(c * c for c in normal))
        in_plane = [normal[k] / length for k in axes]
        for i in range(2):
            # A plane facing along one drawn axis is a line at offset along it: kept in view
            # when it is within a span of the paths.
            if abs(in_plane[i]) == 1.0:
                position = offset / in_plane[i]
                span = highs[i] - lows[i]
                if lows[i] - span <= position <= highs[i] + span:
                    lows[i], highs[i] = min(lows[i], position), max(highs[i], position)
    margins = [0.05 * max(highs[i] - lows[i], 1e-3) for i in range(2)]
    return [(lows[i] - margins[i], highs[i] + margins[i]) for i in range(2)]


def draw_obstacles(plane, obstacles, axes, box):
    (u0, u1), (v0, v1) = box
    for obstacle in obstacles:
        kind, name = obstacle.get("type"), obstacle.get("id", "")
        if kind == "plane":
            normal = [float(c) for c in obstacle["normal"]]
            length = math.sqrt(sum(c * c for c in normal))
            nu, nv = normal[axes[0]] / length, normal[axes[1]] / length
            offset = float(obstacle.get("offset", 0.0))  # along the unit normal
            if math.hypot(nu, nv) < 1e-9:
                continue  # parallel to the drawing plane
            # The points with nu u + nv v = offset, across the box.
            if abs(nv) >= abs(nu):
                us = [u0, u1]
                vs = [(offset - nu * u) / nv for u in us]
            else:
                vs = [v0, v1]
                us = [(offset - nv * v) / nu for v in vs]
            plane.plot(us, vs, color="saddlebrown", lw=4, solid_capstyle="butt", zorder=1)
            # The name on the free side, where the normal points.
            mu, mv = (us[0] + us[1]) / 2, (vs[0] + vs[1]) / 2
            shift = 0.02 * max(u1 - u0, v1 - v0)
            plane.text(mu + nu * shift, mv + nv * shift, name, fontsize=7, color="saddlebrown",
                       ha="center", va="center", rotation=0 if abs(nv) >= abs(nu) else 90)
        elif kind == "box" and not obstacle.get("frame") and not turned(obstacle):
            centre = [float(c) for c in obstacle.get("position", [0, 0, 0])]
            size = [float(c) for c in obstacle["size"]]
            corner = (centre[axes[0]] - size[axes[0]] / 2, centre[axes[1]] - size[axes[1]] / 2)
            plane.add_patch(plt.Rectangle(corner, size[axes[0]], size[axes[1]],
                                          color="saddlebrown", alpha=0.4, zorder=1))
            plane.text(centre[axes[0]], centre[axes[1]], name, fontsize=7, ha="center",
                       va="center")
        elif kind == "sphere" and not obstacle.get("frame"):
            centre = [float(c) for c in obstacle.get("position", [0, 0, 0])]
            plane.add_patch(plt.Circle((centre[axes[0]], centre[axes[1]]),
                                       float(obstacle["radius"]), color="saddlebrown", alpha=0.4))
            plane.text(centre[axes[0]], centre[axes[1]], name, fontsize=7, ha="center")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bag")
    parser.add_argument("png")
    parser.add_argument("title", nargs="?")
    parser.add_argument("--scene", help="the scene file: bodies' radii and fixed obstacles")
    args = parser.parse_args()
    paths, impacts, predicted = read_bag(args.bag)
    if not paths:
        sys.exit(f"{args.bag}: no /body_states recorded")
    radii, boxes, obstacles = read_scene(args.scene)
    title = args.title or args.bag
    points = [p for path in paths.values() for p in path]
    spread = [max(p[k] for p in points) - min(p[k] for p in points) for k in (1, 2, 3)]
    axes = sorted(sorted(range(3), key=lambda k: -spread[k])[:2])
    start = min(p[0] for p in points)
    ids = sorted(paths)
    styles = body_styles(ids)
    box = view_box(paths, axes, radii, obstacles, boxes)

    figure, (plane, timeline) = plt.subplots(1, 2, figsize=(15, 6),
                                             gridspec_kw={"width_ratios": [1.4, 1]})
    draw_obstacles(plane, obstacles, axes, box)
    drawn = {}  # id -> speeds, of the speed lines drawn so far
    for body in ids:
        path, (colour, style) = paths[body], styles[body]
        us, vs = [p[axes[0] + 1] for p in path], [p[axes[1] + 1] for p in path]
        plane.plot(us, vs, color=colour, ls=style, lw=1.3, zorder=2)
        if body in radii:
            plane.add_patch(plt.Circle((us[0], vs[0]), radii[body], color=colour, alpha=0.35,
                                       zorder=2))
            plane.add_patch(plt.Circle((us[-1], vs[-1]), radii[body], color=colour, zorder=3))
        elif body in boxes:
            # Its outline at its recorded orientation: at the start (pale), every twentieth of
            # the path (faint: its tumbling) and at the end.
            step = max(1, len(path) // 20)
            for k, p in enumerate(path):
                last = k == len(path) - 1
                if k != 0 and not last and k % step:
                    continue
                alpha = 1.0 if last else 0.35 if k == 0 else 0.12
                plane.add_patch(plt.Polygon(box_outline(p[1:4], p[5], boxes[body], axes),
                                            closed=True, color=colour, alpha=alpha,
                                            zorder=3 if last else 2))
        else:
            plane.plot([us[-1]], [vs[-1]], "o", color=colour, ms=5, zorder=3)
        plane.annotate(body, (us[-1], vs[-1]), xytext=(4, 4), textcoords="offset points",
                       fontsize=7, color=colour, zorder=4)
        speeds = [p[4] for p in path]
        twin = same_speeds(speeds, drawn)
        if twin is None:
            timeline.plot([p[0] - start for p in path], speeds, color=colour, ls=style, lw=1.2,
                          label=body)
            drawn[body] = speeds
        else:
            # A mirror image of a body already drawn (a symmetric break): dotted over its line,
            # so both colours show.
            timeline.plot([p[0] - start for p in path], speeds, color=colour, ls=(0, (2, 2)),
                          lw=1.8, label=f"{body} (= {twin})")
    tick = 0.015 * max(box[0][1] - box[0][0], box[1][1] - box[1][0])
    for impact in impacts:
        c, n = impact.contact_point, impact.normal
        cu, cv = (c.x, c.y, c.z)[axes[0]], (c.x, c.y, c.z)[axes[1]]
        nu, nv = (n.x, n.y, n.z)[axes[0]], (n.x, n.y, n.z)[axes[1]]
        plane.plot([cu], [cv], "kx", ms=4, mew=0.8, zorder=5)
        plane.plot([cu, cu + tick * nu], [cv, cv + tick * nv], "k-", lw=0.8, zorder=5)
        timeline.axvline(impact.header.stamp.to_sec() - start, color="0.85", lw=0.6, zorder=0)
    if predicted["path"]:
        plane.plot([p[axes[0]] for p in predicted["path"]], [p[axes[1]] for p in predicted["path"]],
                   color="darkorange", ls="--", lw=1.6, zorder=6,
                   label="predicted (~predict_impacts, from the first state)")
        plane.plot([p[axes[0]] for p in predicted["impacts"]],
                   [p[axes[1]] for p in predicted["impacts"]], "o", mfc="none",
                   mec="darkorange", ms=9, zorder=6, label="predicted impacts")
        plane.legend(fontsize=7, loc="upper right")
    plane.set_xlim(*box[0])
    plane.set_ylim(*box[1])
    plane.set_xlabel(f"{AXES[axes[0]]} (m)")
    plane.set_ylabel(f"{AXES[axes[1]]} (m)")
    plane.set_aspect("equal", adjustable="datalim")
    shown = ("; discs at start (pale) and end" if radii else
             "; outlines at start (pale), along the path and at the end" if boxes else "")
    plane.set_title(f"{title}: paths{shown}; impacts (x, normal)", fontsize=10)
    timeline.set_xlabel("time (s)")
    timeline.set_ylabel("speed (m/s)")
    timeline.set_title(f"speeds; {len(impacts)} impacts (grey lines)", fontsize=10)
    timeline.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0,
                    title="body", title_fontsize=8)
    figure.tight_layout()
    figure.savefig(args.png, dpi=90)
    print(f"{args.png}: {len(paths)} bodies, {len(impacts)} impacts, "
          f"axes {AXES[axes[0]]}-{AXES[axes[1]]}")


if __name__ == "__main__":
    main()
