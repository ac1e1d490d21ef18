#!/usr/bin/env python3
"""Bytes of machine code per generated function, for firmware flash budgets.

Builds `tests/no-panic` (one `#[inline(never)]` wrapper per generated function of every bundled
mechanism: a generic function per method of `runtime::Dynamics`, one instance per module,
`tests_no_panic::<function>::<mechanisms::<module>::Module, NX, DOF>` in v0 symbol mangling,
which this script turns on so that the instances have distinct names) with the workspace's `firmware` profile (fat
LTO, one codegen unit, `panic = "abort"`) at each optimization level, disassembles it and, for
every wrapper, adds up the sizes of all functions reachable from it through direct calls and
jumps. Shared helpers (LU, kinematics kernels) count in every function that calls them; the
"all functions" row of a mechanism counts each one once. The math routines (`libm`: sin, cos,
sqrt, ...) are shared by every mechanism and reported once, separately.

    python3 tools/code_size.py [--out docs/code-size.md] [--levels s,3] [--target-dir DIR]

Needs cargo, `nm` and `objdump` (binutils). Exits non-zero if a wrapper is missing. A function
that can reach the panic machinery (`core::panicking`) is marked in the table, with the call
site; the machinery itself is not counted. (The `#[no_panic]` proof, `tests/no-panic`, covers the
default `opt-level = 3`.)
"""

import argparse
import bisect
import collections
import datetime
import os
import platform
import re
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CRATE = "tests_no_panic"
MATH = re.compile(r"^(libm::|runtime::math::|compiler_builtins::)")
PANIC = re.compile(r"core::panicking|core::result::unwrap_failed|core::option::expect_failed")


def build(level, target_dir):
    cmd = [
        "cargo", "build", "--locked", "-p", "tests-no-panic", "--profile", "firmware",
        "--config", (f'profile.firmware.opt-level="{level}"' if level in ("s", "z")
                      else f"profile.firmware.opt-level={level}"),
        "--config", 'profile.firmware.panic="abort"',
        # v0 mangling names each instance of a generic wrapper with its module.
        "--config", 'build.rustflags=["-Csymbol-mangling-version=v0"]',
    ]
    env = dict(os.environ, CARGO_TARGET_DIR=target_dir)
    start = time.monotonic()
    subprocess.run(cmd, cwd=ROOT, env=env, check=True)
    took = time.monotonic() - start
    binary = os.path.join(target_dir, "firmware", "tests-no-panic")
    kept = binary + f".opt-{level}"
    shutil.copyfile(binary, kept)
    return kept, took


def symbols(binary):
    """Function symbols: sorted starts, and {start: (name, size)}."""
    out = subprocess.run(["nm", "-S", "-C", "--defined-only", binary], capture_output=True,
                         text=True, check=True).stdout
    funcs = {}
    for line in out.splitlines():
        parts = line.split(None, 3)
        if len(parts) != 4 or parts[2] not in "tTwW":
            continue
        start, size, name = int(parts[0], 16), int(parts[1], 16), parts[3]
        if size and (start not in funcs or funcs[start][1] < size):
            funcs[start] = (name, size)
    return sorted(funcs), funcs


def call_graph(binary, starts, funcs):
    """{caller start: set of callee starts} from direct call/jmp targets in the disassembly."""
    edges = collections.defaultdict(set)
    dis = subprocess.Popen(["objdump", "-d", "--no-show-raw-insn", binary],
                           stdout=subprocess.PIPE, text=True)
    target = re.compile(r"\s(?:call|jmp|j[a-z]{1,3})q?\s+([0-9a-f]+) <")
    for line in dis.stdout:
        m = target.search(line)
        if m is None:
            continue
        addr = int(line.split(":", 1)[0].strip(), 16)
        i = bisect.bisect_right(starts, addr) - 1
        if i < 0:
            continue
        caller = starts[i]
        if addr >= caller + funcs[caller][1]:
            continue
        t = int(m.group(1), 16)
        j = bisect.bisect_right(starts, t) - 1
        if j >= 0 and starts[j] != caller and t < starts[j] + funcs[starts[j]][1]:
            edges[caller].add(starts[j])
    dis.wait()
    return edges


def reach(root, edges, funcs):
    """Functions reachable from `root`, not entering the panic machinery; and the panic call
    sites met on the way, as (caller, panic function) names."""
    seen, todo, sites = {root}, [root], set()
    while todo:
        f = todo.pop()
        for c in edges.get(f, ()):
            if PANIC.search(funcs[c][0]):
                sites.add((funcs[f][0], funcs[c][0]))
            elif c not in seen:
                seen.add(c)
                todo.append(c)
    return seen, sites


def measure(binary):
    starts, funcs = symbols(binary)
    edges = call_graph(binary, starts, funcs)
    # `tests_no_panic::<function>::<mechanisms::<module>::Module, NX, DOF>` (v0 demangled;
    # crate disambiguators, if shown, skipped).
    wrapper = re.compile(rf"^{CRATE}(?:\[\w+\])?::(\w+)::<mechanisms(?:\[\w+\])?::"
                         r"(?:f32::)?(\w+)::Module, [^>]*>$")
    sizes, per_mech, math, panics = {}, collections.defaultdict(set), set(), {}
    for s in starts:
        name = funcs[s][0]
        m = wrapper.match(name)
        if not m or m.group(1) == "run":
            continue
        own = 0
        seen, sites = reach(s, edges, funcs)
        for f in seen:
            fname, size = funcs[f]
            if MATH.match(fname):
                math.add(f)
            else:
                own += size
                per_mech[m.group(2)].add(f)
        key = (m.group(2), m.group(1))
        sizes[key] = own
        if sites:
            panics[key] = sorted(sites)
    totals = {k: sum(funcs[f][1] for f in v) for k, v in per_mech.items()}
    math_bytes = sum(funcs[f][1] for f in math)
    math_names = sorted({funcs[f][0] for f in math})
    return sizes, totals, math_bytes, math_names, panics


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "code-size.md"))
    ap.add_argument("--levels", default="s,3")
    ap.add_argument("--target-dir", default=os.environ.get(
        "CARGO_TARGET_DIR", os.path.join(ROOT, "target")))
    args = ap.parse_args()
    levels = args.levels.split(",")
    results, took = {}, {}
    for level in levels:
        binary, took[level] = build(level, args.target_dir)
        results[level] = measure(binary)
    ok = True
    keys = sorted(set().union(*(r[0].keys() for r in results.values())))
    for level, (sizes, _, _, _, panics) in results.items():
        missing = [k for k in keys if k not in sizes]
        if missing:
            print(f"opt-level {level}: wrappers missing: {missing}", file=sys.stderr)
            ok = False
        for key, sites in panics.items():
            for caller, callee in sites:
                print(f"opt-level {level}: {key[0]}::{key[1]} can panic: {caller} calls "
                      f"{callee}", file=sys.stderr)
    mechs = sorted({m for m, _ in keys})
    rustc = subprocess.run(["rustc", "--version"], capture_output=True, text=True).stdout.strip()
    head = " | ".join(f'opt-level "{lv}"' if lv in ("s", "z") else f"opt-level {lv}" for lv in levels)
    lines = [
        "# Code size of the generated functions",
        "",
        "Bytes of machine code per generated function: everything reachable from the function "
        "through direct calls (shared helpers such as the LU or the kinematics kernels count in "
        "every function that uses them), without the math routines, which every mechanism "
        "shares (listed below the table). The `all` row of a mechanism counts each machine-code "
        "function once: it is what linking every function of that mechanism costs.",
        "",
        f"Generated by `python3 tools/code_size.py` on {datetime.date.today().isoformat()}: "
        f"{rustc}, target {platform.machine()}-linux, the workspace's `firmware` profile "
        "(fat LTO, `codegen-units = 1`) with `panic = \"abort\"`, `f64`, math from the `libm` "
        "crate. Sizes on a Cortex-M (Thumb-2) differ; the ratios between functions carry over.",
        "",
        f"| mechanism | function | {head} |",
        "|---|---|" + "---:|" * len(levels),
    ]
    for mech in mechs:
        fns = [f for m, f in keys if m == mech]
        for f in fns:
            cells = " | ".join(
                f"{results[lv][0].get((mech, f), 0):,}" + (" †" if (mech, f) in results[lv][4]
                                                         else "")
                for lv in levels)
            lines.append(f"| `{mech}` | `{f}` | {cells} |")
        cells = " | ".join(f"**{results[lv][1].get(mech, 0):,}**" for lv in levels)
        lines.append(f"| `{mech}` | all | {cells} |")
    lines.append("")
    for lv in levels:
        _, _, mb, names, _ = results[lv]
        short = sorted({re.sub(r"^(libm::|runtime::)(.*::)?", "", n) for n in names})
        lines.append(f"Math routines at opt-level {lv}: {mb:,} bytes ({', '.join(short)}).")
        lines.append("")
    for lv in levels:
        panics = results[lv][4]
        if not panics:
            lines.append(f"No function reaches a panic at opt-level {lv}.")
            lines.append("")
            continue
        sites = sorted({site for v in panics.values() for site in v})
        lines.append(f"† Can reach a panic at opt-level {lv} (the panic machinery is not "
                     "counted in the size): " + "; ".join(
                         f"`{caller}` calls `{callee}`" for caller, callee in sites) + ".")
        lines.append("")
    lines.append("Build times (2 cores, incremental on an existing target directory): "
                 + ", ".join(f"opt-level {lv} {took[lv]:.0f} s" for lv in levels) + ".")
    text = "\n".join(lines) + "\n"
    with open(args.out, "w") as fh:
        fh.write(text)
    print(text)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
