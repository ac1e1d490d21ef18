"""Reads mechanisms/specs/gough_stewart.toml and writes, for the harness in this directory:

- specs/bundled/gough_stewart.toml: the bundled spec as it is (copied);
- specs/full/gough_stewart.toml: the same platform with full inertia tensors and off-axis mass
  centres on every body (the leg bodies' values of runtime/tests/parallel_gs.rs's "skew" platform,
  products of inertia and an offset mass centre on the platform);
- gs_model.hpp: both as Pinocchio models of the opened tree (a free-flyer platform; per leg RX, RY
  (the U joint) and PZ (the actuated prismatic joint) from the base; the S joints cut), with the
  numbers the spec's expressions evaluate to, printed to 17 significant digits.

The spec's expression language (docs/spec.md, "Parameters"): arrays indexed from 1, the copy
number i from 1, `^` for powers, sqrt/atan2/hypot/sin/cos/...; the few constructs this spec uses
are evaluated here and anything else is refused (an assertion), so a changed spec fails loudly.
"""
import math, os, re, shutil, sys, tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
SPEC = os.path.join(HERE, "..", "..", "..", "mechanisms", "specs", "gough_stewart.toml")


class Arr:
    """A spec array: indexed from 1."""
    def __init__(self, v): self.v = v
    def __getitem__(self, k):
        k = int(k); assert k == float(k) and 1 <= k <= len(self.v), k
        return self.v[k - 1]


FUNCS = dict(sqrt=math.sqrt, atan2=math.atan2, hypot=math.hypot, sin=math.sin, cos=math.cos,
             tan=math.tan, asin=math.asin, acos=math.acos, atan=math.atan, abs=abs, min=min,
             max=max, pi=math.pi)


class Env:
    """Parameters evaluated lazily (they may use each other in any order)."""
    def __init__(self, raw, parent=None, extra=None):
        self.raw, self.parent, self.vals = raw, parent, dict(extra or {})
    def get(self, name):
        if name in self.vals: return self.vals[name]
        if name in self.raw:
            v = self.raw[name]
            v = Arr([self.eval(x) for x in v]) if isinstance(v, list) else self.eval(v)
            self.vals[name] = v
            return v
        if self.parent: return self.parent.get(name)
        raise KeyError(name)
    def eval(self, e):
        if isinstance(e, (int, float)): return float(e)
        assert isinstance(e, str), e
        assert not re.search(r"\b(deg|rad)\b|°|π", e), f"units not handled: {e}"
        py = e.replace("^", "**")
        names = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", py)) - set(FUNCS)
        ns = dict(FUNCS); ns.update({n: self.get(n) for n in names})
        return float(eval(py, {"__builtins__": {}}, ns))


def rpy_matrix(r, p, y):
    """R = Rz(y) Ry(p) Rx(r) (the spec's and URDF's fixed-axis X-Y-Z angles)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr]]


def inertia(env, t):
    """(ixx, ixy, ixz, iyy, iyz, izz) about the mass centre, body axes (products as tensor entries)."""
    assert set(t) <= {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"}, t
    g = lambda k: env.eval(t.get(k, 0.0))
    return [g("ixx"), g("ixy"), g("ixz"), g("iyy"), g("iyz"), g("izz")]


def body(env, b):
    assert set(b) <= {"name", "mass", "com", "inertia"}, b  # no inertia_rpy
    return dict(mass=env.eval(b["mass"]), com=[env.eval(c) for c in b.get("com", [0, 0, 0])],
                inertia=inertia(env, b["inertia"]))


def model(spec):
    mech, plat = spec["mechanism"], spec["platform"]
    top = Env(spec.get("parameters", {}))
    assert plat["coordinates"] == "pose" and "rpy" not in plat["home"], plat
    home = [top.eval(v) for v in plat["home"]["xyz"]]
    bodies = {b["name"]: b for b in spec["body"]}
    (pat,) = spec["pattern"]
    assert float(pat["angle"]) == 0.0 and "axis" not in pat, "copies that turn are not handled"
    assert not spec.get("joint"), "joints outside the pattern are not handled"
    legs = []
    for i in range(1, pat["copies"] + 1):
        env = Env(pat.get("parameters", {}), top, {"i": float(i)})
        sub = lambda s: s.replace("{i}", str(i))
        js = {sub(j["name"]): j for j in pat["joint"]}
        bs = {sub(b["name"]): b for b in pat["body"]}
        u, p, s = js[f"u{i}"], js[f"p{i}"], js[f"s{i}"]
        # U at the base, two revolutes about the joint frame's x then y (the default axes).
        assert u["kind"] == "U" and u["parent"] == "base" and "axes" not in u, u
        assert set(u["origin"]) == {"xyz", "rpy"}
        # The actuated P along z from the U centre (identity origin): q = leg length - home length.
        assert p["kind"] == "P" and sub(p["parent"]) == sub(u["child"]) and "origin" not in p and p.get("actuated")
        assert [float(a) for a in p["axis"]] == [0.0, 0.0, 1.0]
        # The S at (0, 0, length) on the piston, at child_origin on the platform.
        assert s["kind"] == "S" and sub(s["parent"]) == sub(p["child"]) and s["child"] == plat["body"]
        assert set(s["origin"]) == {"xyz"} and set(s["child_origin"]) == {"xyz"}
        so = [env.eval(c) for c in s["origin"]["xyz"]]
        assert so[0] == 0.0 and so[1] == 0.0
        rpy = [env.eval(c) for c in u["origin"]["rpy"]]
        legs.append(dict(
            b=[env.eval(c) for c in u["origin"]["xyz"]], rpy=rpy, R0=rpy_matrix(*rpy),
            tip=so[2], p=[env.eval(c) for c in s["child_origin"]["xyz"]],
            cylinder=body(env, bs[sub(u["child"])]), piston=body(env, bs[sub(p["child"])])))
    return dict(name=mech["name"], gravity=[top.eval(g) for g in mech.get("gravity", [0, 0, -9.81])],
                home=home, platform=body(top, bodies[plat["body"]]), legs=legs)


def full_variant(text):
    """The bundled spec with full inertia tensors and off-axis mass centres (each edit made once)."""
    edits = [
        # platform
        ('com = [0.0, 0.0, 0.0]', 'com = [0.01, -0.02, 0.015]'),
        ('inertia = { ixx = 0.08, iyy = 0.08, izz = 0.08 }',
         'inertia = { ixx = 0.08, iyy = 0.09, izz = 0.1, ixy = 0.002, ixz = -0.003, iyz = 0.001 }'),
        # cylinder (the first leg body)
        ('com = [0.0, 0.0, 0.5]', 'com = [0.013, -0.021, 0.47]'),
        ('inertia = { ixx = "leg_inertia", iyy = "leg_inertia", izz = "leg_inertia" }\n\n[[pattern.body]]',
         'inertia = { ixx = 0.006, iyy = 0.007, izz = 0.002, ixy = 0.0004, ixz = -0.0003, iyz = 0.0002 }\n\n[[pattern.body]]'),
        # piston
        ('com = [0.0, 0.0, "length - 0.5"]', 'com = [-0.017, 0.008, "length - 0.5"]'),
        ('inertia = { ixx = "leg_inertia", iyy = "leg_inertia", izz = "leg_inertia" }\n\n[[pattern.joint]]',
         'inertia = { ixx = "leg_inertia", iyy = "leg_inertia", izz = "leg_inertia", ixz = 0.0005 }\n\n[[pattern.joint]]'),
    ]
    for a, b in edits:
        assert text.count(a) == 1, f"edit not unique in the spec: {a!r}"
        text = text.replace(a, b)
    return ("# Generated by tools/pinocchio_check/gough_stewart/gen.py: the bundled spec with full inertia\n"
            "# tensors and off-axis mass centres on every body (not a published platform).\n" + text)


def cpp_body(name, b):
    f = lambda v: ", ".join(f"{x:.17g}" for x in v)
    return f"  const Body {name}{{{b['mass']:.17g}, {{{f(b['com'])}}}, {{{f(b['inertia'])}}}}};\n"


def cpp(ns, m):
    f = lambda v: ", ".join(f"{x:.17g}" for x in v)
    s = f"namespace {ns} {{  // {m['name']}\n"
    s += f"  const double gravity[3] = {{{f(m['gravity'])}}};\n"
    s += f"  const double home[3] = {{{f(m['home'])}}};\n"
    s += cpp_body("platform", m["platform"])
    s += "  const Leg legs[6] = {\n"
    for L in m["legs"]:
        R = L["R0"]
        s += (f"    {{{{{f(L['b'])}}}, {{{f(L['rpy'])}}},\n"
              f"     {{{f(R[0])}, {f(R[1])}, {f(R[2])}}},\n"
              f"     {L['tip']:.17g}, {{{f(L['p'])}}},\n"
              f"     {{{L['cylinder']['mass']:.17g}, {{{f(L['cylinder']['com'])}}}, {{{f(L['cylinder']['inertia'])}}}}},\n"
              f"     {{{L['piston']['mass']:.17g}, {{{f(L['piston']['com'])}}}, {{{f(L['piston']['inertia'])}}}}}}},\n")
    s += "  };\n}\n"
    return s


def main():
    text = open(SPEC, encoding="utf-8").read()
    variants = {"bundled": text, "full": full_variant(text)}
    out = ["// @generated by gen.py from mechanisms/specs/gough_stewart.toml: do not edit.\n"
           "#pragma once\n"
           "struct Body { double mass, com[3], inertia[6]; };  // inertia: ixx ixy ixz iyy iyz izz, about com\n"
           "// U at b (origin rpy, R0 = Rz Ry Rx of it: the U frame, z along the leg at home), axes x then y;\n"
           "// P along that z; S at z = tip on the piston, at p on the platform.\n"
           "struct Leg { double b[3], rpy[3], R0[9], tip, p[3]; Body cylinder, piston; };\n"]
    for v, t in variants.items():
        d = os.path.join(HERE, "specs", v)
        os.makedirs(d, exist_ok=True)
        p = os.path.join(d, "gough_stewart.toml")
        if not os.path.exists(p) or open(p, encoding="utf-8").read() != t:
            open(p, "w", encoding="utf-8").write(t)
        out.append(cpp(v, model(tomllib.loads(t))))
    h = os.path.join(HERE, "gs_model.hpp")
    if not os.path.exists(h) or open(h).read() != "".join(out):  # so that run.sh's g++ runs only on a change
        open(h, "w").write("".join(out))


if __name__ == "__main__":
    main()
