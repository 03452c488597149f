#!/usr/bin/env python3
"""Writes the generated scene files scenes/ragdoll_pile.json, scenes/plank_bridge.json,
scenes/wall_120.json and the articulated scenes of tools/articulated_scenes.py (arm_push,
legged_base, spherical_chain, limit_chain).

Their bodies and joints repeat with rotations the scene generators (stack, pyramid, grid) do
not express; this script is their source. Run it from anywhere after changing it:
    python3 tools/make_scenes.py
and commit the JSON it writes (tests, benches and charts read only the JSON).
    python3 tools/make_scenes.py --check
exits 1 when a committed file differs from what the script writes (a ctest runs this).
"""
import json
import math
import os
import sys

from articulated_scenes import articulated_scenes

SCENES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")


def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return [aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw]


def qaxis(axis, radians):
    n = math.sqrt(sum(c * c for c in axis))
    s = math.sin(radians / 2) / n
    return [math.cos(radians / 2), axis[0] * s, axis[1] * s, axis[2] * s]


def rotate(q, v):
    w, x, y, z = q
    p = qmul(qmul(q, [0, v[0], v[1], v[2]]), [w, -x, -y, -z])
    return p[1:]


def r(v, digits=6):
    return [round(c, digits) + 0.0 for c in v]


def text_of(scene):
    """One body or joint per line: long files stay readable and diff well."""
    lines = ["{"]
    lists = [k for k in ("bodies", "articulations", "joints") if k in scene]
    head = [k for k in scene if k not in lists]
    for k in head:
        lines.append("  %s: %s," % (json.dumps(k), json.dumps(scene[k])))
    for n, key in enumerate(lists):
        items = scene[key]
        lines.append('  "%s": [' % key)
        for i, item in enumerate(items):
            comma = "," if i + 1 < len(items) else ""
            if key == "articulations":  # one link per line
                top = {k: v for k, v in item.items() if k != "links"}
                lines.append("    " + json.dumps(top)[:-1] + ', "links": [')
                for j, link in enumerate(item["links"]):
                    last = j + 1 == len(item["links"])
                    lines.append("      " + json.dumps(link) + ("" if last else ","))
                lines.append("    ]}" + comma)
            else:
                lines.append("    " + json.dumps(item) + comma)
        lines.append("  ]" + ("," if n + 1 < len(lists) else ""))
    lines.append("}")
    return "\n".join(lines) + "\n"


# A ragdoll standing at the origin, z up, facing +y, in a T pose: capsule parts (Bullet's
# RagdollDemo proportions, masses of a 60 kg person), bones along z except the arms (along x).
PARTS = [  # name, radius, length, centre, bone along x, mass
    ("pelvis", 0.15, 0.20, (0, 0, 1.00), False, 10),
    ("spine", 0.15, 0.28, (0, 0, 1.20), False, 15),
    ("head", 0.10, 0.05, (0, 0, 1.60), False, 5),
    ("thigh_l", 0.07, 0.45, (-0.18, 0, 0.65), False, 7),
    ("shin_l", 0.05, 0.37, (-0.18, 0, 0.20), False, 4),
    ("thigh_r", 0.07, 0.45, (0.18, 0, 0.65), False, 7),
    ("shin_r", 0.05, 0.37, (0.18, 0, 0.20), False, 4),
    ("upper_arm_l", 0.05, 0.33, (-0.35, 0, 1.45), True, 3),
    ("forearm_l", 0.04, 0.25, (-0.70, 0, 1.45), True, 2),
    ("upper_arm_r", 0.05, 0.33, (0.35, 0, 1.45), True, 3),
    ("forearm_r", 0.04, 0.25, (0.70, 0, 1.45), True, 2),
]
QUARTER = math.pi / 4
JOINTS = [  # type, child, parent, anchor, axis, limits or cone
    ("hinge", "spine", "pelvis", (0, 0, 1.15), (1, 0, 0), {"lower": -QUARTER, "upper": 2 * QUARTER}),
    ("cone_twist", "head", "spine", (0, 0, 1.50), (0, 0, 1),
     {"swing1": QUARTER, "swing2": QUARTER, "twist": 2 * QUARTER}),
    ("cone_twist", "thigh_l", "pelvis", (-0.18, 0, 0.90), (0, 0, -1),
     {"swing1": QUARTER, "swing2": QUARTER, "twist": 0}),
    ("hinge", "shin_l", "thigh_l", (-0.18, 0, 0.425), (1, 0, 0), {"lower": -2 * QUARTER, "upper": 0}),
    ("cone_twist", "thigh_r", "pelvis", (0.18, 0, 0.90), (0, 0, -1),
     {"swing1": QUARTER, "swing2": QUARTER, "twist": 0}),
    ("hinge", "shin_r", "thigh_r", (0.18, 0, 0.425), (1, 0, 0), {"lower": -2 * QUARTER, "upper": 0}),
    ("cone_twist", "upper_arm_l", "spine", (-0.18, 0, 1.45), (-1, 0, 0),
     {"swing1": 1.2, "swing2": 1.2, "twist": 0}),
    ("hinge", "forearm_l", "upper_arm_l", (-0.525, 0, 1.45), (0, 0, 1), {"lower": -2 * QUARTER, "upper": 0}),
    ("cone_twist", "upper_arm_r", "spine", (0.18, 0, 1.45), (1, 0, 0),
     {"swing1": 1.2, "swing2": 1.2, "twist": 0}),
    ("hinge", "forearm_r", "upper_arm_r", (0.525, 0, 1.45), (0, 0, 1), {"lower": 0, "upper": 2 * QUARTER}),
]


def ragdoll_pile(count=6, layer=0.45):
    bodies = [{"name": "ground", "shape": {"type": "plane", "normal": [0, 0, 1], "offset": 0}}]
    joints = []
    lie = qaxis((1, 0, 0), math.pi / 2)  # lying face up: head towards -y, front towards +z
    for k in range(count):
        turn = qmul(qaxis((0, 0, 1), k * math.pi / 3), lie)
        # The centre of the standing ragdoll (z = 0.8) goes to this height.
        lift = [0.1 * (k % 2), 0, 0.2 + k * layer]

        def place(p):
            q = rotate(turn, (p[0], p[1], p[2] - 0.8))
            return r([q[0] + lift[0], q[1] + lift[1], q[2] + lift[2]])

        for name, radius, length, centre, along_x, mass in PARTS:
            q = qmul(turn, qaxis((0, 1, 0), math.pi / 2)) if along_x else turn
            bodies.append({"name": "r%d.%s" % (k, name),
                           "shape": {"type": "capsule", "radius": radius, "length": length},
                           "mass": mass, "position": place(centre), "orientation": r(q, 9)})
        for kind, child, parent, anchor, axis, limits in JOINTS:
            j = {"type": kind, "bodies": ["r%d.%s" % (k, child), "r%d.%s" % (k, parent)],
                 "anchor": place(anchor), "axis": r(rotate(turn, axis), 9)}
            j["cone" if kind == "cone_twist" else "limits"] = limits
            joints.append(j)
    return {
        "format": "mlcp-scene/1",
        "name": "ragdoll_pile",
        "description": "%d ragdolls of 11 capsules each (60 kg; Bullet's RagdollDemo proportions), "
                       "lying face up in layers 0.45 m apart, each turned 60 degrees from the one "
                       "below, falling on each other: cone-twist necks, hips and shoulders, hinged "
                       "spines, knees and elbows with limits. Written by tools/make_scenes.py."
                       % count,
        "settings": {"steps": 300},
        "bodies": bodies,
        "joints": joints,
    }


def plank_bridge(planks=12, sag=0.5):
    """Planks on a circular arc, each joined to the next by two ball (point-to-point) joints at
    its edges, the end planks held to the world the same way, and two crates dropped on it."""
    link, plank_length, width, thickness = 0.35, 0.30, 1.0, 0.05
    edge = 0.45  # the joints' distance from the centre line
    angles = [sag * (2 * (i + 0.5) / planks - 1) for i in range(planks)]
    x = -link * sum(math.cos(a) for a in angles) / 2
    z = 2.0 - link * sum(math.sin(a) for a in angles[: planks // 2])  # lowest point at 2 m
    points = [(x, z)]
    for a in angles:
        x, z = x + link * math.cos(a), z + link * math.sin(a)
        points.append((x, z))
    bodies = [{"name": "ground", "shape": {"type": "plane", "normal": [0, 0, 1], "offset": 0}}]
    joints = []
    for i, a in enumerate(angles):
        (x0, z0), (x1, z1) = points[i], points[i + 1]
        bodies.append({"name": "plank.%d" % i,
                       "shape": {"type": "box", "size": [plank_length, width, thickness]},
                       "mass": 2, "position": r([(x0 + x1) / 2, 0, (z0 + z1) / 2]),
                       "orientation": {"axis": [0, -1, 0], "radians": round(a, 9)}})
    for i, (px, pz) in enumerate(points):
        pair = ["plank.%d" % i, "plank.%d" % (i - 1)] if 0 < i < planks else \
            ["plank.%d" % min(i, planks - 1)]
        for side in (-edge, edge):
            joints.append({"type": "ball", "bodies": pair, "anchor": r([px, side, pz])})
    low = min(pz for _, pz in points)
    for k, dx in enumerate((-0.4, 0.5)):
        bodies.append({"name": "crate.%d" % k, "shape": {"type": "box", "size": [0.4, 0.4, 0.4]},
                       "mass": 10, "position": r([dx, 0.1 * k, low + 0.6 + 0.5 * k])})
    return {
        "format": "mlcp-scene/1",
        "name": "plank_bridge",
        "description": "A rope bridge of %d planks (2 kg) on an arc sagging %.2f m, each joined to "
                       "the next by two ball (point-to-point) joints at its edges and the end "
                       "planks held to the world by two more: every joint pair shares an axis, so "
                       "the rows are redundant; two 10 kg crates drop on it. Written by "
                       "tools/make_scenes.py." % (planks, points[0][1] - low),
        "settings": {"steps": 300},
        "bodies": bodies,
        "joints": joints,
    }


def brick_wall(width=12, height=10, size=1.0, gap=0.01):
    """ODE's demo_crash wall (WBOXSIZE 1 m cubes in courses on the ground), 12 wide and 10 high,
    every other course shifted by a quarter cube so that each cube rests on two below (a half
    shift would leave each shifted course's end cube balanced on the edge below), 1 cm apart
    sideways so that only the courses touch."""
    bodies = [{"name": "ground", "shape": {"type": "plane", "normal": [0, 0, 1], "offset": 0}}]
    pitch = size + gap
    for k in range(height):
        shift = pitch / 4 if k % 2 else 0.0
        for i in range(width):
            x = (i - (width - 1) / 2) * pitch + shift
            bodies.append({"name": "brick.%d.%d" % (k, i),
                           "shape": {"type": "box", "size": [size, size, size]}, "mass": 1,
                           "position": r([x, 0, size / 2 + k * size])})
    return {
        "format": "mlcp-scene/1",
        "name": "wall_%d" % (width * height),
        "description": "A brick wall of %d cubes (1 m, 1 kg) on the ground in the manner of ODE's "
                       "demo_crash wall: %d courses of %d, every other course shifted by a "
                       "quarter cube, 1 cm apart sideways. Written by tools/make_scenes.py."
                       % (width * height, height, width),
        "bodies": bodies,
        "joints": [],
    }


if __name__ == "__main__":
    check = sys.argv[1:] == ["--check"]
    stale = []
    generated = (("ragdoll_pile", ragdoll_pile()), ("plank_bridge", plank_bridge()),
                 ("wall_120", brick_wall())) + articulated_scenes()
    for name, scene in generated:
        path = os.path.join(SCENES, name + ".json")
        text = text_of(scene)
        if check:
            with open(path) as f:
                if f.read() != text:
                    stale.append(path)
        else:
            with open(path, "w") as f:
                f.write(text)
    for path in stale:
        print("%s differs from what tools/make_scenes.py writes: run it and commit" % path)
    sys.exit(1 if stale else 0)
