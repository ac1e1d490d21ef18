#!/usr/bin/env python3
"""Writes the test specs of this folder whose loops are turned in space, with full-precision
numbers that close every loop at home (checked here to 1e-15 m).

    python3 tests/data/gen_rank_specs.py

Standard library only. Conventions as in mechanisms/specs: R = Rz(yaw)·Ry(pitch)·Rx(roll), a
body's frame is its joint's frame after the motion, every tree joint is at zero at home.

* planar_3rrr_inclined.toml: a planar 3-RRR (three R-R-R legs from the base to a triangular
  platform, the base joints actuated) on a plane inclined by rpy = (0.3, 0.2, 0): 3 DOF.
* delta_4r.toml: a Delta robot whose forearm parallelograms are four revolute joints each (with
  a revolute at each end of the parallelogram, parallel to the actuated axis), legs at 120°:
  16 tree joints, 5 loop-closing joints, loop equations of rank 13, 3 DOF.
"""

import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def add(a, b):
    return [a[i] + b[i] for i in range(3)]


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def scale(s, a):
    return [s * x for x in a]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]


def norm(a):
    return math.sqrt(dot(a, a))


def rz(t, v):
    c, s = math.cos(t), math.sin(t)
    return [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]


def circle_meet(a, ra, c, rc, pick):
    """Points in the plane of 2-vectors at distance ra from a and rc from c; pick(+1/-1)."""
    d = [c[0] - a[0], c[1] - a[1]]
    dd = math.hypot(*d)
    x = (ra * ra - rc * rc + dd * dd) / (2 * dd)
    y = pick * math.sqrt(ra * ra - x * x)
    ex = [d[0] / dd, d[1] / dd]
    return [a[0] + x * ex[0] - y * ex[1], a[1] + x * ex[1] + y * ex[0]]


def f(x):
    return repr(float(x))


def vec(v):
    return "[" + ", ".join(f(x) for x in v) + "]"


def body(name, mass, com, i):
    return (
        f'[[body]]\nname = "{name}"\nmass = {f(mass)}\ncom = {vec(com)}\n'
        f"inertia = {{ ixx = {f(i[0])}, iyy = {f(i[1])}, izz = {f(i[2])} }}\n"
    )


def joint(name, kind, parent, child, xyz, rpy=(0.0, 0.0, 0.0), axis=None, extra=""):
    s = f'[[joint]]\nname = "{name}"\nkind = "{kind}"\nparent = "{parent}"\nchild = "{child}"\n'
    s += f"origin = {{ xyz = {vec(xyz)}, rpy = {vec(rpy)} }}\n"
    if axis is not None:
        s += f"axis = {vec(axis)}\n"
    return s + extra


def rod(m, length):
    """Slender rod along x: (ixx, iyy, izz) about its centre (a 1 cm square section)."""
    a = m * 2 * 0.01**2 / 12
    b = m * (length**2 + 0.01**2) / 12
    return (a, b, b)


def planar_3rrr():
    rb, rp, l1, l2 = 0.5, 0.12, 0.32, 0.3
    psi, centre = 0.2, [0.02, -0.01, 0.0]  # platform orientation and centre in the plane
    th = [math.pi / 2 + 2 * math.pi * i / 3 for i in range(3)]
    a = [[rb * math.cos(t), rb * math.sin(t), 0.0] for t in th]
    c = [add(centre, rz(psi, [rp * math.cos(t), rp * math.sin(t), 0.0])) for t in th]
    b = []
    for i in range(3):
        e = circle_meet(a[i], l1, c[i], l2, 1.0)
        b.append([e[0], e[1], 0.0])
        assert abs(norm(sub(b[i], a[i])) - l1) < 1e-15 and abs(norm(sub(c[i], b[i])) - l2) < 1e-15
    al = [math.atan2(b[i][1] - a[i][1], b[i][0] - a[i][0]) for i in range(3)]
    be = [math.atan2(c[i][1] - b[i][1], c[i][0] - b[i][0]) for i in range(3)]
    out = [
        "# A planar 3-RRR (three R-R-R legs from the base to a triangular platform, the base joints\n"
        "# actuated) on a plane inclined by rpy = (0.3, 0.2, 0): 3 DOF. Test data of\n"
        "# tests/tests/turned.rs, written by tests/data/gen_rank_specs.py (illustrative numbers).\n"
        "# Legs at 120° on a 0.5 m circle, links 0.32 m and 0.3 m, platform joints on a 0.12 m\n"
        "# circle; the platform frame is at the first leg's platform joint, turned by 0.2 rad.\n",
        '[mechanism]\nname = "planar_3rrr_inclined"\ngravity = [0.0, 0.0, -9.81]\n',
        body("plane", 0.0, [0.0] * 3, (0.0, 0.0, 0.0)),
        joint("mount", "fixed", "base", "plane", [0.05, -0.02, 0.1], (0.3, 0.2, 0.0)),
    ]
    com = rz(-psi, sub(centre, c[0]))
    out.append(body("platform", 0.6, com, (2e-3, 2e-3, 4e-3)))
    for i in range(3):
        k = i + 1
        out.append(body(f"proximal{k}", 0.4, [l1 / 2, 0.0, 0.0], rod(0.4, l1)))
        out.append(body(f"distal{k}", 0.3, [l2 / 2, 0.0, 0.0], rod(0.3, l2)))
        z = [0.0, 0.0, 1.0]
        out.append(joint(f"a{k}", "revolute", "plane", f"proximal{k}", a[i], (0, 0, al[i]), z, "actuated = true\n"))
        out.append(joint(f"b{k}", "revolute", f"proximal{k}", f"distal{k}", [l1, 0.0, 0.0], (0, 0, be[i] - al[i]), z))
        if i == 0:
            out.append(joint("c1", "revolute", "distal1", "platform", [l2, 0.0, 0.0], (0, 0, psi - be[0]), z))
        else:
            co = rz(-psi, sub(c[i], c[0]))
            extra = f"child_origin = {{ xyz = {vec(co)}, rpy = {vec([0.0, 0.0, be[i] - psi])} }}\n"
            out.append(joint(f"c{k}", "revolute", f"distal{k}", "platform", [l2, 0.0, 0.0], (0, 0, 0), z, extra))
    return "\n".join(out)


def delta_4r():
    rb, la, lf, w, rp = 0.2, 0.25, 0.6, 0.08, 0.05
    centre = [0.03, -0.02, -0.5]  # the platform centre at home, off the axis
    phi = [2 * math.pi * i / 3 for i in range(3)]
    y = [0.0, 1.0, 0.0]
    out = [
        "# A Delta robot whose forearm parallelograms are four revolute joints each, legs at 120°.\n"
        "# Leg i (frame turned by 120° i about z, x outward): the actuated revolute at A about y,\n"
        "# the upper arm to the elbow E, a revolute about y to the elbow bar (along y, 0.08 m), the\n"
        "# parallelogram: two 0.6 m rods on revolutes about n = y × d (d the rod direction) to the\n"
        "# platform bar, and a revolute about y to the platform. Tree: 16 joints; loop-closing: the\n"
        "# three second rods and legs 2 and 3 at the platform; loop equations of rank 13: 3 DOF.\n"
        "# Test data of tests/tests/turned.rs, written by tests/data/gen_rank_specs.py\n"
        "# (illustrative numbers).\n",
        '[mechanism]\nname = "delta_4r"\ngravity = [0.0, 0.0, -9.81]\n',
    ]
    c_base = [add(centre, rz(p, [rp, 0.0, 0.0])) for p in phi]
    out.append(body("platform", 0.4, sub(centre, c_base[0]), (4e-4, 4e-4, 8e-4)))
    for i in range(3):
        k = i + 1
        a = [rb, 0.0, 0.0]
        c = rz(-phi[i], c_base[i])  # leg frame
        # The elbow on the circle of radius la about A in the x-z plane, at distance lf from C.
        r = math.sqrt(lf * lf - c[1] * c[1])
        ex = circle_meet([a[0], a[2]], la, [c[0], c[2]], r, -1.0)
        e = [ex[0], 0.0, ex[1]]
        if e[0] < a[0]:
            ex = circle_meet([a[0], a[2]], la, [c[0], c[2]], r, 1.0)
            e = [ex[0], 0.0, ex[1]]
        assert abs(norm(sub(e, a)) - la) < 1e-15 and abs(norm(sub(c, e)) - lf) < 1e-15
        d = scale(1 / lf, sub(c, e))
        n = cross(y, d)
        n = scale(1 / norm(n), n)
        ce = sub(c, e)
        out.append(body(f"upper{k}", 0.3, scale(0.5, sub(e, a)), (6e-4, 1.6e-3, 1.6e-3)))
        out.append(body(f"elbow_bar{k}", 0.02, [0.0] * 3, (1.1e-5, 2e-7, 1.1e-5)))
        out.append(body(f"rod_a{k}", 0.05, scale(0.5, ce), (1.5e-3, 1.5e-3, 1e-6)))
        out.append(body(f"rod_b{k}", 0.05, scale(0.5, ce), (1.5e-3, 1.5e-3, 1e-6)))
        out.append(body(f"platform_bar{k}", 0.02, [0.0, w / 2, 0.0], (1.1e-5, 2e-7, 1.1e-5)))
        out.append(joint(f"a{k}", "revolute", "base", f"upper{k}", rz(phi[i], a), (0, 0, phi[i]), y, "actuated = true\n"))
        out.append(joint(f"e{k}", "revolute", f"upper{k}", f"elbow_bar{k}", sub(e, a), axis=y))
        out.append(joint(f"ra{k}", "revolute", f"elbow_bar{k}", f"rod_a{k}", [0.0, -w / 2, 0.0], axis=n))
        out.append(joint(f"sa{k}", "revolute", f"rod_a{k}", f"platform_bar{k}", ce, axis=n))
        out.append(joint(f"rb{k}", "revolute", f"elbow_bar{k}", f"rod_b{k}", [0.0, w / 2, 0.0], axis=n))
        extra = f"child_origin = {{ xyz = {vec([0.0, w, 0.0])} }}\n"
        out.append(joint(f"sb{k}", "revolute", f"rod_b{k}", f"platform_bar{k}", ce, axis=n, extra=extra))
        if i == 0:
            out.append(joint("p1", "revolute", "platform_bar1", "platform", [0.0, w / 2, 0.0], axis=y))
        else:
            co = sub(c_base[i], c_base[0])
            extra = f"child_origin = {{ xyz = {vec(co)}, rpy = {vec([0.0, 0.0, phi[i]])} }}\n"
            out.append(joint(f"p{k}", "revolute", f"platform_bar{k}", "platform", [0.0, w / 2, 0.0], axis=y, extra=extra))
        # Closure of the leg at the platform, in the base frame.
        tip = add(rz(phi[i], add(add(a, sub(e, a)), add([0.0, -w / 2, 0.0], add(ce, [0.0, w / 2, 0.0])))), [0.0] * 3)
        assert norm(sub(tip, c_base[i])) < 1e-15, norm(sub(tip, c_base[i]))
    return "\n".join(out)


for name, text in [("planar_3rrr_inclined", planar_3rrr()), ("delta_4r", delta_4r())]:
    with open(os.path.join(HERE, f"{name}.toml"), "w") as fh:
        fh.write(text)
    print(f"wrote {name}.toml")
