/*
 * A host code's own force law in jprom: NLvib's example 02 (two masses, a cubic spring from
 * q1 to ground and one between the masses; M. Krack, J. Gross, NLvib 1.3), with the coupling
 * cubic spring given twice: once as jprom's polynomial spring, once as a C callback that
 * returns the force and its derivative at each AFT time sample, as a host code would plug in
 * its own contact law. Sweeps the built-in version over NLvib's band (H = 7, 256 samples),
 * solves the host-law version at the sweep's frequencies (each from the previous point), and
 * prints `index omega |X1 q1| built-in |X1 q1| host law`; exits 1 if they differ by more than
 * 1e-8 (the solves' tolerance is 1e-10 on the residual).
 *
 * Build (from the repository root, after `cargo build -p jprom-capi`):
 *   gcc -Wall -Werror -std=c11 -Iinclude examples-c/host_law.c \
 *       -Ltarget/debug -ljprom -Wl,-rpath,$PWD/target/debug -lm -o host_law
 */
#include <math.h>
#include <stdio.h>
#include "jprom.h"

static int check(jprom_status s, const char *what) {
    if (s != JPROM_OK) {
        fprintf(stderr, "%s failed: %s: %s\n", what, jprom_status_name((int)s), jprom_last_error_message());
        return 1;
    }
    return 0;
}

/* The host law: F = k3 w^3 on the relative displacement w = q2 - q1, dF/dw = 3 k3 w^2.
 * Called from the solver's threads: it only reads its arguments. */
static int32_t cubic_law(void *user_data, size_t dim, const double *w, double *force, double *jacobian) {
    const double k3 = *(const double *)user_data;
    if (dim != 1) return 1; /* a nonzero return ends the solve with JPROM_CALLBACK_ERROR */
    force[0] = k3 * w[0] * w[0] * w[0];
    jacobian[0] = 3.0 * k3 * w[0] * w[0];
    return 0;
}

/* NLvib's chain: masses 1 and 0.05, springs 1 (ground-q1) and 0.0453 (q1-q2), dampers 0.002
 * and 0.013, force 0.11 cos(W t) on q1, cubic spring 1 from q1 to ground. */
static jprom_model *nlvib_two_dof(void) {
    const double m[4] = {1.0, 0.0, 0.0, 0.05};
    const double k[4] = {1.0453, -0.0453, -0.0453, 0.0453};
    const double c[4] = {0.015, -0.013, -0.013, 0.013};
    const double f_cos[2] = {0.11, 0.0}, f_sin[2] = {0.0, 0.0}, cubic[3] = {0.0, 0.0, 1.0};
    const size_t outputs[2] = {0, 1};
    jprom_model *model = NULL;
    if (check(jprom_model_new(2, m, k, &model), "jprom_model_new")) return NULL;
    if (check(jprom_model_set_damping_matrix(model, c, 2), "damping")
        || check(jprom_model_set_harmonic_force(model, 1, f_cos, f_sin, 2), "force")
        || check(jprom_model_set_output_dofs(model, outputs, 2), "outputs")
        || check(jprom_model_add_polynomial_spring(model, 0, NULL, cubic, 3), "cubic spring to ground")) {
        jprom_model_free(model);
        return NULL;
    }
    return model;
}

int main(void) {
    static double k3 = 0.0042; /* the coupling spring, read by the callback */
    const size_t q1 = 0, q2 = 1;
    const double coupling[3] = {0.0, 0.0, 0.0042};
    jprom_model *built_in = nlvib_two_dof(), *host = nlvib_two_dof();
    if (!built_in || !host) return 1;
    if (check(jprom_model_add_polynomial_spring(built_in, q2, &q1, coupling, 3), "polynomial coupling")
        || check(jprom_model_add_element_callback(host, 1, &q2, &q1, NULL, cubic_law, &k3), "host-law coupling"))
        return 1;

    jprom_hbm_options opts;
    jprom_sweep_options sweep_opts;
    jprom_hbm_options_default(&opts);
    jprom_sweep_options_default(&sweep_opts);
    opts.harmonics = 7;
    opts.nt = 256;
    sweep_opts.omega_start = 0.8;
    sweep_opts.omega_end = 1.4;

    jprom_sweep_result *sweep = NULL;
    if (check(jprom_sweep(built_in, &opts, &sweep_opts, NULL, NULL, &sweep), "jprom_sweep")) return 1;
    size_t n_points = 0;
    jprom_sweep_end end;
    jprom_sweep_result_n_points(sweep, &n_points);
    jprom_sweep_result_end_reason(sweep, &end);
    printf("# NLvib example 02, H = 7: %zu points, %s\n", n_points, jprom_sweep_end_name((int)end));
    printf("# index omega X1_q1_built_in X1_q1_host_law\n");
    /* the host-law model is solved at each point's frequency from the built-in sweep's
     * previous point (the first from zero): a real Newton solve with the host law, started
     * on the branch, so it follows the branch through its folds (where it lands on another
     * solution of the same frequency, again from the point itself) */
    double worst = 0.0;
    int bad = 0;
    size_t iterations = 0, folds = 0;
    for (size_t i = 0; i < n_points && !bad; ++i) {
        jprom_solution *guess = NULL, *sol = NULL;
        double omega, a, b;
        size_t it = 0;
        bad = (i > 0 && check(jprom_sweep_result_point(sweep, i - 1, &guess), "jprom_sweep_result_point"))
           || check(jprom_sweep_result_point_omega(sweep, i, &omega), "omega")
           || check(jprom_sweep_result_point_amplitude(sweep, i, 1, 0, &a), "amplitude")
           || check(jprom_solve_point_from(host, omega, &opts, guess, &sol), "jprom_solve_point_from")
           || check(jprom_solution_amplitude(sol, 1, 0, &b), "amplitude")
           || check(jprom_solution_convergence(sol, &it, NULL), "convergence");
        if (!bad && fabs(a - b) > 1e-8 * fabs(a)) {
            /* near a fold the frequency has several solutions and Newton from the previous
             * point may land on another one: solve again from the point itself */
            jprom_solution *own = NULL;
            jprom_solution_free(sol);
            sol = NULL;
            bad = check(jprom_sweep_result_point(sweep, i, &own), "jprom_sweep_result_point")
               || check(jprom_solve_point_from(host, omega, &opts, own, &sol), "jprom_solve_point_from")
               || check(jprom_solution_amplitude(sol, 1, 0, &b), "amplitude")
               || check(jprom_solution_convergence(sol, &it, NULL), "convergence");
            jprom_solution_free(own);
        }
        if (!bad) {
            printf("%zu %.10e %.10e %.10e\n", i, omega, a, b);
            iterations += it;
            /* at a fold (the sweep turns back in frequency) two solutions meet and the
             * fixed-frequency problem is singular: Newton may land on either, so folds are
             * not compared */
            double before = 0.0, after = 0.0;
            if (i > 0 && i + 1 < n_points) {
                jprom_sweep_result_point_omega(sweep, i - 1, &before);
                jprom_sweep_result_point_omega(sweep, i + 1, &after);
            }
            if ((omega - before) * (after - omega) < 0.0)
                folds += 1;
            else if (fabs(a - b) > worst * fabs(a))
                worst = fabs(a - b) / fabs(a);
        }
        jprom_solution_free(sol);
        jprom_solution_free(guess);
    }
    printf("# host-law solves: %zu Newton iterations in all\n", iterations);
    printf("# host law vs built-in spring: largest relative difference of |X1| %.2e (%zu fold points not compared)\n", worst, folds);
    jprom_sweep_result_free(sweep);
    jprom_model_free(built_in);
    jprom_model_free(host);
    return bad || worst > 1e-8 || end != JPROM_SWEEP_REACHED_END;
}
