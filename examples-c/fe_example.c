/*
 * jprom from C, starting from an FE model on disk: a CalculiX job is read, friction contacts
 * are put on the nodes of its set TIP, a force on LOAD and outputs on OUT, the model is
 * reduced by Craig-Bampton, and the self-correcting Jacobian Projection sweep (NLR ROM) runs
 * across the first bending modes. Prints `omega |X1| e*_1` per point (rad/s; first-harmonic
 * amplitude of the y displacement at the first OUT node, mm; error predictor of harmonic 1).
 * examples-fortran/fe_example.f90 does the same from Fortran and prints the same table.
 *
 * The deck is a CalculiX job with a `*FREQUENCY, SOLVER=MATRIXSTORAGE` step, run by `ccx`
 * beforehand: jprom reads the .inp (nodes, *NSET) and ccx's .sti, .mas and .dof beside it.
 * Units are the model's (here mm, tonne, s: forces in N, stiffnesses in N/mm).
 *
 * usage: fe_example [DECK.inp]
 *   default: crates/jprom/tests/data/calculix/block/block.inp (run from the repository
 *   root), a 720-DoF steel cantilever 100 x 20 x 10 mm whose first mode is at 897 Hz.
 *
 * Build (from the repository root, after `cargo build --lib`):
 *   gcc -Wall -Werror -std=c11 -Iinclude examples-c/fe_example.c \
 *       -Ltarget/debug -ljprom -Wl,-rpath,$PWD/target/debug -lm -o fe_example
 */
#include <stdio.h>
#include <stdlib.h>
#include "jprom.h"

/* Contact at each tip node: tangential and normal stiffness (N/mm), friction coefficient,
 * normal preload (N). The casing is beyond the tip along x: rows of the frame are t1 = y,
 * t2 = z, n = x. */
static const double KT = 2.0e3, KN = 2.0e4, MU = 0.3, N0 = 1.0;
static const double FRAME[9] = {0, 1, 0, 0, 0, 1, 1, 0, 0};
/* Fixed-interface modes kept by Craig-Bampton (besides the contact, load and output nodes). */
static const size_t CB_MODES = 12;
/* Modal damping ratio of every mode of the reduced model, the band around the stuck mode the
 * load drives most (the linear limit, contacts stuck: its frequency times 1 -/+ BAND), and the
 * first-harmonic force (N along y at LOAD). */
static const double ZETA = 0.005, BAND = 0.15, FORCE = 1.0;

static int fail(jprom_status s, const char *what) {
    fprintf(stderr, "%s failed: %s: %s\n", what, jprom_status_name((int)s), jprom_last_error_message());
    return 1;
}
/* every call returns a status; on error print jprom's message and stop */
#define TRY(call) do { jprom_status s_ = (call); if (s_ != JPROM_OK) return fail(s_, #call); } while (0)

int main(int argc, char **argv) {
    const char *deck = argc > 1 ? argv[1] : "crates/jprom/tests/data/calculix/block/block.inp";

    /* 1. the FE model: K, M and the node/DoF table from ccx's files, node sets from the deck */
    jprom_fe_model *fe = NULL;
    TRY(jprom_fe_model_load_calculix(deck, &fe));
    size_t n_dof = 0, n_tip = 0, n_out = 0, n_load = 0;
    TRY(jprom_fe_model_n_dof(fe, &n_dof));
    /* a set's size first (ids NULL), then its node ids */
    TRY(jprom_fe_model_node_set(fe, "TIP", NULL, 0, &n_tip));
    TRY(jprom_fe_model_node_set(fe, "OUT", NULL, 0, &n_out));
    TRY(jprom_fe_model_node_set(fe, "LOAD", NULL, 0, &n_load));
    int64_t *tip = malloc((n_tip + n_out + n_load) * sizeof *tip);
    if (!tip) return fail(JPROM_BAD_SIZE, "malloc");
    int64_t *out = tip + n_tip, *load = out + n_out;
    TRY(jprom_fe_model_node_set(fe, "TIP", tip, n_tip, NULL));
    TRY(jprom_fe_model_node_set(fe, "OUT", out, n_out, NULL));
    TRY(jprom_fe_model_node_set(fe, "LOAD", load, n_load, NULL));

    /* 2. what the reduced model keeps: contacts, the first-harmonic load, the outputs (y) */
    for (size_t i = 0; i < n_tip; ++i) TRY(jprom_fe_model_add_contact(fe, tip[i], FRAME, KT, KT, KN, MU, N0));
    const double f_y[3] = {0.0, FORCE, 0.0};
    TRY(jprom_fe_model_add_force(fe, load[0], 1, f_y));
    for (size_t i = 0; i < n_out; ++i) TRY(jprom_fe_model_add_output(fe, out[i], 1));
    free(tip);

    /* 3. Craig-Bampton: the reduced model is an ordinary jprom_model; the FE model can go */
    jprom_model *model = NULL;
    TRY(jprom_fe_model_reduce(fe, CB_MODES, &model));
    jprom_fe_model_free(fe);
    size_t n_red = 0;
    TRY(jprom_model_n_dof(model, &n_red));
    TRY(jprom_model_set_modal_damping_ratios(model, NULL, 0, ZETA));

    /* the natural frequencies: contacts open, and stuck (the band goes around the first stuck one) */
    double free_hz[3], stuck_hz[3], modal_force[3];
    TRY(jprom_model_modes(model, 0, free_hz, NULL, 3, NULL));
    TRY(jprom_model_modes(model, 1, stuck_hz, modal_force, 3, NULL));
    /* the stuck mode the load drives most (the largest modal force) of the lowest three */
    int k = 0;
    for (int i = 1; i < 3; ++i) if (modal_force[i] > modal_force[k]) k = i;
    const double two_pi = 6.283185307179586;
    const double omega_lo = (1.0 - BAND) * two_pi * stuck_hz[k], omega_hi = (1.0 + BAND) * two_pi * stuck_hz[k];

    /* 4. the self-correcting JP sweep: a basis predicted from the stuck mode, the NLR ROM swept
     * over the band, the basis corrected where the error predictor e*_1 says so */
    jprom_hbm_options opts;
    jprom_sweep_options band;
    jprom_jp_options jp;
    TRY(jprom_hbm_options_default(&opts));
    TRY(jprom_sweep_options_default(&band));
    TRY(jprom_jp_options_default(&jp));
    band.omega_start = omega_lo;
    band.omega_end = omega_hi;
    jprom_sweep_result *sweep = NULL;
    TRY(jprom_rom_sweep_adaptive(model, JPROM_ROM_NLR, &opts, &band, &jp, NULL, NULL, &sweep, NULL));

    size_t n = 0, n_corr = 0;
    jprom_sweep_end end;
    TRY(jprom_sweep_result_n_points(sweep, &n));
    TRY(jprom_sweep_result_n_corrections(sweep, &n_corr));
    TRY(jprom_sweep_result_end_reason(sweep, &end));
    printf("# %s: %zu DoFs, %zu tip contacts, reduced to %zu DoFs\n", deck, n_dof, n_tip, n_red);
    printf("# first modes, contacts open: %.6g %.6g %.6g Hz; stuck: %.6g %.6g %.6g Hz (modal force %.3g %.3g %.3g)\n",
           free_hz[0], free_hz[1], free_hz[2], stuck_hz[0], stuck_hz[1], stuck_hz[2], modal_force[0], modal_force[1], modal_force[2]);
    printf("# JP NLR sweep: %zu points, %zu basis corrections, end: %s\n", n, n_corr, jprom_sweep_end_name((int)end));
    for (size_t c = 0; c < n_corr; ++c) {
        /* what each correction did: its kind, the judged error of the sweep before and after
         * it, and the basis sizes n_h, h = 0..H, it left (H = opts.harmonics) */
        int kind;
        double value, before, after;
        size_t sizes[8];
        if (opts.harmonics + 1 > 8) return 1;
        TRY(jprom_sweep_result_correction(sweep, c, &kind, &value, &before, &after, sizes, opts.harmonics + 1));
        printf("# correction %zu: %s, worst error %.3g -> %.3g, n_h =", c + 1, jprom_correction_kind_name(kind), before, after);
        for (size_t h = 0; h <= opts.harmonics; ++h) printf(" %zu", sizes[h]);
        printf("\n");
    }
    /* why the corrections ended: above the threshold the basis stayed poor, and the sweep holds
     * the best basis found */
    jprom_correction_end corrections_end;
    double judged;
    TRY(jprom_sweep_result_correction_end(sweep, &corrections_end, &judged));
    printf("# corrections ended: %s, judged error %.3g (threshold %g)%s\n", jprom_correction_end_name((int)corrections_end), judged,
           jp.threshold, judged > jp.threshold ? ": the basis stayed poor" : "");
    /* the static term, which the corrections do not judge (docs/formulation.md, section 10.6) */
    double w0_error;
    if (jprom_sweep_result_static_error(sweep, &w0_error) == JPROM_OK)
        printf("# static contact displacement error %.3g%s\n", w0_error, w0_error > jp.threshold ? ": X0 is poor" : "");
    printf("# omega_rad_s X1_out0_y e*_1\n");
    for (size_t i = 0; i < n; ++i) {
        double w, x1, e1;
        TRY(jprom_sweep_result_point_omega(sweep, i, &w));
        TRY(jprom_sweep_result_point_amplitude(sweep, i, 1, 0, &x1));
        TRY(jprom_sweep_result_point_predicted_error(sweep, i, 1, &e1));
        printf("%.17e %.17e %.17e\n", w, x1, e1);
    }
    jprom_sweep_result_free(sweep);
    jprom_model_free(model);
    return end == JPROM_SWEEP_REACHED_END ? 0 : 1;
}
