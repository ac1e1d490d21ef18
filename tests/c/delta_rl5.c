/* Calls every function of the C interface of delta_rl5 (a parallel platform, `codegen SPEC
   --emit c`) and prints the results; tests/tests/c_api.rs compares them with the Rust module. */
#include <math.h>
#include <string.h>

#include "delta_rl5.h"
#include "report.h"

#define N DELTA_RL5_DOF
#define NX DELTA_RL5_NX

static void report_err(const char *label, int32_t s, const delta_rl5_error_t *e) {
    failure(label, s, e->index, e->column, e->iterations, e->value, e->condition_estimate);
}

int main(void) {
    const double home[NX] = DELTA_RL5_HOME;
    const double x[NX] = {0.05, -0.03, -0.95};
    const double u[N] = {0.2, -0.1, 0.3};
    const double ud[N] = {-0.4, 0.5, 0.1};
    const double tau[N] = {2.0, -1.0, 0.5};
    const double far[NX] = {0.0, 0.0, -10.0};
    double q[N], qd[N], t[N], g[N], c[N], m[N * N], am[N * N], a[N], fk[NX];
    double asym[N * N];
    delta_rl5_inertia_indices_t ix;
    delta_rl5_error_t err;
    double d1[N * N], d2[N * N], d3[N * N], d[3 * N * N];
    int32_t s;

    input("x", x, NX);
    input("u", u, N);
    input("ud", ud, N);
    input("tau", tau, N);

    output("inverse_kinematics", delta_rl5_inverse_kinematics(x, q, &err), q, N);
    output("actuator_rates", delta_rl5_actuator_rates(x, u, qd, &err), qd, N);
    output("inverse_dynamics", delta_rl5_inverse_dynamics(x, u, ud, t, &err), t, N);
    output("gravity", delta_rl5_gravity(x, g, &err), g, N);
    output("coriolis", delta_rl5_coriolis(x, u, c, NULL), c, N);
    output("mass_matrix", delta_rl5_mass_matrix(x, m, &err), m, N * N);
    output("actuator_mass_matrix", delta_rl5_actuator_mass_matrix(x, am, &err), am, N * N);
    output("forward_dynamics", delta_rl5_forward_dynamics(x, u, tau, a, &err), a, N);
    s = delta_rl5_inverse_dynamics_derivatives(x, u, ud, d1, d2, &err);
    memcpy(d, d1, sizeof d1);
    memcpy(d + N * N, d2, sizeof d2);
    output("inverse_dynamics_derivatives", s, d, 2 * N * N);
    s = delta_rl5_forward_dynamics_derivatives(x, u, tau, d1, d2, d3, &err);
    memcpy(d, d1, sizeof d1);
    memcpy(d + N * N, d2, sizeof d2);
    memcpy(d + 2 * N * N, d3, sizeof d3);
    output("forward_dynamics_derivatives", s, d, 3 * N * N);
    {
        double y[N * DELTA_RL5_NBP];
        output("regressor", delta_rl5_regressor(x, u, ud, y, &err), y, N * DELTA_RL5_NBP);
    }
    /* Forward kinematics from home back to x. */
    output("forward_kinematics", delta_rl5_forward_kinematics(q, home, fk, &err), fk, NX);
    s = delta_rl5_inertia_indices(am, &ix, &err);
    output("inertia_indices", s, ix.eigenvalues, N);
    printf("indices %.17g %.17g %.17g\n", ix.condition, ix.manipulability, ix.isotropic_acceleration);

    /* Failures: out of reach, no convergence, a matrix that is not symmetric, NULL pointers. */
    s = delta_rl5_inverse_dynamics(far, u, ud, t, &err);
    report_err("inverse_dynamics_far", s, &err);
    q[0] = NAN;
    s = delta_rl5_forward_kinematics(q, home, fk, &err);
    report_err("forward_kinematics_nan", s, &err);
    memcpy(asym, am, sizeof asym);
    asym[0 * N + 2] += 1.0;
    s = delta_rl5_inertia_indices(asym, &ix, &err);
    report_err("inertia_indices_asymmetric", s, &err);
    s = delta_rl5_gravity(NULL, g, &err);
    report_err("null_gravity", s, &err);
    s = delta_rl5_forward_kinematics(q, NULL, fk, NULL);
    failure("null_forward_kinematics", s, -1, -1, 0, 0.0, 0.0);
    return 0;
}
