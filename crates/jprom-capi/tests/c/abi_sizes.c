/* The options structs grow (ABI policy): a caller of version 1 of jprom_sweep_options, which
 * ends at max_points, passes struct_size = JPROM_SWEEP_OPTIONS_V1_SIZE and gets the same sweep
 * as one that fills the whole struct with the defaults; a struct_size that is no released
 * version's is JPROM_BAD_SIZE with nothing written. Prints "ok" and exits 0 when all hold. */
#include <stdio.h>
#include <string.h>
#include "jprom.h"
#include "two_node_model.h"


/* jprom_sweep_options as jprom 0.1 declared it */
typedef struct {
    size_t struct_size;
    double omega_start, omega_end, initial_step, min_step, max_step;
    size_t max_points;
} sweep_options_v1;

_Static_assert(sizeof(sweep_options_v1) == JPROM_SWEEP_OPTIONS_V1_SIZE, "version 1 size");

static int failures = 0;
#define CHECK(cond, ...) do { if (!(cond)) { printf("FAIL: " __VA_ARGS__); printf("\n"); ++failures; } } while (0)


/* Last point's omega and X1 at output 0, and the point count, of a sweep with `band`. */
static jprom_status sweep_summary(jprom_model *model, const jprom_sweep_options *band, size_t *n, double *omega, double *x1) {
    jprom_hbm_options opts;
    jprom_hbm_options_default(&opts);
    jprom_sweep_result *sweep = NULL;
    jprom_status s = jprom_sweep(model, &opts, band, NULL, NULL, &sweep);
    if (s != JPROM_OK) {
        CHECK(sweep == NULL, "*out written on failure");
        return s;
    }
    jprom_sweep_result_n_points(sweep, n);
    jprom_sweep_result_point_omega(sweep, *n - 1, omega);
    jprom_sweep_result_point_amplitude(sweep, *n - 1, 1, 0, x1);
    jprom_sweep_result_free(sweep);
    return s;
}

int main(void) {
    jprom_model *model = two_node_model(5.0);
    if (!model) return 1;

    jprom_sweep_options full;
    jprom_sweep_options_default(&full);
    full.omega_start = 60.0;
    full.omega_end = 160.0;
    CHECK(full.struct_size == sizeof(jprom_sweep_options) && sizeof(jprom_sweep_options) > JPROM_SWEEP_OPTIONS_V1_SIZE,
          "the current struct is larger than version 1");

    /* a version-1 caller: its own 56-byte struct, filled field by field */
    sweep_options_v1 v1 = {JPROM_SWEEP_OPTIONS_V1_SIZE, full.omega_start, full.omega_end, full.initial_step,
                           full.min_step, full.max_step, full.max_points};
    size_t n_full = 0, n_v1 = 0;
    double w_full = 0, w_v1 = 0, x_full = 0, x_v1 = 0;
    CHECK(sweep_summary(model, &full, &n_full, &w_full, &x_full) == JPROM_OK, "full-size sweep: %s", jprom_last_error_message());
    CHECK(sweep_summary(model, (const jprom_sweep_options *)&v1, &n_v1, &w_v1, &x_v1) == JPROM_OK,
          "version-1 sweep: %s", jprom_last_error_message());
    CHECK(n_full > 10 && n_full == n_v1 && w_full == w_v1 && x_full == x_v1,
          "version 1 and full-size sweeps differ: %zu/%zu points, omega %g/%g, X1 %g/%g", n_full, n_v1, w_full, w_v1, x_full, x_v1);
    printf("version-1 and current jprom_sweep_options: %zu points each, same last point (omega %.6f, X1 %.6e)\n", n_v1, w_v1, x_v1);

    /* a new field changes the sweep only for callers that know it */
    jprom_sweep_options coarse = full;
    coarse.max_omega_step = 0.2;
    coarse.max_angle = 0.6;
    size_t n_coarse = 0;
    double w_c = 0, x_c = 0;
    CHECK(sweep_summary(model, &coarse, &n_coarse, &w_c, &x_c) == JPROM_OK, "coarse sweep: %s", jprom_last_error_message());
    CHECK(n_coarse < n_full, "version-2 fields have no effect: %zu vs %zu points", n_coarse, n_full);

    /* the default functions: the symbol jprom_sweep_options_default writes version 1 only (an
     * old caller's struct is that small), _init writes the size it is given */
    jprom_sweep_options probe;
    memset(&probe, 0x7f, sizeof probe);
    double sentinel = probe.max_angle;
    CHECK((jprom_sweep_options_default)(&probe) == JPROM_OK && probe.struct_size == JPROM_SWEEP_OPTIONS_V1_SIZE
              && probe.max_points == full.max_points && probe.max_angle == sentinel && probe.max_omega_step == sentinel,
          "the exported jprom_sweep_options_default writes exactly version 1");
    memset(&probe, 0x7f, sizeof probe);
    CHECK(jprom_sweep_options_init(&probe, sizeof probe) == JPROM_OK && probe.struct_size == sizeof probe
              && probe.max_angle == full.max_angle && probe.max_omega_step == full.max_omega_step,
          "jprom_sweep_options_init(sizeof) writes every field");
    CHECK(jprom_sweep_options_init(&probe, 12) == JPROM_BAD_SIZE, "jprom_sweep_options_init with a size of no version");
    CHECK(full.max_angle > 0.0 && full.max_omega_step > 0.0, "the macro jprom_sweep_options_default fills the version-2 fields");

    /* sizes of no released version */
    const size_t bad[] = {0, 8, JPROM_SWEEP_OPTIONS_V1_SIZE - 8, JPROM_SWEEP_OPTIONS_V1_SIZE + 8, sizeof(jprom_sweep_options) + 8};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        jprom_sweep_options b = full;
        b.struct_size = bad[i];
        size_t n = 0;
        double w = 0, x = 0;
        jprom_status s = sweep_summary(model, &b, &n, &w, &x);
        CHECK(s == JPROM_BAD_SIZE && strstr(jprom_last_error_message(), "struct_size") != NULL,
              "struct_size %zu: %s (%s)", bad[i], jprom_status_name((int)s), jprom_last_error_message());
    }
    jprom_model_free(model);
    if (failures) return 1;
    printf("ok\n");
    return 0;
}
