# States and Pinocchio's rnea, crba and aba for every URDF in urdf/ (fixed base, as nocdyn reads
# a URDF), 30 per robot; continuous joints as (cos, sin). Robots with a joint of more than one
# DOF are left out.
import pinocchio as pin, numpy as np, glob, os
rng = np.random.default_rng(11)
for f in sorted(glob.glob("urdf/*.urdf")):
    name = os.path.basename(f)[:-5]
    try:
        m = pin.buildModelFromUrdf(f)
    except Exception as e:
        print("SKIP", name, e); continue
    d = m.createData()
    names = [m.names[i] for i in range(1, m.njoints)]
    if any(m.joints[j].nv != 1 for j in range(1, m.njoints)):
        print("SKIP multi-dof joint", name); continue
    with open(f"data/{name}.txt", "w") as out:
        out.write(" ".join(names) + "\n")
        for _ in range(30):
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
    print(name, m.nq, m.nv)
