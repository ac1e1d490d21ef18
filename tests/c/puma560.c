/* Calls every function of the C interface of puma560 (`codegen SPEC --emit c`) and prints the
   results; tests/tests/c_api.rs compares them with the Rust module. */
#include <math.h>
#include <string.h>

#include "puma560.h"
#include "report.h"

#define N PUMA560_DOF

int main(void) {
    const double q[N] = {0.1, -0.4, 0.7, 0.2, -0.3, 0.5};
    const double qd[N] = {0.3, 0.1, -0.2, 0.5, -0.4, 0.2};
    const double qdd[N] = {-0.5, 0.2, 0.4, -0.1, 0.3, 0.6};
    const double tau[N] = {1.0, -20.0, 5.0, 0.2, -0.1, 0.05};
    double bad[N];
    double m[N * N], c[N], g[N], t[N], a[N];
    double d1[N * N], d2[N * N], d3[N * N], d[5 * N * N];
    double asym[N * N];
    double y[N * PUMA560_NBP];
    double rot[9], pos[3], jac[6 * N], jdot[6], pose[12];
    puma560_inertia_indices_t ix;
    puma560_error_t err;
    int32_t s;

    input("q", q, N);
    input("qd", qd, N);
    input("qdd", qdd, N);
    input("tau", tau, N);

    output("mass_matrix", puma560_mass_matrix(q, m), m, N * N);
    output("coriolis", puma560_coriolis(q, qd, c), c, N);
    output("gravity", puma560_gravity(q, g), g, N);
    output("inverse_dynamics", puma560_inverse_dynamics(q, qd, qdd, t), t, N);
    output("forward_dynamics", puma560_forward_dynamics(q, qd, tau, a, &err), a, N);
    s = puma560_inverse_dynamics_derivatives(q, qd, qdd, d1, d2);
    memcpy(d, d1, sizeof d1);
    memcpy(d + N * N, d2, sizeof d2);
    output("inverse_dynamics_derivatives", s, d, 2 * N * N);
    s = puma560_forward_dynamics_derivatives(q, qd, tau, d1, d2, d3, NULL);
    memcpy(d, d1, sizeof d1);
    memcpy(d + N * N, d2, sizeof d2);
    memcpy(d + 2 * N * N, d3, sizeof d3);
    output("forward_dynamics_derivatives", s, d, 3 * N * N);
    output("regressor", puma560_regressor(q, qd, qdd, y), y, N * PUMA560_NBP);
    s = puma560_link6_pose(q, rot, pos);
    memcpy(pose, rot, sizeof rot);
    memcpy(pose + 9, pos, sizeof pos);
    output("link6_pose", s, pose, 12);
    output("link6_jacobian", puma560_link6_jacobian(q, jac), jac, 6 * N);
    output("link6_jacobian_dot_qd", puma560_link6_jacobian_dot_qd(q, qd, jdot), jdot, 6);
    s = puma560_inertia_indices(m, &ix, &err);
    output("inertia_indices", s, ix.eigenvalues, N);
    printf("indices %.17g %.17g %.17g\n", ix.condition, ix.manipulability, ix.isotropic_acceleration);

    /* An output may alias an input: the inputs are read first. */
    memcpy(a, q, sizeof a);
    output("gravity_in_place", puma560_gravity(a, a), a, N);

    /* Failures: a NaN position (its pivot fails), an infinite effort, a matrix that is not symmetric, NULL pointers. */
    memcpy(bad, q, sizeof bad);
    bad[2] = NAN;
    s = puma560_forward_dynamics(bad, qd, tau, a, &err);
    failure("forward_dynamics_nan", s, err.index, err.column, err.iterations, err.value,
            err.condition_estimate);
    memcpy(bad, tau, sizeof bad);
    bad[4] = INFINITY;
    s = puma560_forward_dynamics(q, qd, bad, a, &err);
    failure("forward_dynamics_inf_tau", s, err.index, err.column, err.iterations, err.value,
            err.condition_estimate);
    memcpy(asym, m, sizeof asym);
    asym[1 * N + 4] += 1.0;
    s = puma560_inertia_indices(asym, &ix, &err);
    failure("inertia_indices_asymmetric", s, err.index, err.column, err.iterations, err.value,
            err.condition_estimate);
    s = puma560_mass_matrix(NULL, m);
    failure("null_mass_matrix", s, -1, -1, 0, 0.0, 0.0);
    s = puma560_forward_dynamics(q, qd, tau, NULL, &err);
    failure("null_forward_dynamics", s, err.index, err.column, err.iterations, err.value,
            err.condition_estimate);
    return 0;
}
