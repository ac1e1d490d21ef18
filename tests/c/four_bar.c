/* Calls every function of the C interface of four_bar (a closed loop, `codegen SPEC --emit c`)
   and prints the results; tests/tests/c_api.rs compares them with the Rust module. */
#include <math.h>
#include <string.h>

#include "four_bar.h"
#include "report.h"

#define N FOUR_BAR_DOF
#define NX FOUR_BAR_NX

static void report_err(const char *label, int32_t s, const four_bar_error_t *e) {
    failure(label, s, e->index, e->column, e->iterations, e->value, e->condition_estimate);
}

int main(void) {
    const double home[NX] = FOUR_BAR_HOME;
    const double crank[N] = {0.4};
    const double u[N] = {1.5};
    const double ud[N] = {-0.7};
    const double tau[N] = {0.3};
    double x[NX], open[NX], q[N], qd[N], xd[NX], t[N], g[N], c[N], m[N * N], am[N * N], a[N];
    double bad[N * N];
    four_bar_inertia_indices_t ix;
    four_bar_error_t err;
    double d1[N * N], d2[N * N], d3[N * N], d[3 * N * N];
    int32_t s;

    /* Assemble the loop at the crank angle, then evaluate there. */
    input("crank", crank, N);
    input("u", u, N);
    input("ud", ud, N);
    input("tau", tau, N);
    output("forward_kinematics", four_bar_forward_kinematics(crank, home, x, &err), x, NX);
    input("x", x, NX);
    output("inverse_kinematics", four_bar_inverse_kinematics(x, q, &err), q, N);
    output("actuator_rates", four_bar_actuator_rates(x, u, qd, &err), qd, N);
    output("joint_rates", four_bar_joint_rates(x, u, xd, &err), xd, NX);
    output("inverse_dynamics", four_bar_inverse_dynamics(x, u, ud, t, &err), t, N);
    output("mass_matrix", four_bar_mass_matrix(x, m, NULL), m, N * N);
    output("forward_dynamics", four_bar_forward_dynamics(x, u, tau, a, &err), a, N);
    s = four_bar_inverse_dynamics_derivatives(x, u, ud, d1, d2, &err);
    memcpy(d, d1, sizeof d1);
    memcpy(d + N * N, d2, sizeof d2);
    output("inverse_dynamics_derivatives", s, d, 2 * N * N);
    s = four_bar_forward_dynamics_derivatives(x, u, tau, d1, d2, d3, &err);
    memcpy(d, d1, sizeof d1);
    memcpy(d + N * N, d2, sizeof d2);
    memcpy(d + 2 * N * N, d3, sizeof d3);
    output("forward_dynamics_derivatives", s, d, 3 * N * N);
    {
        double y[N * FOUR_BAR_NBP];
        output("regressor", four_bar_regressor(x, u, ud, y, &err), y, N * FOUR_BAR_NBP);
    }
    output("gravity", four_bar_gravity(x, g, &err), g, N);
    output("coriolis", four_bar_coriolis(x, u, c, &err), c, N);
    output("actuator_mass_matrix", four_bar_actuator_mass_matrix(x, am, &err), am, N * N);
    s = four_bar_inertia_indices(am, &ix, &err);
    output("inertia_indices", s, ix.eigenvalues, N);
    printf("indices %.17g %.17g %.17g\n", ix.condition, ix.manipulability, ix.isotropic_acceleration);

    /* Failures: a configuration that does not close the loop, a NaN, NULL pointers. */
    memcpy(open, x, sizeof open);
    open[1] += 0.3;
    input("open", open, NX);
    s = four_bar_forward_dynamics(open, u, tau, a, &err);
    report_err("forward_dynamics_open", s, &err);
    q[0] = NAN;
    s = four_bar_forward_kinematics(q, home, x, &err);
    report_err("forward_kinematics_nan", s, &err);
    bad[0] = NAN;
    s = four_bar_inertia_indices(bad, &ix, &err);
    report_err("inertia_indices_nan", s, &err);
    s = four_bar_joint_rates(open, u, NULL, &err);
    report_err("null_joint_rates", s, &err);
    return 0;
}
