#!/usr/bin/env python3
"""Draws a recorded scene: each body's path (from /body_states) and each impact (from /impacts).

usage: plot_bag.py BAG PNG [TITLE]

The two axes along which the bodies moved most are drawn (x-y for a table, x-z for a drop).
Impacts are marked at their contact points, with a short line along the normal.
"""
import collections
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import rosbag  # noqa: E402


def main():
    bag_path, png_path = sys.argv[1], sys.argv[2]
    title = sys.argv[3] if len(sys.argv) > 3 else bag_path
    paths = collections.defaultdict(list)  # id -> [(t, x, y, z, speed)]
    impacts = []
    with rosbag.Bag(bag_path) as bag:
        for topic, message, _ in bag.read_messages(topics=["/body_states", "/impacts"]):
            if topic == "/body_states":
                for state in message.states:
                    p, v = state.pose.position, state.twist.linear
                    speed = (v.x ** 2 + v.y ** 2 + v.z ** 2) ** 0.5
                    paths[state.id].append((state.header.stamp.to_sec(), p.x, p.y, p.z, speed))
            else:
                impacts.extend(message.impacts)
    if not paths:
        sys.exit(f"{bag_path}: no /body_states recorded")
    points = [p for path in paths.values() for p in path]
    spread = [max(p[k] for p in points) - min(p[k] for p in points) for k in (1, 2, 3)]
    axes = sorted(sorted(range(3), key=lambda k: -spread[k])[:2])
    names = "xyz"
    start = min(p[0] for p in points)

    figure, (plane, timeline) = plt.subplots(1, 2, figsize=(13, 5.5),
                                             gridspec_kw={"width_ratios": [1.3, 1]})
    for body, path in sorted(paths.items()):
        plane.plot([p[axes[0] + 1] for p in path], [p[axes[1] + 1] for p in path], lw=1.2,
                   label=body)
        timeline.plot([p[0] - start for p in path], [p[4] for p in path], lw=1.0)
    for impact in impacts:
        c, n = impact.contact_point, impact.normal
        cx, cy = (c.x, c.y, c.z)[axes[0]], (c.x, c.y, c.z)[axes[1]]
        nx, ny = (n.x, n.y, n.z)[axes[0]], (n.x, n.y, n.z)[axes[1]]
        plane.plot([cx], [cy], "kx", ms=6)
        plane.plot([cx, cx + 0.05 * nx], [cy, cy + 0.05 * ny], "k-", lw=1.5)
        timeline.axvline(impact.header.stamp.to_sec() - start, color="0.8", lw=0.6, zorder=0)
    plane.set_xlabel(f"{names[axes[0]]} (m)")
    plane.set_ylabel(f"{names[axes[1]]} (m)")
    plane.set_aspect("equal", adjustable="datalim")
    plane.set_title(f"{title}: paths, and impacts (x, normal)")
    if len(paths) <= 16:
        plane.legend(fontsize=7, ncol=2, loc="best")
    timeline.set_xlabel("time (s)")
    timeline.set_ylabel("speed (m/s)")
    timeline.set_title(f"speeds; {len(impacts)} impacts (grey lines)")
    figure.tight_layout()
    figure.savefig(png_path, dpi=90)
    print(f"{png_path}: {len(paths)} bodies, {len(impacts)} impacts, axes {names[axes[0]]}-{names[axes[1]]}")


if __name__ == "__main__":
    main()
