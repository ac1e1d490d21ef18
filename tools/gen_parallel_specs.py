#!/usr/bin/env python3
"""Writes the parallel-mechanism specs of mechanisms/specs/ with full-precision numbers.

    python3 tools/gen_parallel_specs.py        # rewrites the four parallel .toml files in mechanisms/specs/

Standard library only. Every leg joint is at zero at home, so the joint frames of each leg are
placed such that the loop closes at the declared home pose of the platform; the script checks
the closure itself and prints, for each mechanism, the leg lengths and the condition number of
the (normalized) actuation matrix at home (large means near a parallel singularity).

Conventions (docs/spec.md): SI units; `origin.rpy` and `child_origin.rpy` are fixed-axis X-Y-Z
angles, R = Rz(yaw)·Ry(pitch)·Rx(roll); a U joint rotates about x, then y of its joint frame;
a body's frame is its joint's frame after the motion.
"""

import math
import os

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "mechanisms", "specs")


# ---------------------------------------------------------------- small linear algebra
def add(a, b):
    return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def scale(s, a):
    return [s * a[0], s * a[1], s * a[2]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    return scale(1.0 / norm(a), a)


def columns(x, y, z):
    """The rotation matrix whose columns are x, y, z."""
    return [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]


def transpose(m):
    return [[m[j][i] for j in range(3)] for i in range(3)]


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def mat_vec(a, v):
    return [dot(a[i], v) for i in range(3)]


def rpy_of(m):
    """Fixed-axis X-Y-Z angles of a rotation matrix: m = Rz(y)·Ry(p)·Rx(r)."""
    p = math.asin(max(-1.0, min(1.0, -m[2][0])))
    r = math.atan2(m[2][1], m[2][2])
    y = math.atan2(m[1][0], m[0][0])
    return [r, p, y]


def rpy_matrix(rpy):
    r, p, y = rpy
    sr, cr = math.sin(r), math.cos(r)
    sp, cp = math.sin(p), math.cos(p)
    sy, cy = math.sin(y), math.cos(y)
    return [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]


def frame_with_z(z):
    """A rotation whose z axis is `z` (unit) and whose x axis is horizontal (z is not vertical)."""
    x = unit(cross([0.0, 0.0, 1.0], z))
    y = cross(z, x)
    return columns(x, y, z)


def condition(rows):
    """2-norm condition number of a square matrix (Jacobi eigenvalues of AᵀA)."""
    n = len(rows)
    a = [[sum(rows[k][i] * rows[k][j] for k in range(n)) for j in range(n)] for i in range(n)]
    for _ in range(100):
        off = sum(a[i][j] ** 2 for i in range(n) for j in range(n) if i != j)
        if off < 1e-30:
            break
        for p in range(n):
            for q in range(p + 1, n):
                if abs(a[p][q]) < 1e-300:
                    continue
                theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q])
                t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
                c = 1.0 / math.sqrt(t * t + 1.0)
                s = t * c
                for k in range(n):
                    akp, akq = a[k][p], a[k][q]
                    a[k][p] = c * akp - s * akq
                    a[k][q] = s * akp + c * akq
                for k in range(n):
                    apk, aqk = a[p][k], a[q][k]
                    a[p][k] = c * apk - s * aqk
                    a[q][k] = s * apk + c * aqk
    ev = sorted(a[i][i] for i in range(n))
    return math.sqrt(ev[-1] / ev[0]) if ev[0] > 0 else float("inf")


# ---------------------------------------------------------------- inertia formulas
def rod_inertia(m, length, radius):
    """Solid cylinder along z about its mass centre: (ixx, iyy, izz)."""
    i = m * (3.0 * radius * radius + length * length) / 12.0
    return (i, i, m * radius * radius / 2.0)


def box_inertia(m, a, b, c):
    """Solid box with edges a, b, c along x, y, z about its mass centre."""
    return (m * (b * b + c * c) / 12.0, m * (a * a + c * c) / 12.0, m * (a * a + b * b) / 12.0)


def arc_props(m, rho, a, b, core):
    """A thin 90° circular arc of radius `rho` about the origin from unit direction a to b
    (orthogonal), plus `core` kg·m² on the diagonal for the cross-section: (com, inertia
    about the com as a 3×3 matrix)."""
    # Second moments S = ∫ r rᵀ dm = m ρ² (½aaᵀ + ½bbᵀ + (abᵀ + baᵀ)/π).
    s = [
        [m * rho * rho * (0.5 * a[i] * a[j] + 0.5 * b[i] * b[j] + (a[i] * b[j] + b[i] * a[j]) / math.pi)
         for j in range(3)]
        for i in range(3)
    ]
    tr = s[0][0] + s[1][1] + s[2][2]
    io = [[(tr if i == j else 0.0) - s[i][j] for j in range(3)] for i in range(3)]
    # Mass centre on the bisector at ρ·sin(π/4)/(π/4).
    c = scale(rho * math.sin(math.pi / 4) / (math.pi / 4) / math.sqrt(2.0), add(a, b))
    cc = dot(c, c)
    ic = [
        [io[i][j] - m * ((cc if i == j else 0.0) - c[i] * c[j]) + (core if i == j else 0.0)
         for j in range(3)]
        for i in range(3)
    ]
    return c, ic


# ---------------------------------------------------------------- TOML output
def num(x):
    """Shortest repr that round-trips; exact zeros as 0.0."""
    if x == 0.0:
        return "0.0"
    return repr(float(x))


def vec(v):
    return "[" + ", ".join(num(x) for x in v) + "]"


def inertia_table(i):
    if isinstance(i, tuple):
        return "{ ixx = %s, iyy = %s, izz = %s }" % tuple(num(x) for x in i)
    parts = [
        ("ixx", i[0][0]), ("iyy", i[1][1]), ("izz", i[2][2]),
        ("ixy", i[0][1]), ("ixz", i[0][2]), ("iyz", i[1][2]),
    ]
    return "{ " + ", ".join("%s = %s" % (k, num(v)) for k, v in parts) + " }"


def origin(xyz, rpy=None):
    if rpy is None or all(a == 0.0 for a in rpy):
        return "{ xyz = %s }" % vec(xyz)
    return "{ xyz = %s, rpy = %s }" % (vec(xyz), vec(rpy))


class Spec:
    def __init__(self, header):
        self.lines = ["# " + l if l else "#" for l in header.strip("\n").split("\n")]
        self.lines.append("# Generated by tools/gen_parallel_specs.py; edit the script, not this file.")

    def blank(self):
        self.lines.append("")

    def comment(self, text):
        self.lines.append("# " + text)

    def table(self, header, items):
        self.lines.append(header)
        for k, v in items:
            self.lines.append("%s = %s" % (k, v))
        self.blank()

    def body(self, name, mass, com, inertia):
        self.table("[[body]]", [
            ("name", '"%s"' % name),
            ("mass", num(mass)),
            ("com", vec(com)),
            ("inertia", inertia_table(inertia)),
        ])

    def joint(self, name, kind, parent, child, origin_=None, axis=None, actuated=False,
              child_origin=None):
        items = [
            ("name", '"%s"' % name),
            ("kind", '"%s"' % kind),
            ("parent", '"%s"' % parent),
            ("child", '"%s"' % child),
        ]
        if origin_ is not None:
            items.append(("origin", origin_))
        if axis is not None:
            items.append(("axis", vec(axis)))
        if actuated:
            items.append(("actuated", "true"))
        if child_origin is not None:
            items.append(("child_origin", child_origin))
        self.table("[[joint]]", items)

    def write(self, file):
        text = "\n".join(self.lines).rstrip("\n") + "\n"
        with open(os.path.join(HERE, file), "w", encoding="utf-8") as f:
            f.write(text)
        print("wrote", file)


def semi_regular(radius, half_angle_deg, phase_deg, z=0.0):
    """Six points in three pairs, 3-fold symmetric: angles phase + 120k ∓ half_angle,
    in the order (pair 0 −, pair 0 +, pair 1 −, …)."""
    pts = []
    for k in range(3):
        for s in (-1.0, 1.0):
            a = math.radians(phase_deg + 120.0 * k + s * half_angle_deg)
            pts.append([radius * math.cos(a), radius * math.sin(a), z])
    return pts


def check_closure(name, tip, target, tol=1e-12):
    d = norm(sub(tip, target))
    assert d < tol, "%s: the loop does not close (%g m)" % (name, d)


def plucker_condition(points, dirs):
    rows = [cross(p, s) + s for p, s in zip(points, dirs)]
    return condition(rows)


# ---------------------------------------------------------------- 1. Gough–Stewart (Tsai 2000)
def gough_stewart():
    base = [
        [-2.12, 1.374, 0.0], [-2.38, 1.224, 0.0], [-2.38, -1.224, 0.0],
        [-2.12, -1.374, 0.0], [0.0, -0.15, 0.0], [0.0, 0.15, 0.0],
    ]
    plat = [
        [0.17, 0.595, -0.4], [-0.6, 0.15, -0.4], [-0.6, -0.15, -0.4],
        [0.17, -0.595, -0.4], [0.43, -0.445, -0.4], [0.43, 0.445, -0.4],
    ]
    home = [-1.5, 0.0, 1.0]
    i_leg = 1.0 / 160.0
    s = Spec("""
Gough-Stewart platform, 6-UPS: the example of L.-W. Tsai, "Solving the inverse dynamics of a
Stewart-Gough manipulator by the principle of virtual work", ASME J. Mech. Des. 122(1):3-9, 2000.
Numbers as in a public re-implementation citing the paper (as collected in docs/method.md,
"Test cases from the literature"):
  base joints b_i (world, z = 0), platform joints p_i (platform frame, origin at the platform's
  mass centre), platform m = 1.5 kg, I = diag(0.08) kg m^2, cylinder and piston 0.1 kg each,
  gravity 9.81 m/s^2 along -z.
*Unconfirmed* against the paper: the leg inertias diag(1/160) kg m^2 about the mass centres, and
the leg mass-centre offsets (cylinder 0.5 m from the base joint, piston 0.5 m from the platform
joint).
Home: platform frame at (-1.5, 0, 1.0) m, identity orientation (the centre of Tsai's motions).
Leg i: U at b_i whose joint frame has its z axis along the leg at home (U axes: that frame's x,
horizontal, then y); the cylinder is the U's second body; an actuated P joint along z from the
U centre moves the piston (so q_i = leg length - home length); the S joint at p_i on the piston's
z axis. Tsai's no-spin assumption holds by construction (a U joint at the base).
""")
    s.table("[mechanism]", [
        ("name", '"gough_stewart"'),
        ("gravity", vec([0.0, 0.0, -9.81])),
        ("source", '"Tsai (2000), ASME J. Mech. Des. 122(1):3-9, via a public re-implementation; leg inertias and mass-centre offsets unconfirmed"'),
    ])
    s.table("[platform]", [
        ("body", '"platform"'),
        ("coordinates", '"pose"'),
        ("home", origin(home, [0.0, 0.0, 0.0])),
    ])
    s.body("platform", 1.5, [0.0, 0.0, 0.0], (0.08, 0.08, 0.08))
    points, dirs, lengths = [], [], []
    for i in range(6):
        n = i + 1
        b = base[i]
        p_world = add(home, plat[i])
        d = sub(p_world, b)
        length = norm(d)
        z = unit(d)
        r = frame_with_z(z)
        rpy = rpy_of(r)
        r2 = rpy_matrix(rpy)
        tip = add(b, mat_vec(r2, [0.0, 0.0, length]))
        check_closure("gough_stewart leg %d" % n, tip, p_world)
        points.append(sub(p_world, home))
        dirs.append(z)
        lengths.append(length)
        s.comment("Leg %d: b = %s, p = %s, home length %.6f m" % (n, vec(b), vec(plat[i]), length))
        s.body("cylinder%d" % n, 0.1, [0.0, 0.0, 0.5], (i_leg, i_leg, i_leg))
        s.body("piston%d" % n, 0.1, [0.0, 0.0, length - 0.5], (i_leg, i_leg, i_leg))
        s.joint("u%d" % n, "U", "base", "cylinder%d" % n, origin(b, rpy))
        s.joint("p%d" % n, "P", "cylinder%d" % n, "piston%d" % n, axis=[0.0, 0.0, 1.0],
                actuated=True)
        s.joint("s%d" % n, "S", "piston%d" % n, "platform", origin([0.0, 0.0, length]),
                child_origin=origin(plat[i]))
    s.write("gough_stewart.toml")
    print("  leg lengths", ["%.4f" % l for l in lengths],
          "cond(A) %.3g" % plucker_condition(points, dirs))


# ---------------------------------------------------------------- 2. sliding-leg hexapod (6-PUS)
def sliding_hexapod():
    rb, ab = 0.6, 10.0  # rail circle radius (m), pair half-angle (deg)
    rp, ap = 0.25, 15.0  # platform joint circle radius, pair half-angle
    zp = -0.05  # S centres below the platform frame
    home = [0.0, 0.0, 1.0]
    rod_len = 0.6
    m_slider, m_rod, m_plat = 1.5, 0.8, 8.0
    rails = semi_regular(rb, ab, 90.0)
    plat_pts = semi_regular(rp, ap, 30.0, zp)
    s = Spec("""
Sliding-leg (fixed-length leg) hexapod, 6-PUS, in the manner of the HexaM (Toyoda), Hexaglide
(ETH) and Linapod (Stuttgart) machines (docs/method.md, "Test cases from the literature"; Sinatra & Xi 2008). ILLUSTRATIVE
numbers, not a real machine: six vertical rails on a semi-regular hexagon of radius 0.6 m (pairs
+-10 deg about 90, 210, 330 deg), an actuated slider (P, along z) on each, a U on the slider,
a fixed-length leg of 0.6 m (steel tube: 0.8 kg, radius 15 mm) to an S joint on the platform, whose
joints lie on a semi-regular hexagon of radius 0.25 m (pairs +-15 deg about 30, 150, 270 deg),
5 cm below the platform frame. Base and platform hexagons are not similar (no architecture
singularity). Platform: 8 kg disc (radius 0.3 m, 30 mm thick), mass centre at the platform frame
origin. Sliders: 1.5 kg boxes 0.1 x 0.1 x 0.15 m, mass centre 3 cm radially outward of the U
centre. Home: platform frame at (0, 0, 1.0) m, identity orientation; every slider's coordinate is
measured from its home height.
""")
    s.table("[mechanism]", [
        ("name", '"sliding_hexapod"'),
        ("gravity", vec([0.0, 0.0, -9.81])),
        ("source", '"illustrative HexaM/Linapod-like 6-PUS hexapod (see the header comment)"'),
    ])
    s.table("[platform]", [
        ("body", '"platform"'),
        ("coordinates", '"pose"'),
        ("home", origin(home, [0.0, 0.0, 0.0])),
    ])
    s.body("platform", m_plat, [0.0, 0.0, 0.0], rod_inertia(m_plat, 0.03, 0.3))
    # Rail (pair k, −) meets the platform joint (pair k, +) and rail (pair k, +) the joint
    # (pair k + 1, −): 35 degrees apart in azimuth.
    partner = [(i + 1) % 6 for i in range(6)]
    points, dirs = [], []
    for i in range(6):
        n = i + 1
        rail = rails[i]
        p_local = plat_pts[partner[i]]
        p_world = add(home, p_local)
        horiz = norm(sub([p_world[0], p_world[1], 0.0], [rail[0], rail[1], 0.0]))
        z_slider = p_world[2] - math.sqrt(rod_len * rod_len - horiz * horiz)
        u_centre = [rail[0], rail[1], z_slider]
        d = unit(sub(p_world, u_centre))
        r = frame_with_z(d)
        rpy = rpy_of(r)
        tip = add(u_centre, mat_vec(rpy_matrix(rpy), [0.0, 0.0, rod_len]))
        check_closure("sliding_hexapod leg %d" % n, tip, p_world)
        points.append(sub(p_world, home))
        dirs.append(d)
        radial = unit([rail[0], rail[1], 0.0])
        s.comment("Leg %d: rail at %s, slider home height %.6f m, platform joint %s"
                  % (n, vec(rail[:2]), z_slider, vec(p_local)))
        s.body("slider%d" % n, m_slider, scale(0.03, radial), box_inertia(m_slider, 0.1, 0.1, 0.15))
        s.body("leg%d" % n, m_rod, [0.0, 0.0, rod_len / 2.0], rod_inertia(m_rod, rod_len, 0.015))
        s.joint("slide%d" % n, "P", "base", "slider%d" % n, origin(u_centre),
                axis=[0.0, 0.0, 1.0], actuated=True)
        s.joint("u%d" % n, "U", "slider%d" % n, "leg%d" % n, origin([0.0, 0.0, 0.0], rpy))
        s.joint("s%d" % n, "S", "leg%d" % n, "platform", origin([0.0, 0.0, rod_len]),
                child_origin=origin(p_local))
    s.write("sliding_hexapod.toml")
    print("  cond(A) %.3g" % plucker_condition(points, dirs))


# ---------------------------------------------------------------- 3. rotary hexapod (6-RUS)
def rus_hexapod():
    rb, ab = 0.2, 15.0  # motor shafts: circle radius (m), pair half-angle (deg)
    rp, ap = 0.12, 20.0  # platform joints
    crank, rod_len = 0.1, 0.3
    m_crank, m_rod, m_plat = 0.2, 0.15, 1.2
    motors = semi_regular(rb, ab, 90.0)
    plat_pts = semi_regular(rp, ap, 30.0)
    partner = [(i + 1) % 6 for i in range(6)]  # 25 degrees apart in azimuth
    s = Spec("""
Rotary hexapod, 6-RUS (revolute-actuated cranks, as in the common servo-driven Stewart
platforms). ILLUSTRATIVE numbers, not a real machine: six motor shafts on a semi-regular hexagon
of radius 0.2 m (pairs +-15 deg about 90, 210, 330 deg) with horizontal axes tangent to that
circle; a 0.1 m crank on each (actuated R; at home the crank points radially outward and is
horizontal); a U at the crank tip; a 0.3 m rod (0.15 kg, radius 5 mm) to an S joint on the
platform, whose joints lie on a semi-regular hexagon of radius 0.12 m (pairs +-20 deg about 30,
150, 270 deg) in the plane of the platform frame. Base and platform hexagons are not similar.
Cranks: 0.2 kg bars 0.1 m long, mass centre at mid-length. Platform: 1.2 kg disc (radius 0.15 m,
10 mm thick), mass centre at the platform frame origin. Home: platform frame above the base
centre at the height where every rod meets its platform joint with the cranks horizontal,
identity orientation.
""")
    # Platform height: every rod has the same length by symmetry.
    tips = []
    for i in range(6):
        radial = unit([motors[i][0], motors[i][1], 0.0])
        tips.append(add(motors[i], scale(crank, radial)))
    t0, p0 = tips[0], plat_pts[partner[0]]
    horiz = norm(sub([p0[0], p0[1], 0.0], [t0[0], t0[1], 0.0]))
    height = math.sqrt(rod_len * rod_len - horiz * horiz)
    home = [0.0, 0.0, height]
    s.table("[mechanism]", [
        ("name", '"rus_hexapod"'),
        ("gravity", vec([0.0, 0.0, -9.81])),
        ("source", '"illustrative rotary (6-RUS) hexapod (see the header comment)"'),
    ])
    s.table("[platform]", [
        ("body", '"platform"'),
        ("coordinates", '"pose"'),
        ("home", origin(home, [0.0, 0.0, 0.0])),
    ])
    s.body("platform", m_plat, [0.0, 0.0, 0.0], rod_inertia(m_plat, 0.01, 0.15))
    points, dirs = [], []
    for i in range(6):
        n = i + 1
        radial = unit([motors[i][0], motors[i][1], 0.0])
        # Crank frame: x along the crank (radial), y up, z = x × y (the shaft axis, tangential).
        rc = columns(radial, [0.0, 0.0, 1.0], cross(radial, [0.0, 0.0, 1.0]))
        rpy_c = rpy_of(rc)
        rc2 = rpy_matrix(rpy_c)
        tip = add(motors[i], mat_vec(rc2, [crank, 0.0, 0.0]))
        p_local = plat_pts[partner[i]]
        p_world = add(home, p_local)
        d = unit(sub(p_world, tip))
        ru = frame_with_z(d)
        rpy_u = rpy_of(mat_mul(transpose(rc2), ru))  # the U frame in the crank frame
        ru2 = mat_mul(rc2, rpy_matrix(rpy_u))
        end = add(tip, mat_vec(ru2, [0.0, 0.0, rod_len]))
        check_closure("rus_hexapod leg %d" % n, end, p_world)
        points.append(sub(p_world, home))
        dirs.append(d)
        s.comment("Leg %d: shaft at %s, platform joint %s" % (n, vec(motors[i][:2]), vec(p_local)))
        s.body("crank%d" % n, m_crank, [crank / 2.0, 0.0, 0.0],
               box_inertia(m_crank, crank, 0.02, 0.01))
        s.body("rod%d" % n, m_rod, [0.0, 0.0, rod_len / 2.0], rod_inertia(m_rod, rod_len, 0.005))
        s.joint("motor%d" % n, "R", "base", "crank%d" % n, origin(motors[i], rpy_c),
                axis=[0.0, 0.0, 1.0], actuated=True)
        s.joint("u%d" % n, "U", "crank%d" % n, "rod%d" % n, origin([crank, 0.0, 0.0], rpy_u))
        s.joint("s%d" % n, "S", "rod%d" % n, "platform", origin([0.0, 0.0, rod_len]),
                child_origin=origin(p_local))
    s.write("rus_hexapod.toml")
    print("  home height %.6f m, cond(A) %.3g" % (height, plucker_condition(points, dirs)))


# ---------------------------------------------------------------- 4. Agile Eye (spherical 3-RRR)
def agile_eye():
    x, y, z = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]
    legs = [(x, y, z), (y, z, x), (z, x, y)]
    r_base, r_mid, r_plat = 0.15, 0.12, 0.10  # where the joints sit on their axes (m)
    m_prox, m_dist = 0.25, 0.2
    core = 2e-5
    s = Spec("""
Agile Eye: spherical 3-RRR camera-orienting mechanism after C. M. Gosselin and J.-F. Hamel,
"The agile eye: a high-performance three-degree-of-freedom camera-orienting device", IEEE ICRA
1994, pp. 781-786 (geometry as in Bonev, Chablat & Wenger, ICRA 2006: all adjacent joint axes
orthogonal). Every axis passes through the centre of rotation, the origin. At home (identity)
leg i has base axis u_i, intermediate axis w_i and platform axis v_i with (u, w, v) = (x, y, z),
(y, z, x), (z, x, y); the base revolutes are actuated, and at home the actuation matrix is the
identity. Masses and inertias are ILLUSTRATIVE: each link is a thin 90-degree circular arc about
the centre (proximal link: 0.25 kg, radius 0.12 m, from the u axis to the w axis; distal link:
0.2 kg, radius 0.10 m, from w to v) plus 2e-5 kg m^2 on the diagonal for its cross-section; the
camera platform is 0.3 kg, I = diag(4e-4, 4e-4, 2.5e-4) kg m^2, mass centre 2 cm along its z
axis. The joints sit on their axes at 0.15 m (base), 0.12 m (intermediate) and 0.10 m
(platform) from the centre; each body frame has the base orientation at home.
""")
    s.table("[mechanism]", [
        ("name", '"agile_eye"'),
        ("gravity", vec([0.0, 0.0, -9.81])),
        ("source", '"Gosselin & Hamel (ICRA 1994) geometry; illustrative masses and inertias"'),
    ])
    s.table("[platform]", [
        ("body", '"camera"'),
        ("coordinates", '"orientation"'),
        ("home", origin([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])),
        ("centre", vec([0.0, 0.0, 0.0])),
    ])
    s.body("camera", 0.3, [0.0, 0.0, 0.02], (4e-4, 4e-4, 2.5e-4))
    for i, (u, w, v) in enumerate(legs):
        n = i + 1
        # Body frames keep the base orientation at home; origins on the joint axes.
        o1 = scale(r_base, u)
        o2 = scale(r_mid, w)
        o3 = scale(r_plat, v)
        c1, i1 = arc_props(m_prox, r_mid, u, w, core)
        c2, i2 = arc_props(m_dist, r_plat, w, v, core)
        s.comment("Leg %d: u = %s, w = %s, v = %s" % (n, vec(u), vec(w), vec(v)))
        s.body("proximal%d" % n, m_prox, sub(c1, o1), i1)
        s.body("distal%d" % n, m_dist, sub(c2, o2), i2)
        s.joint("a%d" % n, "R", "base", "proximal%d" % n, origin(o1), axis=u, actuated=True)
        s.joint("b%d" % n, "R", "proximal%d" % n, "distal%d" % n, origin(sub(o2, o1)), axis=w)
        s.joint("c%d" % n, "R", "distal%d" % n, "camera", origin(sub(o3, o2)), axis=v,
                child_origin=origin(o3))
    s.write("agile_eye.toml")


if __name__ == "__main__":
    gough_stewart()
    sliding_hexapod()
    rus_hexapod()
    agile_eye()
