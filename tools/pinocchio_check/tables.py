"""The README's tables "Against Pinocchio's code generation" from one run of run.sh.

Usage: python3 tables.py out/rust.txt out/cg.txt
rust.txt: the `fma NAME ...` lines of src/main.rs (generated code without and with FMA, and with
FMA and the joint angles' `sin_cos` in one call, `batch`);
cg.txt: the `cg NAME ...` lines of bench_cg.cpp (plain Pinocchio, its CppADCodeGen code through
the CodeGen classes' evalFunction, and the generated library called alone).
"""
import sys


def fields(line):
    return line.split()


def parse_rust(path):
    out = {}
    for line in open(path):
        if not line.startswith("fma "):
            continue
        f = fields(line)
        name, dof = f[1], int(f[3])
        err = {"ID": float(f[7]), "M": float(f[9]), "dID": float(f[11])}
        berr = {"ID": float(f[15]), "M": float(f[17]), "dID": float(f[19])}
        i = f.index("plain/fma/batch:")
        ns = {}
        for k in range(4):
            key, a, b, c = f[i + 1 + 4 * k:i + 5 + 4 * k]
            ns[key] = (float(a), float(b), float(c))
        err = (err, berr)
        out[name] = (dof, err, ns)
    return out


def parse_cg(path):
    out = {}
    for line in open(path):
        if not line.startswith("cg "):
            continue
        f = fields(line)
        name = f[1]
        check = {f[5]: float(f[6]), f[7]: float(f[8]), f[9]: float(f[10]), f[11]: float(f[12])}
        build = [float(x) for x in f[14:18]]
        i = f.index("plain")
        plain = [float(x) for x in f[i + 1:i + 5]]
        i = f.index("cg", 2)
        cg = [float(x) for x in f[i + 1:i + 5]]
        i = f.index("raw")
        raw = [float(x) for x in f[i + 1:i + 5]]
        out[name] = (check, build, plain, cg, raw)
    return out


def main():
    rust, cg = parse_rust(sys.argv[1]), parse_cg(sys.argv[2])
    names = [n for n in rust if n in cg]
    funcs = [
        ("Inverse dynamics", "ID", "`rnea`", "`CodeGenRNEA`", 3.0),
        ("Mass matrix", "M", "`crba`", "`CodeGenCRBA`", 4.0),
        ("Inverse dynamics derivatives (∂τ/∂q, ∂τ/∂q̇)", "IDD", "`computeRNEADerivatives`",
         "`CodeGenRNEADerivatives`", 1.0),
        ("Forward dynamics derivatives (∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)", "FDD", "`computeABADerivatives`",
         "`CodeGenABADerivatives`", 1.0),
    ]
    for k, (title, key, pname, cname, target) in enumerate(funcs):
        print(f"**{title}**, ns per call (Pinocchio {pname}, CppADCodeGen {cname})\n")
        print("| robot | DOF | generated | generated FMA | FMA + batched `sin_cos` | Pinocchio | CppADCodeGen "
              "| CppADCodeGen raw | CG ÷ generated | CG ÷ generated FMA | CG ÷ batched | raw ÷ batched |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        worst = None
        for n in names:
            dof, _, ns = rust[n]
            g, gf, gb = ns[key]
            _, _, plain, c, raw = cg[n]
            best = min(g, gf, gb)
            print(f"| {n} | {dof} | {g:.0f} | {gf:.0f} | {gb:.0f} | {plain[k]:.0f} | {c[k]:.0f} | {raw[k]:.0f} "
                  f"| {c[k] / g:.1f} | {c[k] / gf:.1f} | {c[k] / gb:.1f} | {raw[k] / gb:.1f} |")
            r = c[k] / best
            if worst is None or r < worst[1]:
                worst = (n, r)
        met = [n for n in names if cg[n][3][k] / min(rust[n][2][key]) >= target]
        goal = f"Target {target:g}×" if target > 1 else "Faster than CppADCodeGen"
        print(f"\n{goal} (CppADCodeGen ÷ the faster generated variant): met on "
              f"{len(met)} of {len(names)} ({', '.join(met) or 'none'}); lowest ratio "
              f"{worst[1]:.2f} ({worst[0]}).\n")
    print("Checks (worst relative error at 5 states, CppADCodeGen vs plain Pinocchio; FMA and batched "
          "variants vs Pinocchio over 200 states) and CppADCodeGen build time (taping + C generation + gcc, s):\n")
    print("| robot | CG ID | CG M | CG ∂RNEA | CG ∂ABA | FMA ID | FMA M | FMA ∂ID | batched ID | batched M "
          "| batched ∂ID | build s (ID, M, ∂ID, ∂FD) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for n in names:
        check, build, *_ = cg[n]
        _, (err, berr), _ = rust[n]
        print(f"| {n} | {check['ID']:.1e} | {check['M']:.1e} | {check['dRNEA']:.1e} | {check['dABA']:.1e} "
              f"| {err['ID']:.1e} | {err['M']:.1e} | {err['dID']:.1e} "
              f"| {berr['ID']:.1e} | {berr['M']:.1e} | {berr['dID']:.1e} | "
              + ", ".join(f"{b:.1f}" for b in build) + " |")


main()
