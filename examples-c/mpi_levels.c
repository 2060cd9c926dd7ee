/*
 * jprom from an MPI program: excitation levels shared out over the ranks of MPI_COMM_WORLD.
 *
 * Rank 0 builds the model of sweep_example.c (two nodes, one 3D friction contact), predicts
 * its JP basis once, and saves both as versioned JSON in DIR (argument 1, default
 * `mpi_levels_files`, a folder every rank can read). After a barrier every rank loads the
 * model and the basis and sweeps its share of the levels (level i on rank i mod size): the
 * full-order sweep and the NLR sweep on the shared basis, each level scaling the harmonic
 * force (`jprom_model_set_dynamic_scale`). Rank 0 gathers one row per level with MPI_Gather and
 * prints the table in level order; with one rank the table is the same, byte for byte (each
 * sweep is deterministic and runs on its own handles).
 *
 * Outside its handles jprom keeps only the thread-local error message, the process-wide memory
 * budget (jprom_set_memory_budget) and the live-handle count, so each rank (a process of its
 * own), and each thread of a rank, may call it with its own handles.
 *
 * Build and run (from the repository root, after `cargo build --lib`; mpicc from OpenMPI or
 * MPICH):
 *   mpicc -Wall -Werror -std=c11 -Iinclude examples-c/mpi_levels.c \
 *       -Ltarget/debug -ljprom -Wl,-rpath,$PWD/target/debug -lm -o mpi_levels
 *   mpirun -np 2 ./mpi_levels /tmp/mpi_levels_files
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <mpi.h>
#include "jprom.h"

#define N 6        /* DoFs: node 0 (x, y, z) then node 1 (x, y, z) */
#define N_LEVELS 6 /* harmonic force scales below */
#define N_COLS 8   /* level index, scale, FO points, FO peak omega, FO peak |X1|, NLR points, NLR peak |X1|, max e*_1 */

static const double scales[N_LEVELS] = {0.5, 1.0, 1.5, 2.0, 3.0, 4.0};

static int check(jprom_status s, const char *what, int rank) {
    if (s != JPROM_OK) {
        fprintf(stderr, "rank %d: %s failed: %s: %s\n", rank, what, jprom_status_name((int)s), jprom_last_error_message());
        return 1;
    }
    return 0;
}

/* The model of sweep_example.c: springs 1e4 from ground to node 0 and from node 0 to node 1, a
 * 3D friction contact pressing node 1 against ground, excited along x at node 0. */
static int build_model(jprom_model **out, int rank) {
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
    if (check(jprom_model_new(N, mass, stiffness, &model), "jprom_model_new", rank)) return 1;
    const size_t node1[3] = {3, 4, 5};
    const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double f1_cos[N] = {5.0, 0, 0, 0, 0, 0}, f1_sin[N] = {0};
    const size_t outputs[2] = {0, 3};
    if (check(jprom_model_add_contact_3d(model, node1, NULL, frame, 3.0e4, 3.0e4, 5.0e4, 0.5, 20.0), "add contact", rank)
        || check(jprom_model_set_rayleigh_damping(model, 0.0, 1.0e-4), "damping", rank)
        || check(jprom_model_set_harmonic_force(model, 1, f1_cos, f1_sin, N), "harmonic force", rank)
        || check(jprom_model_set_output_dofs(model, outputs, 2), "outputs", rank)) {
        jprom_model_free(model);
        return 1;
    }
    *out = model;
    return 0;
}

/* Largest |X1| at output 0 of a sweep (and its frequency), its point count, and for a reduced
 * sweep the largest e*_1. */
static int sweep_peak(const jprom_sweep_result *s, int reduced, double *n_points, double *omega_peak, double *x1_peak, double *e_max, int rank) {
    size_t n = 0;
    if (check(jprom_sweep_result_n_points(s, &n), "jprom_sweep_result_n_points", rank)) return 1;
    *n_points = (double)n;
    *omega_peak = 0.0;
    *x1_peak = 0.0;
    *e_max = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double omega, x1, e1 = 0.0;
        if (check(jprom_sweep_result_point_omega(s, i, &omega), "omega", rank) || check(jprom_sweep_result_point_amplitude(s, i, 1, 0, &x1), "amplitude", rank)) return 1;
        if (reduced && check(jprom_sweep_result_point_predicted_error(s, i, 1, &e1), "predicted error", rank)) return 1;
        if (x1 > *x1_peak) {
            *x1_peak = x1;
            *omega_peak = omega;
        }
        if (e1 > *e_max) *e_max = e1;
    }
    return 0;
}

/* One level: the full-order and the NLR sweeps of `model` scaled by `scale`. */
static int run_level(jprom_model *model, const jprom_basis *basis, int level, double row[N_COLS], int rank) {
    jprom_hbm_options opts;
    jprom_sweep_options sweep_opts;
    jprom_hbm_options_default(&opts);
    jprom_sweep_options_default(&sweep_opts);
    opts.harmonics = 3;
    sweep_opts.omega_start = 60.0;
    sweep_opts.omega_end = 160.0;
    row[0] = level;
    row[1] = scales[level];
    if (check(jprom_model_set_dynamic_scale(model, scales[level]), "jprom_model_set_dynamic_scale", rank)) return 1;
    jprom_sweep_result *fo = NULL, *rom = NULL;
    double unused;
    int bad = check(jprom_sweep(model, &opts, &sweep_opts, NULL, NULL, &fo), "jprom_sweep", rank)
           || sweep_peak(fo, 0, &row[2], &row[3], &row[4], &unused, rank)
           || check(jprom_rom_sweep(model, basis, JPROM_ROM_NLR, &opts, &sweep_opts, NULL, NULL, &rom), "jprom_rom_sweep", rank)
           || sweep_peak(rom, 1, &row[5], &unused, &row[6], &row[7], rank);
    jprom_sweep_result_free(fo);
    jprom_sweep_result_free(rom);
    return bad;
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    const char *dir = argc > 1 ? argv[1] : "mpi_levels_files";
    char model_path[4096], basis_path[4096];
    snprintf(model_path, sizeof model_path, "%s/model.json", dir);
    snprintf(basis_path, sizeof basis_path, "%s/basis.json", dir);

    /* rank 0: the shared inputs, once; the others wait for them (and for whether they exist) */
    int ok = 1;
    if (rank == 0) {
        jprom_model *model = NULL;
        jprom_basis *basis = NULL;
        jprom_hbm_options opts;
        jprom_jp_options jp_opts;
        jprom_hbm_options_default(&opts);
        jprom_jp_options_default(&jp_opts);
        opts.harmonics = 3;
        mkdir(dir, 0777); /* may exist */
        ok = !build_model(&model, rank)
          && !check(jprom_basis_predict_opts(model, &opts, &jp_opts, 60.0, 160.0, &basis), "jprom_basis_predict_opts", rank)
          && !check(jprom_model_save_json(model, model_path), "jprom_model_save_json", rank)
          && !check(jprom_basis_save_json(basis, basis_path), "jprom_basis_save_json", rank);
        jprom_basis_free(basis);
        jprom_model_free(model);
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) {
        MPI_Finalize();
        return 1;
    }

    /* every rank: its own handles, its share of the levels */
    jprom_model *model = NULL;
    jprom_basis *basis = NULL;
    int per_rank = (N_LEVELS + size - 1) / size;
    double *mine = malloc(sizeof(double) * (size_t)per_rank * N_COLS);
    for (int k = 0; k < per_rank * N_COLS; ++k) mine[k] = -1.0; /* level index -1: an empty slot */
    int bad = check(jprom_model_load_json(model_path, &model), "jprom_model_load_json", rank)
           || check(jprom_basis_load_json(basis_path, &basis), "jprom_basis_load_json", rank);
    for (int level = rank, slot = 0; !bad && level < N_LEVELS; level += size, ++slot) {
        bad = run_level(model, basis, level, &mine[slot * N_COLS], rank);
    }
    jprom_basis_free(basis);
    jprom_model_free(model);

    /* rank 0 gathers every rank's rows (and whether it failed) and prints them in level order */
    double *all = rank == 0 ? malloc(sizeof(double) * (size_t)size * per_rank * N_COLS) : NULL;
    int *failed = rank == 0 ? malloc(sizeof(int) * (size_t)size) : NULL;
    MPI_Gather(mine, per_rank * N_COLS, MPI_DOUBLE, all, per_rank * N_COLS, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    MPI_Gather(&bad, 1, MPI_INT, failed, 1, MPI_INT, 0, MPI_COMM_WORLD);
    int status = 0;
    if (rank == 0) {
        for (int r = 0; r < size; ++r) {
            if (failed[r]) {
                fprintf(stderr, "rank %d failed (its message above)\n", r);
                status = 1;
            }
        }
        printf("# jprom %s: %d levels, full order and NLR on one shared basis, H = 3\n", jprom_version(), N_LEVELS);
        printf("# level scale fo_points fo_peak_omega fo_peak_x1 nlr_points nlr_peak_x1 nlr_max_e_star_1\n");
        for (int level = 0; level < N_LEVELS; ++level) {
            const double *row = NULL;
            for (int k = 0; k < size * per_rank; ++k) {
                if (all[k * N_COLS] == (double)level) row = &all[k * N_COLS];
            }
            if (!row) {
                printf("%d missing\n", level);
                status = 1;
                continue;
            }
            printf("%d %.3f %.0f %.10e %.10e %.0f %.10e %.4e\n", level, row[1], row[2], row[3], row[4], row[5], row[6], row[7]);
        }
    }
    free(mine);
    free(all);
    free(failed);
    MPI_Finalize();
    return status;
}
