/* The bad-input catalogue of issue 12 (hardening) through the C API: each case returns its
 * documented status with a message that says what is wrong; none returns JPROM_PANIC, none
 * aborts or hangs (the Rust test runs this program under a time limit).
 * Prints "ok <what>: <STATUS>: <message>" per check and "all checks passed" at the end;
 * exits 1 if any check failed. Usage: hostile_input SCRATCH_DIR */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
/* calls the deprecated functions too: they stay in the ABI and must keep working */
#define JPROM_NO_DEPRECATION_WARNINGS
#include "jprom.h"

static int failures = 0;

/* `got` must be `want`, and on failure the message must contain `needle` (NULL: any message
 * of at least 10 characters). On success the message must be empty. */
static void expect(jprom_status got, jprom_status want, const char *what, const char *needle) {
    const char *msg = jprom_last_error_message();
    if (got != want) {
        printf("FAIL %s: got %s, expected %s (%s)\n", what, jprom_status_name((int)got), jprom_status_name((int)want), msg);
        failures++;
    } else if (want != JPROM_OK && (strlen(msg) < 10 || (needle != NULL && strstr(msg, needle) == NULL))) {
        printf("FAIL %s: message '%s' should say '%s'\n", what, msg, needle ? needle : "(anything)");
        failures++;
    } else if (want == JPROM_OK && msg[0] != '\0') {
        printf("FAIL %s: OK but the last error is '%s'\n", what, msg);
        failures++;
    } else {
        printf("ok %s: %s: %s\n", what, jprom_status_name((int)got), msg);
    }
}

static void check(int cond, const char *what) {
    if (!cond) {
        printf("FAIL %s\n", what);
        failures++;
    } else {
        printf("ok %s\n", what);
    }
}

/* The examples' two-node model: node 0 on springs, node 1 against ground by a friction
 * contact (contact = 0: no contact at all). */
static jprom_model *two_nodes(int contact) {
    enum { N = 6 };
    double m[N * N] = {0}, k[N * N] = {0}, fc[N] = {5.0, 0, 0, 0, 0, 0}, f0[N] = {0, 0, 0, 0, 0, 1.0};
    for (int d = 0; d < 3; ++d) {
        m[d + d * N] = 1.0;
        m[(3 + d) + (3 + d) * N] = 1.0;
        k[d + d * N] = 2.0e4;
        k[(3 + d) + (3 + d) * N] = 2.0e4;
        k[d + (3 + d) * N] = -1.0e4;
        k[(3 + d) + d * N] = -1.0e4;
    }
    const size_t node1[3] = {3, 4, 5}, outs[2] = {0, 3};
    const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    jprom_model *model = NULL;
    if (jprom_model_new(N, m, k, &model) != JPROM_OK) return NULL;
    if (contact) jprom_model_add_contact_3d(model, node1, NULL, frame, 3.0e4, 3.0e4, 5.0e4, 0.5, 20.0);
    jprom_model_set_rayleigh_damping(model, 0.0, 1.0e-4);
    jprom_model_set_harmonic_force(model, 1, fc, NULL, N);
    jprom_model_set_static_force(model, f0, N);
    jprom_model_set_output_dofs(model, outs, 2);
    return model;
}

/* A progress callback that makes a failing nested call, then lets the sweep go on. */
static int nested_failure(void *user, size_t index, double omega, const double *amps, size_t n) {
    (void)index; (void)omega; (void)amps; (void)n;
    size_t dofs = 0;
    jprom_status s = jprom_model_n_dof(NULL, &dofs);
    *(int *)user += (s == JPROM_NULL_ARGUMENT);
    return 0;
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "/tmp";
    char path[4096];
    const size_t big = (size_t)1 << 40, huge = SIZE_MAX;
    jprom_model *model = two_nodes(1);
    check(model != NULL, "test model");
    jprom_hbm_options opts;
    jprom_sweep_options band;
    jprom_jp_options jp;
    jprom_hbm_options_default(&opts);
    jprom_sweep_options_default(&band);
    jprom_jp_options_default(&jp);
    band.omega_start = 60.0;
    band.omega_end = 160.0;
    jprom_solution *sol = NULL;
    jprom_sweep_result *sweep = NULL;
    jprom_basis *basis = NULL;

    /* --- sizes from the caller: checked before anything is allocated --- */
    expect(jprom_model_set_harmonic_force(model, 1, NULL, NULL, huge), JPROM_BAD_SIZE, "set_harmonic_force n = SIZE_MAX, NULL parts", "must equal the model's DoF count");
    expect(jprom_model_set_harmonic_force(model, 1, NULL, NULL, big), JPROM_BAD_SIZE, "set_harmonic_force n = 2^40", "must equal the model's DoF count");
    size_t harmonics[] = {10000, big, huge, huge - 1};
    for (size_t i = 0; i < sizeof harmonics / sizeof *harmonics; ++i) {
        char what[128];
        jprom_hbm_options o = opts;
        o.harmonics = harmonics[i];
        snprintf(what, sizeof what, "solve_point harmonics = %zu", harmonics[i]);
        expect(jprom_solve_point(model, 100.0, &o, &sol), JPROM_BAD_SIZE, what, "above jprom's limit of 64");
        snprintf(what, sizeof what, "sweep harmonics = %zu", harmonics[i]);
        expect(jprom_sweep(model, &o, &band, NULL, NULL, &sweep), JPROM_BAD_SIZE, what, "harmonics");
        snprintf(what, sizeof what, "basis_predict harmonics = %zu", harmonics[i]);
        expect(jprom_basis_predict(model, &o, 60.0, 160.0, 1e3, 10, &basis), JPROM_BAD_SIZE, what, "harmonics");
        snprintf(what, sizeof what, "basis_predict_opts harmonics = %zu", harmonics[i]);
        expect(jprom_basis_predict_opts(model, &o, &jp, 60.0, 160.0, &basis), JPROM_BAD_SIZE, what, "harmonics");
        snprintf(what, sizeof what, "rom_sweep_adaptive harmonics = %zu", harmonics[i]);
        expect(jprom_rom_sweep_adaptive(model, JPROM_ROM_NLR, &o, &band, &jp, NULL, NULL, &sweep, &basis), JPROM_BAD_SIZE, what, "harmonics");
    }
    size_t nts[] = {big, huge, (size_t)1 << 17};
    for (size_t i = 0; i < sizeof nts / sizeof *nts; ++i) {
        char what[128];
        jprom_hbm_options o = opts;
        o.nt = nts[i];
        snprintf(what, sizeof what, "solve_point nt = %zu", nts[i]);
        expect(jprom_solve_point(model, 100.0, &o, &sol), JPROM_BAD_SIZE, what, "nt");
        snprintf(what, sizeof what, "rom_sweep_adaptive nt = %zu", nts[i]);
        expect(jprom_rom_sweep_adaptive(model, JPROM_ROM_FR, &o, &band, &jp, NULL, NULL, &sweep, &basis), JPROM_BAD_SIZE, what, "nt");
    }
    size_t samples[] = {(size_t)1 << 22, big, huge, JPROM_MAX_SAMPLES + 1};
    for (size_t i = 0; i < sizeof samples / sizeof *samples; ++i) {
        char what[128];
        jprom_jp_options j = jp;
        j.n_samples = samples[i];
        snprintf(what, sizeof what, "basis_predict n_samples = %zu", samples[i]);
        expect(jprom_basis_predict(model, &opts, 60.0, 160.0, 1e3, samples[i], &basis), JPROM_BAD_SIZE, what, "above jprom's limit of 10000");
        snprintf(what, sizeof what, "basis_predict_opts n_samples = %zu", samples[i]);
        expect(jprom_basis_predict_opts(model, &opts, &j, 60.0, 160.0, &basis), JPROM_BAD_SIZE, what, "n_samples");
        snprintf(what, sizeof what, "rom_sweep_adaptive n_samples = %zu", samples[i]);
        expect(jprom_rom_sweep_adaptive(model, JPROM_ROM_NLR, &opts, &band, &j, NULL, NULL, &sweep, &basis), JPROM_BAD_SIZE, what, "n_samples");
    }
    check(sol == NULL && sweep == NULL && basis == NULL, "nothing written by the refused calls");

    /* the memory budget: a full-order solve whose dense Jacobian exceeds it */
    size_t budget = 0;
    expect(jprom_memory_budget(&budget), JPROM_OK, "memory budget", NULL);
    check(budget > ((size_t)1 << 20), "the default budget is a share of the machine's memory");
    expect(jprom_set_memory_budget(1000), JPROM_OK, "set a budget of 1000 bytes", NULL);
    jprom_hbm_options full = opts;
    full.condensed = 0;
    expect(jprom_solve_point(model, 100.0, &full, &sol), JPROM_BAD_SIZE, "solve beyond the budget", "more than the memory budget of 1000 bytes (raise it with jprom_set_memory_budget");
    /* the unreduced FE model (dense M and K, 2 n^2 doubles) of a 4-node chain: 12 DoFs, 2304 bytes */
    {
        size_t cp[13], ri[12];
        double kv[12], mv[12];
        int64_t ids[4] = {1, 2, 3, 4}, rows[24];
        for (size_t i = 0; i < 12; i++) { cp[i] = i; ri[i] = i; kv[i] = 1e4; mv[i] = 1.0; }
        cp[12] = 12;
        for (int nd = 0; nd < 4; nd++)
            for (int d = 0; d < 6; d++) rows[6 * nd + d] = d < 3 ? 3 * nd + d : -1;
        jprom_fe_model *fe = NULL;
        jprom_model *dense = NULL;
        const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        expect(jprom_set_memory_budget(0), JPROM_OK, "restore the default budget", NULL);
        expect(jprom_fe_model_new_csc(12, cp, ri, kv, cp, ri, mv, 4, ids, rows, &fe), JPROM_OK, "a 12-DoF FE model", NULL);
        expect(jprom_fe_model_add_contact(fe, 4, frame, 1e3, 1e3, 1e3, 0.3, 1.0), JPROM_OK, "a contact on it", NULL);
        expect(jprom_set_memory_budget(1000), JPROM_OK, "a budget of 1000 bytes again", NULL);
        expect(jprom_fe_model_unreduced(fe, &dense), JPROM_BAD_SIZE, "the unreduced FE model beyond the budget", "the unreduced FE model (12 DoFs, dense M, K) is too large");
        check(dense == NULL, "nothing written by the refused unreduced model");
        expect(jprom_set_memory_budget(0), JPROM_OK, "restore the default budget", NULL);
        expect(jprom_fe_model_unreduced(NULL, &dense), JPROM_NULL_ARGUMENT, "the unreduced model of NULL", "fe");
        expect(jprom_fe_model_unreduced(fe, NULL), JPROM_NULL_ARGUMENT, "the unreduced model into NULL", "out");
        expect(jprom_fe_model_unreduced(fe, &dense), JPROM_OK, "the unreduced FE model", NULL);
        size_t n_dense = 0, n_contacts = 0;
        jprom_model_n_dof(dense, &n_dense);
        jprom_model_n_contacts(dense, &n_contacts);
        check(n_dense == 12 && n_contacts == 1, "every FE DoF kept, the contact on it");
        jprom_model_free(dense);
        jprom_fe_model_free(fe);
    }
    expect(jprom_set_memory_budget(0), JPROM_OK, "restore the default budget", NULL);
    size_t again = 0;
    jprom_memory_budget(&again);
    check(again == budget, "the default budget is back");
    /* reproducible kernels: NULL out refused; any nonzero is on; 0 restores the default */
    {
        int repro = -1;
        expect(jprom_reproducible(NULL), JPROM_NULL_ARGUMENT, "reproducible into NULL", "out");
        expect(jprom_reproducible(&repro), JPROM_OK, "reproducible (default)", NULL);
        check(repro == 0, "kernels on all threads by default");
        expect(jprom_set_reproducible(-7), JPROM_OK, "reproducible kernels on (a nonzero int)", NULL);
        expect(jprom_reproducible(&repro), JPROM_OK, "reproducible (on)", NULL);
        check(repro == 1, "reproducible reads back 1");
        expect(jprom_set_reproducible(0), JPROM_OK, "reproducible kernels off", NULL);
        expect(jprom_reproducible(&repro), JPROM_OK, "reproducible (off)", NULL);
        check(repro == 0, "reproducible reads back 0");
    }
    expect(jprom_solve_point(model, 100.0, &full, &sol), JPROM_OK, "the same solve within the budget", NULL);

    /* --- values --- */
    double level = 0.0;
    jprom_model_excitation_level(model, &level);
    expect(jprom_model_set_excitation_level(model, 1e-320), JPROM_INVALID_VALUE, "excitation level 1e-320", "must be finite and > 0");
    double after = 0.0;
    jprom_model_excitation_level(model, &after);
    check(after == level, "a refused excitation level leaves the scale unchanged");
    expect(jprom_model_set_excitation_level(model, INFINITY), JPROM_INVALID_VALUE, "excitation level infinite", "must be finite and > 0");
    expect(jprom_model_set_excitation_level(model, 0.5), JPROM_OK, "excitation level 0.5", NULL);
    jprom_solution_free(sol);
    sol = NULL;
    expect(jprom_solve_point(model, 100.0, &opts, &sol), JPROM_OK, "a solve after the refused levels", NULL);
    jprom_solution_free(sol);
    sol = NULL;
    const size_t repeated[3] = {1, 1, 1}, node0[3] = {0, 1, 2};
    const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    expect(jprom_model_add_contact_3d(model, repeated, NULL, frame, 1e3, 1e3, 1e3, 0.3, 1.0), JPROM_INVALID_VALUE, "dofs_a = {1, 1, 1}", "repeated within the node");
    const size_t repeated_b[3] = {4, 4, 4};
    expect(jprom_model_add_contact_3d(model, node0, repeated_b, frame, 1e3, 1e3, 1e3, 0.3, 1.0), JPROM_INVALID_VALUE, "dofs_b = {4, 4, 4}", "repeated within the node");

    /* --- a model without contacts: every JP entry point refuses it, with one message --- */
    jprom_model *linear = two_nodes(0);
    const char *no_contact = "the model has no contact: JP reduces onto the contact coordinates";
    expect(jprom_basis_predict_opts(linear, &opts, &jp, 60.0, 160.0, &basis), JPROM_INVALID_VALUE, "predict a basis without contacts", no_contact);
    check(basis == NULL, "no basis written without contacts");
    expect(jprom_rom_sweep_adaptive(linear, JPROM_ROM_FR, &opts, &band, &jp, NULL, NULL, &sweep, &basis), JPROM_INVALID_VALUE, "adaptive FR sweep without contacts", no_contact);
    expect(jprom_rom_sweep_adaptive(linear, JPROM_ROM_NLR, &opts, &band, &jp, NULL, NULL, &sweep, &basis), JPROM_INVALID_VALUE, "adaptive NLR sweep without contacts", no_contact);
    check(sweep == NULL && basis == NULL, "no sweep written without contacts");
    /* the full order on all DoFs (the condensed one needs contacts to condense onto) */
    jprom_hbm_options all_dofs = opts;
    all_dofs.condensed = 0;
    expect(jprom_solve_point(linear, 100.0, &all_dofs, &sol), JPROM_OK, "the full order without contacts", NULL);
    expect(jprom_basis_from_solution(linear, sol, &all_dofs, &jp, 60.0, 160.0, &basis), JPROM_INVALID_VALUE, "a basis from a solution without contacts", no_contact);
    jprom_solution_free(sol);
    sol = NULL;
    /* a basis of the model with its contact, given with the model without */
    expect(jprom_basis_predict_opts(model, &opts, &jp, 60.0, 160.0, &basis), JPROM_OK, "predict a basis with the contact", NULL);
    expect(jprom_rom_sweep(linear, basis, JPROM_ROM_FR, &opts, &band, NULL, NULL, &sweep), JPROM_INVALID_VALUE, "FR sweep without contacts", no_contact);
    expect(jprom_rom_sweep(linear, basis, JPROM_ROM_NLR, &opts, &band, NULL, NULL, &sweep), JPROM_INVALID_VALUE, "NLR sweep without contacts", no_contact);
    jprom_basis_free(basis);
    basis = NULL;
    jprom_model_free(linear);
    /* the self-correcting sweep's outcome, and its getters' refusals */
    expect(jprom_rom_sweep_adaptive(model, JPROM_ROM_FR, &opts, &band, &jp, NULL, NULL, &sweep, &basis), JPROM_OK, "adaptive FR sweep", NULL);
    {
        jprom_correction_end end = JPROM_CORRECTIONS_CANCELLED;
        double judged = -1.0;
        expect(jprom_sweep_result_correction_end(sweep, &end, &judged), JPROM_OK, "how the corrections of a sweep ended", NULL);
        check(end != JPROM_CORRECTIONS_CANCELLED && judged >= 0.0, "a finished sweep's corrections end and its judged error");
        expect(jprom_sweep_result_correction_end(NULL, &end, &judged), JPROM_NULL_ARGUMENT, "correction_end of a NULL sweep", "sweep");
        double w0 = -1.0;
        expect(jprom_sweep_result_static_error(NULL, &w0), JPROM_NULL_ARGUMENT, "static_error of a NULL sweep", "sweep");
        expect(jprom_sweep_result_static_error(sweep, NULL), JPROM_NULL_ARGUMENT, "static_error into NULL", "'out'");
        check(w0 == -1.0, "a refused static_error writes nothing");
    }
    jprom_sweep_result_free(sweep);
    jprom_basis_free(basis);
    sweep = NULL;
    basis = NULL;

    /* --- a nested call failing inside a callback leaves no stale message after OK --- */
    int nested = 0;
    expect(jprom_sweep(model, &opts, &band, nested_failure, &nested, &sweep), JPROM_OK, "sweep whose callback makes a failing call", NULL);
    check(nested > 0, "the nested calls failed as they should");
    {
        jprom_correction_end end = JPROM_CORRECTIONS_CANCELLED;
        double judged = -1.0;
        expect(jprom_sweep_result_correction_end(sweep, &end, &judged), JPROM_INVALID_VALUE, "correction_end of a full-order sweep", "not a self-correcting sweep");
        check(end == JPROM_CORRECTIONS_CANCELLED && judged == -1.0, "a refused correction_end writes nothing");
        double w0 = -1.0;
        expect(jprom_sweep_result_static_error(sweep, &w0), JPROM_INVALID_VALUE, "static_error of a full-order sweep", "not a self-correcting sweep");
        check(w0 == -1.0, "a refused static_error writes nothing");
        int swept = -1;
        expect(jprom_sweep_result_correction_swept(sweep, 0, &swept), JPROM_INVALID_VALUE, "correction_swept of a sweep without corrections", "correction index 0");
        expect(jprom_sweep_result_correction_swept(NULL, 0, &swept), JPROM_NULL_ARGUMENT, "correction_swept of a NULL sweep", "sweep");
        expect(jprom_sweep_result_correction_swept(sweep, 0, NULL), JPROM_NULL_ARGUMENT, "correction_swept into NULL", "'out'");
        check(swept == -1, "a refused correction_swept writes nothing");
    }
    size_t live_before = 0, live_after = 0;
    jprom_live_handle_count(&live_before);
    expect(jprom_sweep_result_point(sweep, 0, NULL), JPROM_NULL_ARGUMENT, "sweep_point into NULL", "'out'");
    jprom_live_handle_count(&live_after);
    check(live_after == live_before, "a refused sweep_point leaks no handle");

    /* --- files --- */
    expect(jprom_model_load_json(dir, &model), JPROM_IO, "model_load_json of a directory", "is a directory");
    jprom_solution *s2 = NULL;
    jprom_sweep_result *w2 = NULL;
    jprom_basis *b2 = NULL;
    jprom_model *m2 = NULL;
    expect(jprom_solution_load_json(dir, &s2), JPROM_IO, "solution_load_json of a directory", "is a directory");
    expect(jprom_sweep_result_load_json(dir, &w2), JPROM_IO, "sweep_load_json of a directory", "is a directory");
    expect(jprom_basis_load_json(dir, &b2), JPROM_IO, "basis_load_json of a directory", "is a directory");
    snprintf(path, sizeof path, "%s/hostile_sweep.json", dir);
    expect(jprom_sweep_result_save_json(sweep, path), JPROM_OK, "save a sweep", NULL);
    expect(jprom_model_load_json(path, &m2), JPROM_IO, "a sweep file loaded as a model", "this is a jprom sweep file, expected a model");
    expect(jprom_basis_load_json(path, &b2), JPROM_IO, "a sweep file loaded as a basis", "this is a jprom sweep file, expected a basis");
    expect(jprom_sweep_result_load_json(path, &w2), JPROM_OK, "the sweep file loaded as a sweep", NULL);
    jprom_sweep_result_free(w2);
    snprintf(path, sizeof path, "%s/hostile_model.json", dir);
    expect(jprom_model_save_json(model, path), JPROM_OK, "save a model", NULL);
    expect(jprom_solution_load_json(path, &s2), JPROM_IO, "a model file loaded as a solution", "this is a jprom model file, expected a solution");
    check(m2 == NULL && s2 == NULL && b2 == NULL, "nothing written by the refused loads");

    /* writes to a full device: every one is reported, small files included */
    expect(jprom_model_save_json(model, "/dev/full"), JPROM_IO, "model_save_json to /dev/full", "No space left");
    expect(jprom_sweep_result_save_json(sweep, "/dev/full"), JPROM_IO, "sweep_save_json to /dev/full", "No space left");
    expect(jprom_sweep_result_point(sweep, 0, &sol), JPROM_OK, "a point of the sweep", NULL);
    expect(jprom_solution_save_json(sol, "/dev/full"), JPROM_IO, "solution_save_json to /dev/full", "No space left");
    expect(jprom_basis_predict_opts(model, &opts, &jp, 60.0, 160.0, &basis), JPROM_OK, "predict a basis", NULL);
    expect(jprom_basis_save_json(basis, "/dev/full"), JPROM_IO, "basis_save_json to /dev/full", "No space left");
    expect(jprom_model_save_json(model, dir), JPROM_IO, "model_save_json onto a directory", NULL);

    /* damping forms and modes (issue 13) */
    {
        double c_bad[36] = {0}, ratios[2] = {0.01, -0.5}, hz[6], force[6];
        size_t count = 0;
        c_bad[1] = 1.0; /* c(1, 0) without c(0, 1): not symmetric */
        expect(jprom_model_set_damping_matrix(model, c_bad, 6), JPROM_INVALID_VALUE, "an asymmetric damping matrix", "symmetric");
        expect(jprom_model_set_damping_matrix(model, c_bad, 5), JPROM_BAD_SIZE, "a damping matrix of the wrong size", "6 DoFs");
        expect(jprom_model_set_damping_matrix(model, NULL, 6), JPROM_NULL_ARGUMENT, "a NULL damping matrix with n = 6", "c");
        expect(jprom_model_set_modal_damping_ratios(model, ratios, 2, 0.0), JPROM_INVALID_VALUE, "a negative modal ratio", "ratio 1");
        expect(jprom_model_set_modal_damping_ratios(model, ratios, 1, 0.0 / 0.0), JPROM_INVALID_VALUE, "a NaN ratio for the other modes", "other modes");
        expect(jprom_model_set_loss_factor(model, -0.01), JPROM_INVALID_VALUE, "a negative loss factor", "loss factor");
        expect(jprom_model_modes(model, 7, hz, NULL, 6, &count), JPROM_INVALID_VALUE, "modes with stuck = 7", "stuck must be 0 or 1");
        expect(jprom_model_modes(model, 1, NULL, NULL, 6, &count), JPROM_NULL_ARGUMENT, "modes into NULL", "frequency_hz");
        expect(jprom_model_modes(model, 1, hz, force, 6, &count), JPROM_OK, "the stuck modes", NULL);
        check(count == 6 && hz[0] > 0.0 && hz[5] >= hz[0] && force[0] >= 0.0, "six stuck modes, ascending");
        expect(jprom_fe_model_modes(NULL, 3, hz), JPROM_NULL_ARGUMENT, "FE modes of NULL", "fe");
        expect(jprom_fe_model_fix_dof(NULL, 1, 0), JPROM_NULL_ARGUMENT, "fix a DoF of NULL", "fe");
        expect(jprom_fe_model_reduce_cutoff(NULL, 1000.0, 10, &m2), JPROM_NULL_ARGUMENT, "reduce NULL with a cut-off", "fe");
    }

    /* absurd magnitudes (issue 60): refused by the setter, the model unchanged; a solve after
     * them uses the force that was there and reduces its residual to the tolerance */
    {
        enum { N = 6 };
        double f_huge[N] = {1e200, 0, 0, 0, 0, 0}, f_far[N] = {1e60, 0, 0, 0, 0, 0}, f_inf[N] = {1.0 / 0.0, 0, 0, 0, 0, 0};
        expect(jprom_model_set_harmonic_force(model, 1, f_huge, NULL, N), JPROM_INVALID_VALUE, "a harmonic force of 1e200", "beyond jprom's magnitude limit of 1e100");
        expect(jprom_model_set_harmonic_force(model, 1, NULL, f_inf, N), JPROM_INVALID_VALUE, "an infinite harmonic force", "not finite");
        expect(jprom_model_set_static_force(model, f_huge, N), JPROM_INVALID_VALUE, "a static force of 1e200", "beyond jprom's magnitude limit");
        expect(jprom_model_set_harmonic_force(model, 1, f_far, NULL, N), JPROM_INVALID_VALUE, "a force 1e56 times the static scale of the stiffness", "is a displacement scale of");
        expect(jprom_model_set_dynamic_scale(model, 1e95), JPROM_INVALID_VALUE, "a force scale that makes the force 5e95", "displacement scale");
        const size_t node[3] = {3, 4, 5};
        const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        expect(jprom_model_add_contact_3d(model, node, NULL, frame, 3e4, 3e4, 1e200, 0.5, 20.0), JPROM_INVALID_VALUE, "a normal stiffness of 1e200", "kn");
        expect(jprom_model_add_contact_3d(model, node, NULL, frame, 3e4, 3e4, 5e4, 0.5, -1e150), JPROM_INVALID_VALUE, "a preload of -1e150", "n0");
        double m[N * N] = {0}, k[N * N] = {0};
        for (int d = 0; d < N; ++d) m[d + d * N] = 1.0, k[d + d * N] = 1e4;
        k[0] = 1e200;
        jprom_model *absurd = NULL;
        expect(jprom_model_new(N, m, k, &absurd), JPROM_INVALID_VALUE, "a stiffness entry of 1e200", "entry (0, 0) is 1e200");
        check(absurd == NULL, "no model from an absurd stiffness");
        jprom_solution *after = NULL;
        expect(jprom_solve_point(model, 100.0, &opts, &after), JPROM_OK, "a solve after the refused magnitudes", NULL);
        double res = 1.0, amp = 0.0;
        jprom_solution_convergence(after, NULL, &res);
        jprom_solution_amplitude(after, 1, 0, &amp);
        check(res <= opts.residual_tolerance && amp > 0.0, "its residual is within the tolerance, its amplitude that of the force kept");
        jprom_solution_free(after);
    }

    /* the time budget (issue 60): a harmonic count whose dense JP eigenproblems (order
     * 2 H n = 480 here) would take longer than the budget is refused on its estimate, before
     * any eigen solve (the shift-invert path above order 512 is stopped between patterns) */
    {
        double seconds = 0.0;
        expect(jprom_time_budget(&seconds), JPROM_OK, "the default time budget", NULL);
        check(seconds == 3600.0, "the default time budget is an hour");
        expect(jprom_set_time_budget(-1.0), JPROM_INVALID_VALUE, "a negative time budget", "must be finite and > 0 seconds");
        expect(jprom_set_time_budget(0.0 / 0.0), JPROM_INVALID_VALUE, "a NaN time budget", "must be finite and > 0 seconds");
        expect(jprom_set_time_budget(1.0), JPROM_OK, "a time budget of 1 s", NULL);
        jprom_hbm_options h64 = opts;
        h64.harmonics = 40;
        jprom_basis *b64 = NULL;
        clock_t c0 = clock();
        expect(jprom_basis_predict_opts(model, &h64, &jp, 60.0, 160.0, &b64), JPROM_BAD_SIZE, "basis_predict_opts at H = 40 beyond a 1 s budget", "floating-point operations, about");
        check(b64 == NULL, "nothing written");
        printf("H = 40 refused after %.1f s of CPU\n", (double)(clock() - c0) / CLOCKS_PER_SEC);
        expect(jprom_set_time_budget(0.0), JPROM_OK, "the default time budget restored", NULL);
        jprom_time_budget(&seconds);
        check(seconds == 3600.0, "restored to an hour");
    }

    jprom_solution_free(sol);
    jprom_basis_free(basis);
    jprom_sweep_result_free(sweep);
    jprom_model_free(model);
    size_t live = 99;
    jprom_live_handle_count(&live);
    check(live == 0, "no handle leaked");
    if (failures == 0) printf("all checks passed\n");
    return failures != 0;
}
