/* The C callback element (jprom_model_add_element_callback) from a real C program: a cubic
 * spring written as a C callback gives the solution of jprom_model_add_polynomial_spring with the
 * same coefficients (printed "max rel diff <x>"), and a callback returning 3 ends the solve with
 * JPROM_CALLBACK_ERROR and its message (printed "error <status name>: <message>").
 * Exits 1 on any unexpected status. */
#include <math.h>
#include <stdio.h>
#include "jprom.h"

typedef struct { double k1, k3; } cubic_law;

/* F = k1 w + k3 w^3: reads user_data only, so it is thread-safe. */
static int32_t cubic(void *user_data, size_t dim, const double *w, double *force, double *jacobian) {
    const cubic_law *law = (const cubic_law *)user_data;
    if (dim != 1) return 7;
    force[0] = law->k1 * w[0] + law->k3 * w[0] * w[0] * w[0];
    jacobian[0] = law->k1 + 3.0 * law->k3 * w[0] * w[0];
    return 0;
}

/* Fine at w = 0 (when the element is added), refuses anything else with code 3. */
static int32_t refuses(void *user_data, size_t dim, const double *w, double *force, double *jacobian) {
    (void)user_data;
    (void)dim;
    if (w[0] != 0.0) return 3;
    force[0] = 0.0;
    jacobian[0] = 1.0;
    return 0;
}

static jprom_model *two_dof(void) {
    const double m[4] = {1.0, 0.0, 0.0, 0.5}, k[4] = {1.0, 0.0, 0.0, 0.0}, c[4] = {0.02, 0.0, 0.0, 0.01};
    const double f0[2] = {0.1, -0.05}, f1c[2] = {0.3, 0.1}, f1s[2] = {0.0, 0.0};
    const size_t outs[2] = {0, 1};
    jprom_model *model = NULL;
    if (jprom_model_new(2, m, k, &model) != JPROM_OK || jprom_model_set_damping_matrix(model, c, 2) != JPROM_OK
        || jprom_model_set_static_force(model, f0, 2) != JPROM_OK || jprom_model_set_harmonic_force(model, 1, f1c, f1s, 2) != JPROM_OK
        || jprom_model_set_output_dofs(model, outs, 2) != JPROM_OK) {
        fprintf(stderr, "model: %s\n", jprom_last_error_message());
        return NULL;
    }
    return model;
}

static int solve(jprom_model *model, double omega, double *x, size_t n) {
    jprom_hbm_options opts;
    jprom_hbm_options_default(&opts);
    opts.harmonics = 3;
    jprom_solution *s = NULL;
    jprom_status st = jprom_solve_point(model, omega, &opts, &s);
    if (st != JPROM_OK) return (int)st;
    st = jprom_solution_output_coeffs(s, x, n);
    jprom_solution_free(s);
    return (int)st;
}

int main(void) {
    cubic_law law = {0.8, 0.6};
    const size_t a = 1, b = 0;
    const double coefficients[3] = {0.8, 0.0, 0.6};
    jprom_model *poly = two_dof(), *cb = two_dof(), *bad = two_dof();
    if (!poly || !cb || !bad) return 1;
    if (jprom_model_add_polynomial_spring(poly, a, &b, coefficients, 3) != JPROM_OK
        || jprom_model_add_element_callback(cb, 1, &a, &b, NULL, cubic, &law) != JPROM_OK
        || jprom_model_add_element_callback(bad, 1, &a, &b, NULL, refuses, NULL) != JPROM_OK) {
        fprintf(stderr, "add: %s\n", jprom_last_error_message());
        return 1;
    }
    double worst = 0.0;
    const double omegas[3] = {0.5, 0.9, 1.6};
    for (int i = 0; i < 3; i++) {
        double xp[14], xc[14], num = 0.0, den = 0.0;
        if (solve(poly, omegas[i], xp, 14) != JPROM_OK || solve(cb, omegas[i], xc, 14) != JPROM_OK) {
            fprintf(stderr, "solve: %s\n", jprom_last_error_message());
            return 1;
        }
        for (int j = 0; j < 14; j++) {
            num += (xc[j] - xp[j]) * (xc[j] - xp[j]);
            den += xp[j] * xp[j];
        }
        double d = sqrt(num / den);
        if (d > worst) worst = d;
    }
    printf("max rel diff %.3e\n", worst);
    double x[14];
    int st = solve(bad, 0.9, x, 14);
    printf("error %s: %s\n", jprom_status_name(st), jprom_last_error_message());
    jprom_model_free(poly);
    jprom_model_free(cb);
    jprom_model_free(bad);
    return st == JPROM_CALLBACK_ERROR && worst < 1e-12 ? 0 : 1;
}
