/* The two-node model of the C test programs (sweep_end.c, abi_sizes.c): node 0 (DoFs 0-2) on a
 * spring to ground and to node 1 (DoFs 3-5), node 1 against ground through a 3D friction
 * contact closed by a preload of 20, Rayleigh damping beta = 1e-4, a first-harmonic force
 * `force` along x at node 0, outputs DoFs 0 and 3. NULL (with the message on stderr) on failure. */
#ifndef JPROM_TEST_TWO_NODE_MODEL_H
#define JPROM_TEST_TWO_NODE_MODEL_H
#include <stdio.h>
#include "jprom.h"

static jprom_model *two_node_model(double force) {
    enum { N = 6 };
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
    const size_t node1[3] = {3, 4, 5}, outputs[2] = {0, 3};
    const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double f1_cos[N] = {force, 0, 0, 0, 0, 0}, f1_sin[N] = {0};
    if (jprom_model_new(N, mass, stiffness, &model) != JPROM_OK
        || jprom_model_add_contact_3d(model, node1, NULL, frame, 3.0e4, 3.0e4, 5.0e4, 0.5, 20.0) != JPROM_OK
        || jprom_model_set_rayleigh_damping(model, 0.0, 1.0e-4) != JPROM_OK
        || jprom_model_set_harmonic_force(model, 1, f1_cos, f1_sin, N) != JPROM_OK
        || jprom_model_set_output_dofs(model, outputs, 2) != JPROM_OK) {
        fprintf(stderr, "model: %s\n", jprom_last_error_message());
        jprom_model_free(model);
        return NULL;
    }
    return model;
}
#endif
