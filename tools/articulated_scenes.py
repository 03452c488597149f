"""The articulated scenes tools/make_scenes.py writes: trees of links (mlcp-scene/1
"articulations"), each run in reduced coordinates (bullet-multibody) and in maximal ones (bullet,
ode). Poses are computed here so that every anchor sits exactly where its two links meet."""
import math

GROUND = {"name": "ground", "shape": {"type": "plane", "normal": [0, 0, 1], "offset": 0}}


def _box(size):
    return {"type": "box", "size": list(size)}


def _r(v, digits=9):
    return [round(c, digits) + 0.0 for c in v]


def _link(name, parent, size, mass, position, joint, orientation=None):
    link = {"name": name, "parent": parent, "shape": _box(size), "mass": mass,
            "position": _r(position)}
    if orientation is not None:
        link["orientation"] = orientation
    link["joint"] = joint
    return link


def _scene(name, description, steps, articulations, bodies=(), settings=None):
    s = {"format": "mlcp-scene/1", "name": name,
         "description": description + " Written by tools/make_scenes.py.",
         "settings": dict(settings or {}, steps=steps),
         "bodies": [GROUND] + list(bodies), "articulations": articulations}
    return s


def arm_push():
    """A fixed-base arm: a turret (revolute about z, motor into its limit) carrying a shoulder and
    an elbow (revolute about y, motors at 0 velocity as brakes, limits) and a paddle on a
    prismatic wrist (motor down into its limit), sweeping two boxes across the ground."""
    h = 0.45  # shoulder height
    revolute = lambda anchor, axis, lower, upper, v, f: {  # noqa: E731
        "type": "revolute", "anchor": _r(anchor), "axis": axis,
        "limits": {"lower": lower, "upper": upper}, "motor": {"velocity": v, "max_force": f}}
    links = [
        _link("turret", "arm", (0.2, 0.2, 0.1), 2, (0, 0, 0.35),
              revolute((0, 0, 0.3), [0, 0, 1], -1.0, 1.0, 1.0, 40)),
        _link("upper_arm", "turret", (0.7, 0.08, 0.08), 1, (0.35, 0, h),
              revolute((0, 0, h), [0, 1, 0], -0.3, 0.3, 0, 30)),
        _link("forearm", "upper_arm", (0.08, 0.08, 0.35), 1, (0.7, 0, h - 0.175),
              revolute((0.7, 0, h), [0, 1, 0], -0.5, 0.5, 0, 20)),
        _link("paddle", "forearm", (0.06, 0.3, 0.15), 0.5, (0.7, 0, 0.1),
              {"type": "prismatic", "axis": [0, 0, 1], "limits": {"lower": -0.02, "upper": 0.05},
               "motor": {"velocity": -0.1, "max_force": 30}}),
    ]
    arm = {"name": "arm", "fixed_base": True,
           "base": {"shape": _box((0.3, 0.3, 0.3)), "position": [0, 0, 0.15]}, "links": links}
    boxes = [{"name": "box.%d" % k, "shape": _box((0.2, 0.2, 0.2)), "mass": 0.5,
              "position": _r((0.7 * math.cos(a), 0.7 * math.sin(a), 0.1))}
             for k, a in enumerate((0.45, 0.9))]
    return _scene("arm_push", "A fixed-base arm of 4 links (turret, upper arm, forearm: revolute "
                  "with limits and motors; a paddle on a prismatic wrist) whose turret motor "
                  "(1 rad/s, 40 N m) sweeps two 0.5 kg boxes across the ground into its 1 rad "
                  "limit; the shoulder and elbow motors brake at 0 rad/s.", 240, [arm], boxes)


def legged_base(tilt=0.3):
    """A floating base on four legs (hip and knee revolute about y, limits, braking motors),
    thighs splayed by `tilt` and shins vertical, feet on the ground: the joints carry the load."""
    thigh, shin = 0.2, 0.2
    knee_z = shin
    hip_z = knee_z + thigh * math.cos(tilt)
    base_z = hip_z + 0.05
    links = []
    for name, sx, sy in (("fl", 1, 1), ("fr", 1, -1), ("bl", -1, 1), ("br", -1, -1)):
        hip = (0.25 * sx, 0.15 * sy, hip_z)
        knee = (hip[0] + sx * thigh * math.sin(tilt), hip[1], knee_z)
        mid = ((hip[0] + knee[0]) / 2, hip[1], (hip_z + knee_z) / 2)
        # Thigh bone from the hip out and down to the knee: z turned by -sx*tilt about y.
        q = {"axis": [0, 1, 0], "radians": round(-sx * tilt, 9)}
        brake = lambda anchor, f: {  # noqa: E731
            "type": "revolute", "anchor": _r(anchor), "axis": [0, 1, 0],
            "limits": {"lower": -0.4, "upper": 0.4}, "motor": {"velocity": 0, "max_force": f}}
        links.append(_link("thigh_" + name, "body", (0.05, 0.05, thigh), 0.5, mid,
                           brake(hip, 30), q))
        links.append(_link("shin_" + name, "thigh_" + name, (0.05, 0.05, shin), 0.3,
                           (knee[0], knee[1], shin / 2), brake(knee, 30)))
    body = {"name": "body", "base": {"shape": _box((0.6, 0.4, 0.1)), "mass": 4,
                                     "position": [0, 0, round(base_z, 9)]}, "links": links}
    return _scene("legged_base", "A floating 4 kg base on four legs of two links (hip and knee "
                  "revolute about y, limits of 0.4 rad, motors braking at 0 rad/s with 30 N m), "
                  "thighs splayed by %.1f rad, feet on the ground: the joints carry its weight."
                  % tilt, 240, [body])


def spherical_chain(links=5, tilt=math.pi / 4):
    """Bullet's MultiDofDemo, z up: a fixed base and 5 links of 0.1 x 0.2 x 0.74 m (1 kg) on
    spherical joints, the chain turned 45 degrees about (1, 1, 0) at its first joint, swinging
    down into a 1 m box on the ground below the base (Bullet's demo also damps its links; the
    scene does not)."""
    length, top = 0.74, 4.5
    axis = (1 / math.sqrt(2), 1 / math.sqrt(2), 0)
    c, s = math.cos(tilt / 2), math.sin(tilt / 2)
    turn = [c, axis[0] * s, axis[1] * s, 0.0]
    pivot = (0, 0, top - length / 2)

    def place(p):  # p below the first pivot, turned about it
        w, x, y, z = turn
        v = (p[0] - pivot[0], p[1] - pivot[1], p[2] - pivot[2])
        # Rodrigues through the quaternion: v + 2 u x (u x v + w v).
        u = (x, y, z)
        t = (u[1] * v[2] - u[2] * v[1] + w * v[0], u[2] * v[0] - u[0] * v[2] + w * v[1],
             u[0] * v[1] - u[1] * v[0] + w * v[2])
        return (pivot[0] + v[0] + 2 * (u[1] * t[2] - u[2] * t[1]),
                pivot[1] + v[1] + 2 * (u[2] * t[0] - u[0] * t[2]),
                pivot[2] + v[2] + 2 * (u[0] * t[1] - u[1] * t[0]))

    out = []
    for k in range(links):
        centre = place((0, 0, top - length * (k + 1)))
        anchor = place((0, 0, top - length * (k + 0.5)))
        out.append(_link("link.%d" % k, "chain" if k == 0 else "link.%d" % (k - 1),
                         (0.1, 0.2, length), 1, centre,
                         {"type": "spherical", "anchor": _r(anchor)}, _r(turn)))
    chain = {"name": "chain", "fixed_base": True,
             "base": {"shape": _box((0.1, 0.2, length)), "position": [0, 0, top]}, "links": out}
    box = {"name": "box", "shape": _box((1, 1, 1)), "mass": 1, "position": [0, 0, 0.5]}
    return _scene("spherical_chain", "Bullet's MultiDofDemo, z up: a fixed base and %d links "
                  "(0.1 x 0.2 x 0.74 m, 1 kg) on spherical joints, turned 45 degrees about "
                  "(1, 1, 0) at the first joint, swinging down into a 1 m box on the ground below "
                  "its base." % links,
                  300, [chain], [box])


def limit_chain(links=6, limit=0.25, tilt=0.87):
    """A 6-link chain with +-0.25 rad limits hanging from a fixed base onto the ground: straight,
    tilted `tilt` rad from the vertical so that its tip clears the ground; gravity swings it down,
    the ground bends it, and every joint must hold its limit."""
    length, anchor_z = 0.25, 1.0
    d = (math.sin(tilt), 0, -math.cos(tilt))
    q = {"axis": [0, 1, 0], "radians": round(-tilt, 9)}
    out = []
    for k in range(links):
        anchor = [d[i] * length * k for i in range(3)]
        anchor[2] += anchor_z
        centre = [d[i] * length * (k + 0.5) for i in range(3)]
        centre[2] += anchor_z
        out.append(_link("link.%d" % k, "post" if k == 0 else "link.%d" % (k - 1),
                         (0.05, 0.05, length), 1, centre,
                         {"type": "revolute", "anchor": _r(anchor), "axis": [0, 1, 0],
                          "limits": {"lower": -limit, "upper": limit}}, q))
    post = {"name": "post", "fixed_base": True,
            "base": {"shape": _box((0.1, 0.1, 0.1)), "position": [0, 0, anchor_z + 0.05]},
            "links": out}
    return _scene("limit_chain", "A chain of %d links (0.25 m, 1 kg) on revolute joints limited to "
                  "+-%.2f rad, hanging from a fixed post 1 m up onto the ground: released straight "
                  "and tilted %.2f rad, it swings down and the ground bends it into its limits "
                  "(the joint-limit holding case)." % (links, limit, tilt), 300, [post])


def articulated_scenes():
    return (("arm_push", arm_push()), ("legged_base", legged_base()),
            ("spherical_chain", spherical_chain()), ("limit_chain", limit_chain()))
