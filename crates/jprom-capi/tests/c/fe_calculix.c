/* From a CalculiX model to a self-correcting JP sweep in C: FE model from ccx's *MATRIX STORAGE
 * output, a contact on every node of the set TIP, the load at LOAD, outputs at OUT, Craig-Bampton,
 * then jprom_rom_sweep_adaptive (NLR). Prints one row per point: omega, |X1| at output 0, e*_1.
 *
 * usage: fe_calculix DECK.inp kt kn mu n0 dynamic_scale omega_lo omega_hi beta cb_modes */
#include <stdio.h>
#include <stdlib.h>
#include "jprom.h"

static int fail(jprom_status s, const char *what) {
    fprintf(stderr, "%s: %s: %s\n", what, jprom_status_name((int)s), jprom_last_error_message());
    return 1;
}
#define TRY(call) do { jprom_status s_ = (call); if (s_ != JPROM_OK) return fail(s_, #call); } while (0)

int main(int argc, char **argv) {
    if (argc != 11) {
        fprintf(stderr, "usage: %s DECK.inp kt kn mu n0 dynamic_scale omega_lo omega_hi beta cb_modes\n", argv[0]);
        return 2;
    }
    double kt = atof(argv[2]), kn = atof(argv[3]), mu = atof(argv[4]), n0 = atof(argv[5]);
    double scale = atof(argv[6]), lo = atof(argv[7]), hi = atof(argv[8]), beta = atof(argv[9]);
    size_t cb_modes = (size_t)strtoul(argv[10], NULL, 10);

    jprom_fe_model *fe = NULL;
    TRY(jprom_fe_model_load_calculix(argv[1], &fe));
    size_t n_dof = 0, n_tip = 0, n_out = 0;
    TRY(jprom_fe_model_n_dof(fe, &n_dof));
    TRY(jprom_fe_model_node_set(fe, "tip", NULL, 0, &n_tip));
    TRY(jprom_fe_model_node_set(fe, "OUT", NULL, 0, &n_out));
    int64_t tip[256], out_nodes[16], load = 0;
    if (n_tip > 256 || n_out > 16) return fail(JPROM_BAD_SIZE, "node sets");
    TRY(jprom_fe_model_node_set(fe, "TIP", tip, 256, NULL));
    TRY(jprom_fe_model_node_set(fe, "OUT", out_nodes, 16, NULL));
    TRY(jprom_fe_model_node_set(fe, "LOAD", &load, 1, NULL));
    /* the casing is beyond the tip along x: normal x, tangents y and z */
    const double frame[9] = {0, 1, 0, 0, 0, 1, 1, 0, 0};
    for (size_t i = 0; i < n_tip; ++i) TRY(jprom_fe_model_add_contact(fe, tip[i], frame, kt, kt, kn, mu, n0));
    const double f_y[3] = {0.0, 1.0, 0.0};
    TRY(jprom_fe_model_add_force(fe, load, 1, f_y));
    for (size_t i = 0; i < n_out; ++i) TRY(jprom_fe_model_add_output(fe, out_nodes[i], 1));

    jprom_model *model = NULL;
    TRY(jprom_fe_model_reduce(fe, cb_modes, &model));
    jprom_fe_model_free(fe);
    size_t n_red = 0;
    TRY(jprom_model_n_dof(model, &n_red));
    TRY(jprom_model_set_rayleigh_damping(model, 0.0, beta));
    TRY(jprom_model_set_dynamic_scale(model, scale));

    jprom_hbm_options opts;
    jprom_sweep_options band;
    jprom_jp_options jo;
    TRY(jprom_hbm_options_default(&opts));
    TRY(jprom_sweep_options_default(&band));
    TRY(jprom_jp_options_default(&jo));
    band.omega_start = lo;
    band.omega_end = hi;
    jprom_sweep_result *sweep = NULL;
    TRY(jprom_rom_sweep_adaptive(model, JPROM_ROM_NLR, &opts, &band, &jo, NULL, NULL, &sweep, NULL));
    size_t n = 0, n_corr = 0;
    jprom_sweep_end reason;
    TRY(jprom_sweep_result_n_points(sweep, &n));
    TRY(jprom_sweep_result_n_corrections(sweep, &n_corr));
    TRY(jprom_sweep_result_end_reason(sweep, &reason));
    printf("# FE %zu DoFs, %zu tip contacts, reduced to %zu DoFs; %zu points, %zu corrections, end %s\n", n_dof, n_tip, n_red, n, n_corr,
           jprom_sweep_end_name((int)reason));
    jprom_correction_end cend;
    double judged;
    TRY(jprom_sweep_result_correction_end(sweep, &cend, &judged));
    printf("# corrections end %d %.17e\n", (int)cend, judged);
    for (size_t i = 0; i < n; ++i) {
        double w, x1, e1;
        TRY(jprom_sweep_result_point_omega(sweep, i, &w));
        TRY(jprom_sweep_result_point_amplitude(sweep, i, 1, 0, &x1));
        TRY(jprom_sweep_result_point_predicted_error(sweep, i, 1, &e1));
        printf("%.17e %.17e %.17e\n", w, x1, e1);
    }
    jprom_sweep_result_free(sweep);
    jprom_model_free(model);
    return 0;
}
