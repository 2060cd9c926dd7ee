/*
 * jprom from C: a two-node, six-DoF structure with one 3D friction contact pressing node 1
 * against ground, excited along x at node 0. Sweeps the first mode from stick towards slip
 * and prints `index omega |X1| at node 0 x, |X1| at node 1 x` per converged point; then the
 * Jacobian Projection workflow on the same model: a predicted basis, and the self-correcting
 * NLR sweep, printing `index omega |X1| node 0 x, |X1| node 1 x, e*_1` per point.
 *
 * Build (from the repository root, after `cargo build --lib`):
 *   gcc -Wall -Werror -std=c11 -Iinclude examples-c/sweep_example.c \
 *       -Ltarget/debug -ljprom -Wl,-rpath,$PWD/target/debug -lm -o sweep_example
 */
#include <stdio.h>
#include <stdlib.h>
#include "jprom.h"

#define N 6 /* DoFs: node 0 (x, y, z) then node 1 (x, y, z) */

static int check(jprom_status s, const char *what) {
    if (s != JPROM_OK) {
        fprintf(stderr, "%s failed: %s: %s\n", what, jprom_status_name((int)s), jprom_last_error_message());
        return 1;
    }
    return 0;
}

/* Progress callback: counts points; returning nonzero would stop the sweep. */
static int on_point(void *user_data, size_t index, double omega, const double *amps, size_t n_outputs) {
    (void)index;
    (void)omega;
    (void)amps;
    (void)n_outputs;
    *(size_t *)user_data += 1;
    return 0;
}

int main(void) {
    /* column-major M and K: springs 1e4 from ground to node 0 and from node 0 to node 1 */
    double mass[N * N] = {0}, stiffness[N * N] = {0};
    for (int d = 0; d < 3; ++d) {
        int a = d, b = 3 + d;
        mass[a + a * N] = 1.0;
        mass[b + b * N] = 1.0;
        stiffness[a + a * N] = 2.0e4;
        stiffness[b + b * N] = 1.0e4;
        stiffness[a + b * N] = -1.0e4;
        stiffness[b + a * N] = -1.0e4;
    }
    jprom_model *model = NULL;
    if (check(jprom_model_new(N, mass, stiffness, &model), "jprom_model_new")) return 1;

    const size_t node1[3] = {3, 4, 5};
    const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}; /* rows t1, t2, n */
    double f1_cos[N] = {5.0, 0, 0, 0, 0, 0}, f1_sin[N] = {0};
    const size_t outputs[2] = {0, 3};
    int bad = check(jprom_model_add_contact_3d(model, node1, NULL, frame, 3.0e4, 3.0e4, 5.0e4, 0.5, 20.0), "add contact")
           || check(jprom_model_set_rayleigh_damping(model, 0.0, 1.0e-4), "damping")
           || check(jprom_model_set_harmonic_force(model, 1, f1_cos, f1_sin, N), "harmonic force")
           || check(jprom_model_set_output_dofs(model, outputs, 2), "outputs");
    if (bad) {
        jprom_model_free(model);
        return 1;
    }

    jprom_hbm_options opts;
    jprom_sweep_options sweep_opts;
    jprom_hbm_options_default(&opts);
    jprom_sweep_options_default(&sweep_opts);
    opts.harmonics = 3;
    sweep_opts.omega_start = 60.0;
    sweep_opts.omega_end = 160.0;

    size_t seen = 0;
    jprom_sweep_result *sweep = NULL;
    if (check(jprom_sweep(model, &opts, &sweep_opts, on_point, &seen, &sweep), "jprom_sweep")) {
        jprom_model_free(model);
        return 1;
    }
    size_t n_points = 0;
    jprom_sweep_result_n_points(sweep, &n_points);
    printf("# jprom %s, %zu points (%zu reported by the callback)\n", jprom_version(), n_points, seen);
    printf("# index omega_rad_s X1_node0_x X1_node1_x\n");
    for (size_t i = 0; i < n_points; ++i) {
        double omega, a0, a1;
        if (check(jprom_sweep_result_point_omega(sweep, i, &omega), "omega")
            || check(jprom_sweep_result_point_amplitude(sweep, i, 1, 0, &a0), "amplitude")
            || check(jprom_sweep_result_point_amplitude(sweep, i, 1, 1, &a1), "amplitude")) {
            bad = 1;
            break;
        }
        printf("%zu %.10e %.10e %.10e\n", i, omega, a0, a1);
    }
    jprom_sweep_result_free(sweep);
    if (bad) {
        jprom_model_free(model);
        return bad;
    }

    /* Jacobian Projection: a basis predicted along the stuck mode (no full-order solution
     * needed), then the self-correcting reduced sweep, jprom's default JP workflow: it sweeps
     * the NLR model, evaluates the error predictor e*_1 at every point, and corrects the basis
     * while the worst e*_1 exceeds jp_opts.threshold (0.05). */
    jprom_jp_options jp_opts;
    jprom_jp_options_default(&jp_opts);
    jprom_basis *basis = NULL;
    size_t sizes[8], harmonics = 0;
    if (check(jprom_basis_predict_opts(model, &opts, &jp_opts, sweep_opts.omega_start, sweep_opts.omega_end, &basis), "jprom_basis_predict_opts")
        || check(jprom_basis_sizes(basis, sizes, 8, &harmonics), "jprom_basis_sizes")) {
        jprom_basis_free(basis);
        jprom_model_free(model);
        return 1;
    }
    printf("# JP: predicted basis sizes n_h, h = 0..%zu:", harmonics);
    for (size_t h = 0; h <= harmonics; ++h) printf(" %zu", sizes[h]);
    printf("\n");
    jprom_basis_free(basis);

    jprom_sweep_result *rom = NULL;
    jprom_basis *final_basis = NULL;
    seen = 0;
    if (check(jprom_rom_sweep_adaptive(model, JPROM_ROM_NLR, &opts, &sweep_opts, &jp_opts, on_point, &seen, &rom, &final_basis),
              "jprom_rom_sweep_adaptive")) {
        jprom_model_free(model);
        return 1;
    }
    size_t n_corrections = 0;
    jprom_sweep_result_n_points(rom, &n_points);
    jprom_sweep_result_n_corrections(rom, &n_corrections);
    jprom_basis_sizes(final_basis, sizes, 8, &harmonics);
    printf("# JP: self-correcting NLR sweep, %zu points, %zu corrections, final n_1 = %zu\n", n_points, n_corrections, sizes[1]);
    /* why the corrections ended: above the threshold the basis stayed poor (the sweep's own end
     * reason only says whether the last pass covered the band) */
    jprom_correction_end corrections_end = JPROM_CORRECTIONS_WITHIN_THRESHOLD;
    double judged = 0.0;
    if (check(jprom_sweep_result_correction_end(rom, &corrections_end, &judged), "jprom_sweep_result_correction_end")) bad = 1;
    printf("# JP: corrections ended: %s, judged error %.3g (threshold %g)\n", jprom_correction_end_name((int)corrections_end), judged,
           jp_opts.threshold);
    /* whether the result can be trusted: the last pass covered the band and every point's judged
     * error is within the threshold (docs/formulation.md §10.7); if not, its peak is not the
     * reduced model's resonance */
    int trusted = 0;
    char why[1024] = "";
    size_t why_len = 0;
    if (check(jprom_sweep_result_trusted(rom, &trusted), "jprom_sweep_result_trusted")
        || check(jprom_sweep_result_trust_reason_copy(rom, why, sizeof why, &why_len), "jprom_sweep_result_trust_reason_copy"))
        bad = 1;
    printf("# JP: trusted: %s%s%s\n", trusted ? "yes" : "no", trusted ? "" : ": ", why);
    /* the static term's error, reported but not judged (docs/formulation.md §10.6) */
    double w0_error = 0.0;
    if (jprom_sweep_result_static_error(rom, &w0_error) == JPROM_OK)
        printf("# JP: static contact displacement error %.6e\n", w0_error);
    printf("# index omega_rad_s X1_node0_x X1_node1_x e_star_1\n");
    for (size_t i = 0; i < n_points; ++i) {
        double omega, a0, a1, e1;
        if (check(jprom_sweep_result_point_omega(rom, i, &omega), "omega")
            || check(jprom_sweep_result_point_amplitude(rom, i, 1, 0, &a0), "amplitude")
            || check(jprom_sweep_result_point_amplitude(rom, i, 1, 1, &a1), "amplitude")
            || check(jprom_sweep_result_point_predicted_error(rom, i, 1, &e1), "predicted error")) {
            bad = 1;
            break;
        }
        printf("%zu %.10e %.10e %.10e %.10e\n", i, omega, a0, a1, e1);
    }
    jprom_sweep_result_free(rom);
    jprom_basis_free(final_basis);
    jprom_model_free(model);
    return bad;
}
