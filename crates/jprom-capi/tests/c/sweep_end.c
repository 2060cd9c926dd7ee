/* A sweep forced to stall (max_iterations = 1 and min_step = max_step: the band starts in stick,
 * where one Newton step is exact, and the corrector cannot follow the contact into slip)
 * reports why it ended:
 * prints "end <name>: <text>" for a normal and for the forced sweep; exits 1 unless the normal
 * sweep reached the end and the forced one stalled with a reason in words. */
#include <stdio.h>
#include <string.h>
#include "jprom.h"
#include "two_node_model.h"



/* Sweeps with max_iterations = iterations; returns the end reason, or -1 on failure. */
static int sweep_end(jprom_model *model, size_t iterations) {
    jprom_hbm_options opts;
    jprom_sweep_options band;
    jprom_hbm_options_default(&opts);
    jprom_sweep_options_default(&band);
    opts.max_iterations = iterations;
    if (iterations == 1) band.min_step = band.initial_step = band.max_step = 0.05;
    band.omega_start = 60.0;
    band.omega_end = 160.0;
    jprom_sweep_result *sweep = NULL;
    if (jprom_sweep(model, &opts, &band, NULL, NULL, &sweep) != JPROM_OK) {
        fprintf(stderr, "sweep: %s\n", jprom_last_error_message());
        return -1;
    }
    jprom_sweep_end reason;
    char text[512];
    size_t written = 0;
    int reached = -1;
    if (jprom_sweep_result_end_reason(sweep, &reason) != JPROM_OK || jprom_sweep_result_reached_end(sweep, &reached) != JPROM_OK
        || jprom_sweep_result_failure_copy(sweep, text, sizeof text, &written) != JPROM_OK) {
        fprintf(stderr, "accessors: %s\n", jprom_last_error_message());
        jprom_sweep_result_free(sweep);
        return -1;
    }
    printf("end %s: %s\n", jprom_sweep_end_name((int)reason), text);
    /* the reason agrees with reached_end, and an early end has its words */
    int consistent = (reason == JPROM_SWEEP_REACHED_END) == (reached == 1) && (reason == JPROM_SWEEP_REACHED_END) == (written == 0);
    jprom_sweep_result_free(sweep);
    return consistent ? (int)reason : -1;
}

int main(void) {
    jprom_model *model = two_node_model(1.0);
    if (!model) return 1;
    int normal = sweep_end(model, 400);
    int forced = sweep_end(model, 1);
    jprom_model_free(model);
    if (normal != JPROM_SWEEP_REACHED_END || forced != JPROM_SWEEP_STALLED) {
        printf("FAIL normal %d forced %d\n", normal, forced);
        return 1;
    }
    printf("ok\n");
    return 0;
}
