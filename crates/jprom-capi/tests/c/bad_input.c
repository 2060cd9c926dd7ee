/* Bad input through the C API: every call returns its documented status with a readable
 * message, and nothing crashes. Prints "ok <what>: <STATUS>: <message>" per check and
 * "all checks passed" at the end; exits 1 on the first unexpected status. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "jprom.h"

static int failures = 0;

static void expect(jprom_status got, jprom_status want, const char *what) {
    const char *msg = jprom_last_error_message();
    if (got != want) {
        printf("FAIL %s: got %s, expected %s (%s)\n", what, jprom_status_name((int)got), jprom_status_name((int)want), msg);
        failures++;
    } else if (want != JPROM_OK && strlen(msg) < 10) {
        printf("FAIL %s: message too short: '%s'\n", what, msg);
        failures++;
    } else {
        printf("ok %s: %s: %s\n", what, jprom_status_name((int)got), msg);
    }
}

static int stop_at_third(void *user, size_t index, double omega, const double *amps, size_t n) {
    (void)user; (void)omega; (void)amps; (void)n;
    return index >= 2;
}

int main(void) {
    enum { N = 3 };
    double m[N * N] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double k[N * N] = {2e4, -1e4, 0, -1e4, 2e4, -1e4, 0, -1e4, 1e4};
    jprom_model *model = NULL;

    expect(jprom_model_new(N, NULL, k, &model), JPROM_NULL_ARGUMENT, "NULL mass");
    expect(jprom_model_new(N, m, k, NULL), JPROM_NULL_ARGUMENT, "NULL out");
    double knan[N * N];
    memcpy(knan, k, sizeof k);
    knan[4] = NAN;
    expect(jprom_model_new(N, m, knan, &model), JPROM_INVALID_VALUE, "NaN in K");
    double kasym[N * N];
    memcpy(kasym, k, sizeof k);
    kasym[1] = 5.0;
    expect(jprom_model_new(N, m, kasym, &model), JPROM_INVALID_VALUE, "non-symmetric K");
    if (model != NULL) { printf("FAIL out written on failure\n"); failures++; }

    expect(jprom_model_new(N, m, k, &model), JPROM_OK, "valid model");
    double f_short[2] = {1, 2};
    expect(jprom_model_set_static_force(model, f_short, 2), JPROM_BAD_SIZE, "static force of wrong size");
    const size_t dofs[3] = {0, 1, 2};
    const size_t dofs_out[3] = {0, 1, 7};
    const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    expect(jprom_model_add_contact_3d(model, dofs, NULL, frame, 1e3, 1e3, 1e3, -0.1, 10.0), JPROM_INVALID_VALUE, "negative mu");
    expect(jprom_model_add_contact_3d(model, dofs, NULL, frame, -1e3, 1e3, 1e3, 0.3, 10.0), JPROM_INVALID_VALUE, "negative kt1");
    expect(jprom_model_add_contact_3d(model, dofs_out, NULL, frame, 1e3, 1e3, 1e3, 0.3, 10.0), JPROM_INVALID_VALUE, "DoF out of range");
    size_t nc = 99;
    jprom_model_n_contacts(model, &nc);
    if (nc != 0) { printf("FAIL a rejected contact was kept (%zu)\n", nc); failures++; }

    /* singular K without contact: the free-free static problem has no solution */
    double k_free[N * N] = {1e4, -1e4, 0, -1e4, 2e4, -1e4, 0, -1e4, 1e4};
    jprom_model *free_model = NULL;
    expect(jprom_model_new(N, m, k_free, &free_model), JPROM_OK, "free-free model");
    jprom_hbm_options opts;
    jprom_hbm_options_default(&opts);
    opts.condensed = 0;
    jprom_solution *sol = NULL;
    expect(jprom_solve_point(free_model, 50.0, &opts, &sol), JPROM_SINGULAR_MATRIX, "singular K, no contact");
    jprom_model_free(free_model);

    /* a friction case that cannot converge in one Newton iteration */
    double f1[N] = {0, 0, 50.0}, f0[N] = {0};
    expect(jprom_model_add_contact_3d(model, dofs, NULL, frame, 3e4, 3e4, 3e4, 0.3, 10.0), JPROM_OK, "valid contact");
    expect(jprom_model_set_harmonic_force(model, 1, f1, f0, N), JPROM_OK, "harmonic force");
    jprom_hbm_options_default(&opts);
    opts.max_iterations = 1;
    expect(jprom_solve_point(model, 120.0, &opts, &sol), JPROM_NO_CONVERGENCE, "max_iterations = 1");
    expect(jprom_solve_point(model, NAN, &opts, &sol), JPROM_INVALID_VALUE, "NaN frequency");
    jprom_hbm_options_default(&opts);
    opts.struct_size = 3;
    expect(jprom_solve_point(model, 120.0, &opts, &sol), JPROM_BAD_SIZE, "options not from jprom_hbm_options_default");

    /* a callback that stops the sweep: CANCELLED, and the points so far are handed out */
    jprom_hbm_options_default(&opts);
    jprom_sweep_options sopts;
    jprom_sweep_options_default(&sopts);
    sopts.omega_start = 50.0;
    sopts.omega_end = 200.0;
    jprom_sweep_result *sweep = NULL;
    expect(jprom_model_set_output_dofs(model, dofs, 3), JPROM_OK, "output DoFs");
    expect(jprom_sweep(model, &opts, &sopts, stop_at_third, NULL, &sweep), JPROM_OK, "callback stops the sweep");
    jprom_sweep_end reason = JPROM_SWEEP_REACHED_END;
    expect(jprom_sweep_result_end_reason(sweep, &reason), JPROM_OK, "end reason of a cancelled sweep");
    if (reason != JPROM_SWEEP_CANCELLED) { printf("FAIL cancelled sweep's end reason %d\n", (int)reason); failures++; }
    size_t np = 0;
    expect(jprom_sweep_result_n_points(sweep, &np), JPROM_OK, "points of a cancelled sweep");
    if (np != 3) { printf("FAIL cancelled sweep kept %zu points, expected 3\n", np); failures++; }
    double om;
    expect(jprom_sweep_result_point_omega(sweep, 10, &om), JPROM_INVALID_VALUE, "point index out of range");
    /* per-point coefficients: size-checked copy, consistent with the amplitude accessor */
    size_t nout = 0;
    jprom_model_n_outputs(model, &nout);
    size_t ncoef = (2 * opts.harmonics + 1) * nout;
    double coeffs[64];
    if (nout == 0 || ncoef > 64) { printf("FAIL unexpected output count %zu\n", nout); failures++; }
    else {
        expect(jprom_sweep_result_point_output_coeffs(sweep, 1, coeffs, ncoef - 1), JPROM_BAD_SIZE, "coefficient buffer too small");
        expect(jprom_sweep_result_point_output_coeffs(sweep, 1, NULL, ncoef), JPROM_NULL_ARGUMENT, "NULL coefficient buffer");
        expect(jprom_sweep_result_point_output_coeffs(sweep, 10, coeffs, ncoef), JPROM_INVALID_VALUE, "coefficients of a point out of range");
        expect(jprom_sweep_result_point_output_coeffs(sweep, 1, coeffs, ncoef), JPROM_OK, "coefficients of point 1");
        double a = 0.0, c = coeffs[1 * nout + nout - 1], sn = coeffs[2 * nout + nout - 1];
        jprom_sweep_result_point_amplitude(sweep, 1, 1, nout - 1, &a);
        if (fabs(a - sqrt(c * c + sn * sn)) > 1e-12 * a || a <= 0.0) { printf("FAIL amplitude %g vs coefficients %g %g\n", a, c, sn); failures++; }
        size_t iters = 0;
        double res = -1.0, energy[1] = {-1.0};
        expect(jprom_sweep_result_point_convergence(sweep, 1, &iters, &res), JPROM_OK, "convergence of point 1");
        if (!(res >= 0.0 && res < 1e-6)) { printf("FAIL residual %g\n", res); failures++; }
        expect(jprom_sweep_result_point_dissipated_energy(sweep, 1, energy, 1), JPROM_OK, "dissipated energy of point 1");
        if (!(energy[0] >= 0.0)) { printf("FAIL dissipated energy %g\n", energy[0]); failures++; }
        expect(jprom_sweep_result_point_dissipated_energy(sweep, 1, energy, 0), JPROM_BAD_SIZE, "energy buffer too small");
    }
    jprom_sweep_result_free(sweep);

    /* the JP workflow: options, self-correcting sweep, basis from a solution, actual error, on
     * the examples' model (node 0 on springs, node 1 against ground by a friction contact) */
    enum { NJ = 6 };
    double mj[NJ * NJ] = {0}, kj[NJ * NJ] = {0}, fj_cos[NJ] = {5.0, 0, 0, 0, 0, 0}, fj_sin[NJ] = {0};
    for (int d = 0; d < 3; ++d) {
        mj[d + d * NJ] = 1.0;
        mj[(3 + d) + (3 + d) * NJ] = 1.0;
        kj[d + d * NJ] = 2.0e4;
        kj[(3 + d) + (3 + d) * NJ] = 1.0e4;
        kj[d + (3 + d) * NJ] = -1.0e4;
        kj[(3 + d) + d * NJ] = -1.0e4;
    }
    const size_t node1[3] = {3, 4, 5}, outs_j[2] = {0, 3};
    jprom_model *jm = NULL;
    expect(jprom_model_new(NJ, mj, kj, &jm), JPROM_OK, "JP model");
    expect(jprom_model_add_contact_3d(jm, node1, NULL, frame, 3.0e4, 3.0e4, 5.0e4, 0.5, 20.0), JPROM_OK, "JP model contact");
    expect(jprom_model_set_rayleigh_damping(jm, 0.0, 1.0e-4), JPROM_OK, "JP model damping");
    expect(jprom_model_set_harmonic_force(jm, 1, fj_cos, fj_sin, NJ), JPROM_OK, "JP model forcing");
    expect(jprom_model_set_output_dofs(jm, outs_j, 2), JPROM_OK, "JP model outputs");
    sopts.omega_start = 60.0;
    sopts.omega_end = 160.0;
    jprom_jp_options jo;
    expect(jprom_jp_options_default(NULL), JPROM_NULL_ARGUMENT, "jp options default into NULL");
    expect(jprom_jp_options_default(&jo), JPROM_OK, "jp options default");
    jprom_basis *basis = NULL;
    jprom_sweep_result *rom = NULL;
    jo.struct_size = 3;
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_NLR, &opts, &sopts, &jo, NULL, NULL, &rom, &basis), JPROM_BAD_SIZE, "jp options not from jprom_jp_options_default");
    jprom_jp_options_default(&jo);
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_NLR, &opts, &sopts, NULL, NULL, NULL, &rom, &basis), JPROM_NULL_ARGUMENT, "NULL jp options");
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_NLR, &opts, &sopts, &jo, NULL, NULL, NULL, &basis), JPROM_NULL_ARGUMENT, "adaptive sweep into NULL");
    expect(jprom_rom_sweep_adaptive(NULL, JPROM_ROM_NLR, &opts, &sopts, &jo, NULL, NULL, &rom, &basis), JPROM_NULL_ARGUMENT, "adaptive sweep of a NULL model");
    expect(jprom_rom_sweep_adaptive(jm, 7, &opts, &sopts, &jo, NULL, NULL, &rom, &basis), JPROM_INVALID_VALUE, "adaptive sweep of ROM kind 7");
    jo.threshold = NAN;
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_NLR, &opts, &sopts, &jo, NULL, NULL, &rom, &basis), JPROM_INVALID_VALUE, "NaN threshold");
    jo.threshold = 0.0;
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_NLR, &opts, &sopts, &jo, NULL, NULL, &rom, &basis), JPROM_INVALID_VALUE, "zero threshold");
    jprom_jp_options_default(&jo);
    jo.gamma_growth = 1.0;
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_FR, &opts, &sopts, &jo, NULL, NULL, &rom, &basis), JPROM_INVALID_VALUE, "gamma_growth 1");
    jprom_jp_options_default(&jo);
    jo.max_gamma = jo.gamma / 2;
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_FR, &opts, &sopts, &jo, NULL, NULL, &rom, &basis), JPROM_INVALID_VALUE, "max_gamma below gamma");
    jprom_jp_options_default(&jo);
    jo.n_samples = 0;
    expect(jprom_basis_predict_opts(jm, &opts, &jo, 60.0, 160.0, &basis), JPROM_INVALID_VALUE, "prediction with 0 samples");
    jprom_jp_options_default(&jo);
    jo.gamma = NAN;
    expect(jprom_basis_predict_opts(jm, &opts, &jo, 60.0, 160.0, &basis), JPROM_INVALID_VALUE, "NaN gamma");
    jprom_jp_options_default(&jo);
    expect(jprom_basis_predict_opts(jm, &opts, &jo, NAN, 160.0, &basis), JPROM_INVALID_VALUE, "NaN band");
    jprom_jp_options_default(&jo);
    jo.slipping = 3;
    expect(jprom_basis_predict_opts(jm, &opts, &jo, 60.0, 160.0, &basis), JPROM_INVALID_VALUE, "slipping 3 (not a jprom_slipping_samples)");
    jo.slipping = JPROM_SLIPPING_ALWAYS;
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_NLR, &opts, &sopts, &jo, NULL, NULL, &rom, NULL), JPROM_OK, "adaptive sweep with the slipping samples");
    jprom_sweep_result_free(rom);
    rom = NULL;
    if (basis != NULL || rom != NULL) { printf("FAIL basis or sweep written on failure\n"); failures++; }
    expect(jprom_rom_sweep_adaptive(jm, JPROM_ROM_NLR, &opts, &sopts, &jo, stop_at_third, NULL, &rom, &basis), JPROM_OK, "callback stops the adaptive sweep");
    reason = JPROM_SWEEP_REACHED_END;
    expect(jprom_sweep_result_end_reason(rom, &reason), JPROM_OK, "end reason of a cancelled adaptive sweep");
    if (reason != JPROM_SWEEP_CANCELLED) { printf("FAIL cancelled adaptive sweep's end reason %d\n", (int)reason); failures++; }
    np = 0;
    expect(jprom_sweep_result_n_points(rom, &np), JPROM_OK, "points of a cancelled adaptive sweep");
    if (np != 3 || basis == NULL) { printf("FAIL cancelled adaptive sweep kept %zu points, basis %p\n", np, (void *)basis); failures++; }
    size_t ncorr = 99;
    expect(jprom_sweep_result_n_corrections(rom, &ncorr), JPROM_OK, "corrections of a cancelled sweep");
    if (ncorr != 0) { printf("FAIL %zu corrections after a cancelled first pass\n", ncorr); failures++; }
    expect(jprom_sweep_result_n_corrections(NULL, &ncorr), JPROM_NULL_ARGUMENT, "corrections of a NULL sweep");
    int ckind = -1;
    expect(jprom_sweep_result_correction(rom, 0, &ckind, NULL, NULL, NULL, NULL, 0), JPROM_INVALID_VALUE, "correction index out of range");
    if (ckind != -1) { printf("FAIL correction kind written on failure\n"); failures++; }
    expect(jprom_sweep_result_correction((const jprom_sweep_result *)jm, 0, NULL, NULL, NULL, NULL, NULL, 0), JPROM_INVALID_HANDLE, "a model passed as a sweep");

    jprom_solution *fo = NULL, *fo_other = NULL, *red = NULL;
    expect(jprom_solve_point(jm, 60.0, &opts, &fo), JPROM_OK, "full-order point at the first reduced omega");
    expect(jprom_sweep_result_point(rom, 0, &red), JPROM_OK, "reduced point 0");
    jprom_basis *own = NULL;
    expect(jprom_basis_from_solution(jm, NULL, &opts, &jo, 60.0, 160.0, &own), JPROM_NULL_ARGUMENT, "basis from a NULL solution");
    expect(jprom_basis_from_solution(jm, (const jprom_solution *)rom, &opts, &jo, 60.0, 160.0, &own), JPROM_INVALID_HANDLE, "a sweep passed as a solution");
    expect(jprom_basis_from_solution(jm, red, &opts, &jo, 60.0, 160.0, &own), JPROM_INVALID_VALUE, "basis from a reduced solution");
    expect(jprom_basis_from_solution(jm, fo, &opts, &jo, 60.0, NAN, &own), JPROM_INVALID_VALUE, "basis from a solution, NaN band");
    jprom_hbm_options opts3 = opts;
    opts3.harmonics = 3;
    expect(jprom_basis_from_solution(jm, fo, &opts3, &jo, 60.0, 160.0, &own), JPROM_INVALID_VALUE, "basis from a solution of another H");
    if (own != NULL) { printf("FAIL basis written on failure\n"); failures++; }
    expect(jprom_basis_from_solution(jm, fo, &opts, &jo, 60.0, 160.0, &own), JPROM_OK, "basis from a full-order solution");

    double e[2] = {-1.0, -1.0};
    expect(jprom_rom_actual_error(jm, basis, JPROM_ROM_NLR, &opts, red, fo, NULL, 2), JPROM_NULL_ARGUMENT, "actual error into NULL");
    expect(jprom_rom_actual_error(jm, basis, JPROM_ROM_NLR, &opts, red, fo, e, 1), JPROM_BAD_SIZE, "actual error buffer too small");
    expect(jprom_rom_actual_error(jm, basis, 2, &opts, red, fo, e, 2), JPROM_INVALID_VALUE, "actual error of ROM kind 2");
    expect(jprom_rom_actual_error(jm, basis, JPROM_ROM_NLR, &opts, fo, fo, e, 2), JPROM_INVALID_VALUE, "actual error of a full-order 'reduced' solution");
    expect(jprom_rom_actual_error(jm, basis, JPROM_ROM_NLR, &opts, red, red, e, 2), JPROM_INVALID_VALUE, "actual error against a reduced 'full-order' solution");
    expect(jprom_rom_actual_error(jm, (const jprom_basis *)fo, JPROM_ROM_NLR, &opts, red, fo, e, 2), JPROM_INVALID_HANDLE, "a solution passed as a basis");
    expect(jprom_solve_point(jm, 70.0, &opts, &fo_other), JPROM_OK, "full-order point at another omega");
    expect(jprom_rom_actual_error(jm, basis, JPROM_ROM_NLR, &opts, red, fo_other, e, 2), JPROM_INVALID_VALUE, "actual error at two frequencies");
    if (e[0] != -1.0 || e[1] != -1.0) { printf("FAIL actual error written on failure\n"); failures++; }
    expect(jprom_rom_actual_error(jm, basis, JPROM_ROM_NLR, &opts, red, fo, e, 2), JPROM_OK, "actual error at point 0");
    if (!(e[1] >= 0.0 && e[1] < 1.0)) { printf("FAIL actual error %g\n", e[1]); failures++; }
    jprom_solution_free(fo);
    jprom_solution_free(fo_other);
    jprom_solution_free(red);
    jprom_basis_free(own);
    jprom_basis_free(basis);
    jprom_sweep_result_free(rom);
    jprom_model_free(jm);

    expect(jprom_model_load_json("/nonexistent/dir/model.json", &model), JPROM_IO, "load from a missing file");

    /* message copy into a short buffer: truncated, NUL-terminated, full length reported */
    char small[8];
    size_t written = 0;
    jprom_status s = jprom_last_error_copy(small, sizeof small, &written);
    if (s != JPROM_BAD_SIZE || strlen(small) != 7 || written <= 7) { printf("FAIL truncated copy\n"); failures++; }
    else printf("ok truncated message copy: %s (%zu bytes in full)\n", small, written);

    /* double free and use after free are detected, not undefined behaviour */
    expect(jprom_model_free(model), JPROM_OK, "free");
    expect(jprom_model_free(model), JPROM_INVALID_HANDLE, "double free");
    size_t n = 0;
    expect(jprom_model_n_dof(model, &n), JPROM_INVALID_HANDLE, "use after free");
    expect(jprom_model_free(NULL), JPROM_OK, "free(NULL)");

    size_t live = 99;
    jprom_live_handle_count(&live);
    if (live != 0) { printf("FAIL %zu handles leaked\n", live); failures++; }

    if (failures == 0) printf("all checks passed\n");
    return failures != 0;
}
