# States and Pinocchio's rnea, crba and aba (and derivatives) for every URDF in urdf/, into
# data/ (fixed base, as nocdyn reads a URDF). Usage: gen.py [STATES [--values-only]]: STATES
# per robot (200), `--values-only` without the derivatives' files (sweep/run.sh). A robot
# Pinocchio cannot read, or with a joint of more than one DOF, is left out with a line.
import pinocchio as pin, numpy as np, glob, os, sys
states = int(sys.argv[1]) if len(sys.argv) > 1 else 200
values_only = "--values-only" in sys.argv[2:]
rng = np.random.default_rng(7)
for f in sorted(glob.glob("urdf/*.urdf")):
    name = os.path.basename(f)[:-5]
    try:
        m = pin.buildModelFromUrdf(f)
    except Exception as e:
        print("SKIP", name, e); continue
    if any(m.joints[j].nv != 1 for j in range(1, m.njoints)):
        print("SKIP", name, "(a joint of more than one DOF)"); continue
    d = m.createData()
    names = [m.names[i] for i in range(1, m.njoints)]
    # Derivatives for the robots with <= 16 DOF (the others' modules leave them out: scenes/):
    # the state, Pinocchio's computeRNEADerivatives (dtau_dq, dtau_dv) at (q, v, a) and
    # computeABADerivatives (ddq_dq, ddq_dv, Minv) at (q, v, t2), row-major; derivatives in q are
    # w.r.t. the tangent (a continuous joint's angle), as nocdyn's.
    der = open(f"data/{name}.deriv.txt", "w") if m.nv <= 16 and not values_only else None
    if der:
        der.write(" ".join(names) + "\n")
    with open(f"data/{name}.txt", "w") as out:
        out.write(" ".join(names) + "\n")
        for _ in range(states):
            th = rng.uniform(-1.5, 1.5, m.nv)
            q = np.zeros(m.nq)
            for j in range(1, m.njoints):
                jt = m.joints[j]
                if jt.nq == 2:
                    q[jt.idx_q] = np.cos(th[jt.idx_v]); q[jt.idx_q+1] = np.sin(th[jt.idx_v])
                else:
                    q[jt.idx_q] = th[jt.idx_v]
            v = rng.uniform(-2, 2, m.nv)
            a = rng.uniform(-3, 3, m.nv)
            tau = pin.rnea(m, d, q, v, a)
            M = pin.crba(m, d, q); M = np.triu(M) + np.triu(M, 1).T
            t2 = rng.uniform(-10, 10, m.nv)
            fd = pin.aba(m, d, q, v, t2)
            vals = np.concatenate([th, v, a, tau, M.ravel(), t2, fd])
            out.write(" ".join(repr(float(x)) for x in vals) + "\n")
            if der:
                dq, dv, _ = pin.computeRNEADerivatives(m, d, q, v, a)
                dq, dv = np.array(dq), np.array(dv)
                fq, fv, mi = pin.computeABADerivatives(m, d, q, v, t2)
                fq, fv, mi = np.array(fq), np.array(fv), np.array(mi)
                mi = np.triu(mi) + np.triu(mi, 1).T  # Pinocchio fills Minv's upper triangle
                dvals = np.concatenate([th, v, a, t2, dq.ravel(), dv.ravel(), fq.ravel(), fv.ravel(), mi.ravel()])
                der.write(" ".join(repr(float(x)) for x in dvals) + "\n")
    if der:
        der.close()
    print(name, m.nq, m.nv)
