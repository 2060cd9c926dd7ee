/* Seeded random-call harness over the C API (issue 12): N calls of randomly chosen jprom
 * functions with random and hostile arguments -- NULLs, freed handles, handles of another kind,
 * garbage pointers, sizes of 0, SIZE_MAX, 2^40, NaN and infinite values, negative values,
 * edited and truncated files, /dev/full -- mixed with valid calls on small models, so that the
 * valid paths (solves, sweeps, bases, files) are exercised from the odd states the hostile
 * calls leave behind.
 *
 * Asserted on every call: the status is one of the documented codes and never JPROM_PANIC; a
 * failure comes with a message and leaves the out-parameter unwritten; a success leaves no
 * message. A crash or a hang fails the run from outside (the caller runs it under `timeout`).
 *
 * The harness never lies about a buffer: a non-NULL array is always at least as long as the
 * length passed with it (the library cannot check that, by the C API's contract); hostile
 * lengths come with NULL or with buffers that are long enough.
 *
 * Usage: api_fuzz CALLS SEED SCRATCH_DIR. Prints a summary; exits 1 on any violation. On
 * SIGTERM (the caller's timeout) it prints the number of calls done and the last that
 * returned, so that a stall names the call after it. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <signal.h>
#include <unistd.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
/* calls the deprecated functions too: they stay in the ABI and must keep working */
#define JPROM_NO_DEPRECATION_WARNINGS
#include "jprom.h"

/* ------------------------------------------------------------------ random numbers */

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t rnd(void) { /* xorshift64* */
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return rng_state * 0x2545F4914F6CDD1Dull;
}
static size_t below(size_t n) { return n ? (size_t)(rnd() % n) : 0; }
static int chance(int percent) { return (int)below(100) < percent; }
static double uniform(double lo, double hi) { return lo + (hi - lo) * ((double)(rnd() >> 11) / 9007199254740992.0); }

/* a size: mostly small, sometimes hostile */
static size_t rsize(void) {
    static const size_t hostile[] = {0, 1, 2, 3, 6, 7, 64, 65, 10000, (size_t)1 << 22, (size_t)1 << 32, (size_t)1 << 40,
                                     SIZE_MAX / 2, SIZE_MAX - 1, SIZE_MAX};
    return chance(70) ? below(8) : hostile[below(sizeof hostile / sizeof *hostile)];
}
/* a double: mostly ordinary, sometimes hostile */
static double rdouble(void) {
    static const double hostile[] = {0.0, -0.0, -1.0, 1.0, 1e-320, -1e-320, 1e308, -1e308, 1e-9, 1e9};
    int k = (int)below(10);
    if (k < 5) return uniform(-2.0, 2.0) * pow(10.0, (double)below(9) - 4.0);
    if (k < 6) return NAN;
    if (k < 7) return chance(50) ? INFINITY : -INFINITY;
    return hostile[below(sizeof hostile / sizeof *hostile)];
}
/* a frequency: mostly in the small models' range (60..160 rad/s) */
static double romega(void) { return chance(85) ? uniform(50.0, 170.0) : rdouble(); }

/* ------------------------------------------------------------------ checks and counts */

static long calls = 0, by_status[16] = {0}, violations = 0;

static void violation(const char *fn, const char *what) {
    printf("VIOLATION in %s (call %ld): %s (message: '%s')\n", fn, calls, what, jprom_last_error_message());
    violations++;
}

/* The last call that returned and the last that started, with the options of the last
 * costly call (for the SIGTERM report of a stall). */
static const char *volatile last_returned = "(none)";
static const char *volatile last_started = "(none)";
static char last_options[512] = "";

static void on_term(int sig) {
    (void)sig;
    char line[1024];
    int len = snprintf(line, sizeof line, "api_fuzz: stopped after %ld calls; the last that returned: %s; the last that started: %s; the last costly call's options: %s\n",
                       calls, last_returned, last_started, last_options);
    if (len > 0) {
        ssize_t w = write(STDOUT_FILENO, line, (size_t)len < sizeof line ? (size_t)len : sizeof line - 1);
        (void)w;
    }
    _exit(124);
}

/* Checks one call's status and message; returns the status. `seen(fn, call)` names the call
 * as started before its arguments are evaluated. */
static jprom_status seen_(const char *fn, jprom_status s) {
    last_returned = fn;
    calls++;
    int code = (int)s;
    if (code < 0 || code > 11) {
        violation(fn, "status outside the documented codes");
        return s;
    }
    by_status[code]++;
    const char *msg = jprom_last_error_message();
    if (s == JPROM_PANIC) violation(fn, "JPROM_PANIC");
    if (s != JPROM_OK && msg[0] == '\0') violation(fn, "a failure without a message");
    if (s == JPROM_OK && msg[0] != '\0') violation(fn, "a success with a stale message");
    return s;
}

#define seen(fn, call) (last_started = (fn), seen_((fn), (call)))

/* ------------------------------------------------------------------ handle pools */

enum { POOL = 24, DEAD = 64 };
static jprom_model *models[POOL];
static jprom_solution *solutions[POOL];
static jprom_sweep_result *sweeps[POOL];
static jprom_basis *bases[POOL];
static void *dead[DEAD]; /* freed handles of any kind */
static size_t n_dead = 0;

static void bury(void *p) {
    if (p) dead[n_dead++ % DEAD] = p;
}

/* A pointer for a handle argument of kind `pool`: usually a live one, else NULL, a freed
 * one, one of another kind or garbage. */
static void *pick(void **pool) {
    int k = (int)below(100);
    if (k < 80) return pool[below(POOL)]; /* may be NULL */
    if (k < 85) return NULL;
    if (k < 92) return n_dead ? dead[below(n_dead < DEAD ? n_dead : DEAD)] : NULL;
    if (k < 97) {
        void **other[] = {(void **)models, (void **)solutions, (void **)sweeps, (void **)bases};
        return other[below(4)][below(POOL)];
    }
    static double not_a_handle[8];
    return chance(50) ? (void *)not_a_handle : (void *)(uintptr_t)(0x1000 + 8 * below(512));
}
#define PICK_MODEL() ((jprom_model *)pick((void **)models))
#define PICK_SOLUTION() ((jprom_solution *)pick((void **)solutions))
#define PICK_SWEEP() ((jprom_sweep_result *)pick((void **)sweeps))
#define PICK_BASIS() ((jprom_basis *)pick((void **)bases))

/* Puts a new handle into a slot, freeing (and burying) the one it replaces. */
#define ADOPT(pool, freefn, h)                       \
    do {                                             \
        size_t slot_ = below(POOL);                  \
        if ((pool)[slot_]) {                         \
            seen(#freefn, freefn((pool)[slot_]));    \
            bury((pool)[slot_]);                     \
        }                                            \
        (pool)[slot_] = (h);                         \
    } while (0)

/* ------------------------------------------------------------------ small valid models */

/* n_nodes nodes in a chain of springs (3 DoFs each), the last against ground by a 3D
 * friction contact (or a Jenkins element, or nothing), forced at node 0. */
static jprom_model *chain(size_t n_nodes, int contact) {
    size_t n = 3 * n_nodes;
    double m[12 * 12] = {0}, k[12 * 12] = {0}, fc[12] = {0}, f0[12] = {0};
    for (size_t i = 0; i < n; ++i) {
        m[i + i * n] = 1.0;
        k[i + i * n] = (i + 3 < n) ? 2.0e4 : 2.0e4;
        if (i + 3 < n) {
            k[i + (i + 3) * n] = -1.0e4;
            k[(i + 3) + i * n] = -1.0e4;
        }
    }
    fc[0] = 5.0;
    f0[n - 1] = 1.0;
    jprom_model *model = NULL;
    if (seen("jprom_model_new", jprom_model_new(n, m, k, &model)) != JPROM_OK) return NULL;
    const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    size_t last[3] = {n - 3, n - 2, n - 1}, outs[2] = {0, n - 3};
    if (contact == 1) seen("jprom_model_add_contact_3d", jprom_model_add_contact_3d(model, last, NULL, frame, 3e4, 3e4, 5e4, 0.5, 20.0));
    if (contact == 2) seen("jprom_model_add_jenkins", jprom_model_add_jenkins(model, n - 3, NULL, 3e4, 0.5, 20.0));
    seen("jprom_model_set_rayleigh_damping", jprom_model_set_rayleigh_damping(model, 0.0, 1e-4));
    seen("jprom_model_set_harmonic_force", jprom_model_set_harmonic_force(model, 1, fc, NULL, n));
    seen("jprom_model_set_static_force", jprom_model_set_static_force(model, f0, n));
    seen("jprom_model_set_output_dofs", jprom_model_set_output_dofs(model, outs, 2));
    return model;
}

/* ------------------------------------------------------------------ options */

/* `large`: a legal but costly H = 64 may come out (point solves only) */
static jprom_hbm_options hbm_opts(int large) {
    jprom_hbm_options o;
    jprom_hbm_options_default(&o);
    if (chance(85)) { /* sane and cheap */
        o.harmonics = 1 + below(3);
        static const size_t nts[] = {0, 0, 16, 32, 64};
        o.nt = nts[below(5)];
        o.max_iterations = 1 + below(50);
        o.condensed = (int)below(2);
        if (o.nt != 0 && o.nt < 4 * (o.harmonics + 1)) o.nt = 0;
    } else { /* hostile */
        int k = (int)below(7);
        if (k == 0) o.harmonics = rsize();
        if (k == 1) o.nt = rsize();
        if (k == 2) o.residual_tolerance = rdouble();
        if (k == 3) o.max_iterations = chance(50) ? 0 : 1 + below(5);
        if (k == 4) o.struct_size = rsize();
        if (k == 5) o.condensed = (int)rnd();
        if (k == 6 && large) { o.harmonics = 64; o.nt = 0; o.max_iterations = 3; } /* legal, large */
    }
    return o;
}

static jprom_sweep_options sweep_opts(void) {
    jprom_sweep_options o;
    jprom_sweep_options_default(&o);
    o.omega_start = 60.0 + uniform(0.0, 20.0);
    o.omega_end = 120.0 + uniform(0.0, 40.0);
    if (chance(20)) { double t = o.omega_start; o.omega_start = o.omega_end; o.omega_end = t; }
    o.max_points = 2 + below(12);
    if (chance(12)) {
        int k = (int)below(8);
        if (k == 0) o.omega_start = rdouble();
        if (k == 1) o.omega_end = rdouble();
        if (k == 2) o.initial_step = rdouble();
        if (k == 3) o.min_step = rdouble();
        if (k == 4) o.max_step = rdouble();
        if (k == 5) o.max_points = rsize();
        if (k == 6) o.struct_size = rsize();
        if (k == 7) o.omega_end = o.omega_start;
    }
    return o;
}

static jprom_jp_options jp_opts(void) {
    jprom_jp_options o;
    jprom_jp_options_default(&o);
    o.n_samples = 1 + below(12);
    o.max_corrections = below(3); /* SIZE_MAX is issue 12's open continuation item, not fuzzed here */
    if (chance(15)) {
        int k = (int)below(14);
        if (k == 0) o.gamma = rdouble();
        if (k == 1) o.n_samples = rsize();
        if (k == 2) o.extra_outside = rsize();
        if (k == 3) o.static_correction = (int)rnd();
        if (k == 4) o.threshold = rdouble();
        if (k == 5) o.gamma_growth = rdouble();
        if (k == 6) o.max_gamma = rdouble();
        if (k == 7) o.struct_size = rsize();
        if (k == 8) o.threshold = 1e-300;
        if (k == 9) o.slipping = chance(50) ? (int)below(3) : (int)rnd();
        if (k == 10) o.regeneration_samples = chance(50) ? below(4) : rsize();
        if (k == 11) o.screen = (int)rnd();
        if (k == 12) o.verify = (int)rnd();
        if (k == 13) o.response_output = chance(50) ? below(4) : rsize();
    }
    return o;
}

/* Records a costly call's options for the SIGTERM report. */
static void note_options(const jprom_hbm_options *o, const jprom_sweep_options *so, const jprom_jp_options *jo) {
    snprintf(last_options, sizeof last_options,
             "H %zu nt %zu max_iterations %zu condensed %d; band %g..%g max_points %zu; gamma %g n_samples %zu extra_outside %zu threshold %g max_corrections %zu gamma_growth %g max_gamma %g slipping %d regeneration_samples %zu screen %d verify %d response_output %zu",
             o->harmonics, o->nt, o->max_iterations, o->condensed, so ? so->omega_start : 0.0, so ? so->omega_end : 0.0, so ? so->max_points : 0,
             jo->gamma, jo->n_samples, jo->extra_outside, jo->threshold, jo->max_corrections, jo->gamma_growth, jo->max_gamma, jo->slipping, jo->regeneration_samples, jo->screen, jo->verify, jo->response_output);
}

/* ------------------------------------------------------------------ callbacks */

static int cb_stop_at = -1;
static int progress(void *user, size_t index, double omega, const double *amps, size_t n) {
    (void)user; (void)omega;
    volatile double sink = 0.0;
    for (size_t j = 0; j < n; ++j) sink += amps[j];
    (void)sink;
    size_t dofs;
    if (chance(30)) jprom_model_n_dof(NULL, &dofs); /* a failing nested call */
    if (chance(10)) jprom_status_name((int)below(20));
    return cb_stop_at >= 0 && (int)index >= cb_stop_at;
}
static jprom_progress_fn rcallback(void) {
    cb_stop_at = chance(30) ? (int)below(5) : -1;
    return chance(70) ? progress : NULL;
}

/* ------------------------------------------------------------------ files */

static char scratch[3000];
static char file_name[4096];
static const char *rpath(void) {
    int k = (int)below(100);
    if (k < 70) snprintf(file_name, sizeof file_name, "%s/f%zu.json", scratch, below(6));
    else if (k < 78) snprintf(file_name, sizeof file_name, "/dev/full");
    else if (k < 84) snprintf(file_name, sizeof file_name, "%s", scratch);
    else if (k < 90) snprintf(file_name, sizeof file_name, "%s/no/such/dir/x.json", scratch);
    else if (k < 94) return NULL;
    else if (k < 97) return "";
    else snprintf(file_name, sizeof file_name, "%s/\xff\xfe.json", scratch);
    return file_name;
}

/* Edits a scratch file: a digit changed, bytes cut off, or a key renamed. */
static void corrupt_a_file(void) {
    char p[4096];
    snprintf(p, sizeof p, "%s/f%zu.json", scratch, below(6));
    FILE *f = fopen(p, "rb");
    if (!f) return;
    static char buf[1 << 20];
    size_t len = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    if (len == 0) return;
    int k = (int)below(4);
    if (k == 0 || k == 1) { /* change a digit (keeps the JSON valid: an edited size or value) */
        for (int tries = 0; tries < 64; ++tries) {
            size_t at = below(len);
            if (buf[at] >= '0' && buf[at] <= '9') { buf[at] = (char)('0' + below(10)); break; }
        }
    } else if (k == 2) {
        len = below(len);
    } else { /* rename a key */
        char *q = strstr(buf, "\"n_outputs\"");
        if (!q) q = strstr(buf, "\"sizes\"");
        if (q) q[1] = 'X';
    }
    f = fopen(p, "wb");
    if (!f) return;
    fwrite(buf, 1, len, f);
    fclose(f);
}

/* ------------------------------------------------------------------ one random call */

static double dbuf[4096];
static size_t zbuf[4096];
static unsigned char ubuf[1 << 17];

/* a caller buffer of at least `len` doubles, or NULL */
static double *dbuf_for(size_t len) { return (len <= 4096 && chance(90)) ? dbuf : NULL; }

static void one_call(void) {
    jprom_model *m;
    jprom_solution *s;
    jprom_sweep_result *w;
    jprom_basis *b;
    jprom_status st;
    size_t n, len, idx, h, j;
    double x;
    int k = (int)below(1000);

    if (k < 30) { /* new valid model */
        m = chain(1 + below(4), (int)below(3));
        if (m) ADOPT(models, jprom_model_free, m);
    } else if (k < 50) { /* jprom_model_new with hostile sizes */
        n = chance(50) ? below(5) : rsize();
        int fits = n <= 64; /* n x n doubles fit in dbuf */
        if (fits) for (size_t i = 0; i < 4096; ++i) dbuf[i] = (i % (n + 1) == 0) ? 1.0 : 0.0; /* the identity */
        m = (jprom_model *)&x;
        st = seen("jprom_model_new", jprom_model_new(n, fits && chance(90) ? dbuf : NULL, fits && chance(90) ? dbuf : NULL, chance(95) ? &m : NULL));
        if (st == JPROM_OK) ADOPT(models, jprom_model_free, m);
        else if (m != (jprom_model *)&x) violation("jprom_model_new", "out written on failure");
    } else if (k < 60) { /* CSC */
        n = chance(60) ? 1 + below(4) : rsize();
        size_t cp[8] = {0}, nnz = 0;
        if (n <= 7) { for (size_t c = 0; c < n; ++c) { zbuf[nnz] = chance(95) ? c : rsize(); dbuf[nnz++] = 1.0 + c; cp[c + 1] = nnz; } }
        /* a corrupted column pointer, never the last one: colptr[n] is the entry count, and
           rowind/values are only that long */
        if (n >= 1 && n <= 7 && chance(10)) cp[below(n)] = rsize();
        m = NULL;
        const size_t *cpp = n <= 7 ? cp : NULL;
        st = seen("jprom_model_new_csc", jprom_model_new_csc(n, cpp, zbuf, dbuf, cpp, zbuf, dbuf, &m));
        if (st == JPROM_OK) ADOPT(models, jprom_model_free, m);
    } else if (k < 70) {
        m = NULL;
        st = seen("jprom_model_clone", jprom_model_clone(PICK_MODEL(), chance(95) ? &m : NULL));
        if (st == JPROM_OK) ADOPT(models, jprom_model_free, m);
    } else if (k < 90) {
        m = PICK_MODEL();
        seen("jprom_model_free", jprom_model_free(m));
        for (size_t i = 0; i < POOL; ++i) if (models[i] == m) { models[i] = NULL; bury(m); }
    } else if (k < 130) { /* model accessors */
        m = PICK_MODEL();
        size_t out;
        switch (below(5)) {
        case 0: seen("jprom_model_n_dof", jprom_model_n_dof(m, chance(95) ? &out : NULL)); break;
        case 1: seen("jprom_model_n_contacts", jprom_model_n_contacts(m, chance(95) ? &out : NULL)); break;
        case 2: seen("jprom_model_n_outputs", jprom_model_n_outputs(m, chance(95) ? &out : NULL)); break;
        case 3: seen("jprom_model_excitation_level", jprom_model_excitation_level(m, chance(95) ? &x : NULL)); break;
        default: seen("jprom_model_validate", jprom_model_validate(m));
        }
    } else if (k < 230) { /* model setters */
        m = PICK_MODEL();
        switch (below(9)) {
        case 0: seen("jprom_model_set_rayleigh_damping", jprom_model_set_rayleigh_damping(m, chance(50) ? 0.0 : rdouble(), chance(50) ? 1e-4 : rdouble())); break;
        case 1: seen("jprom_model_set_modal_damping", jprom_model_set_modal_damping(m, rdouble(), romega())); break;
        case 2: len = rsize(); for (size_t i = 0; i < 4096; ++i) dbuf[i] = chance(95) ? uniform(-1, 1) : rdouble();
                seen("jprom_model_set_static_force", jprom_model_set_static_force(m, dbuf_for(len), len)); break;
        case 3: len = chance(60) ? 3 * (1 + below(4)) : rsize(); h = chance(70) ? 1 + below(3) : rsize();
                for (size_t i = 0; i < 4096; ++i) dbuf[i] = chance(95) ? uniform(-5, 5) : rdouble();
                seen("jprom_model_set_harmonic_force", jprom_model_set_harmonic_force(m, h, dbuf_for(len), dbuf_for(len), len)); break;
        case 4: seen("jprom_model_set_dynamic_scale", jprom_model_set_dynamic_scale(m, chance(50) ? uniform(0.1, 2) : rdouble())); break;
        case 5: seen("jprom_model_set_excitation_level", jprom_model_set_excitation_level(m, chance(50) ? uniform(0.01, 10) : rdouble())); break;
        case 6: { size_t a[3], bb[3]; double fr[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
                  for (int i = 0; i < 3; ++i) { a[i] = chance(85) ? below(12) : rsize(); bb[i] = chance(85) ? below(12) : rsize(); }
                  if (chance(10)) fr[below(9)] = rdouble();
                  seen("jprom_model_add_contact_3d", jprom_model_add_contact_3d(m, chance(95) ? a : NULL, chance(70) ? NULL : bb, chance(95) ? fr : NULL,
                                                                               chance(80) ? 3e4 : rdouble(), chance(80) ? 3e4 : rdouble(), chance(80) ? 5e4 : rdouble(),
                                                                               chance(80) ? 0.5 : rdouble(), chance(80) ? 20.0 : rdouble()));
                  break; }
        case 7: { size_t bdof = below(12);
                  seen("jprom_model_add_jenkins", jprom_model_add_jenkins(m, chance(80) ? below(12) : rsize(), chance(70) ? NULL : &bdof,
                                                                         chance(80) ? 3e4 : rdouble(), chance(80) ? 0.5 : rdouble(), chance(80) ? 20.0 : rdouble()));
                  break; }
        default: len = chance(70) ? below(4) : rsize(); for (size_t i = 0; i < 4096; ++i) zbuf[i] = chance(90) ? below(12) : rsize();
                 seen("jprom_model_set_output_dofs", jprom_model_set_output_dofs(m, len <= 4096 && chance(90) ? zbuf : NULL, len));
        }
    } else if (k < 290) { /* solve a point */
        jprom_hbm_options o = hbm_opts(1);
        s = NULL;
        st = seen("jprom_solve_point", jprom_solve_point(PICK_MODEL(), romega(), chance(97) ? &o : NULL, chance(97) ? &s : NULL));
        if (st == JPROM_OK) ADOPT(solutions, jprom_solution_free, s);
        else if (s != NULL) violation("jprom_solve_point", "out written on failure");
    } else if (k < 296) { /* sweep */
        jprom_hbm_options o = hbm_opts(0);
        jprom_sweep_options so = sweep_opts();
        w = NULL;
        st = seen("jprom_sweep", jprom_sweep(PICK_MODEL(), chance(98) ? &o : NULL, chance(98) ? &so : NULL, rcallback(), NULL, chance(98) ? &w : NULL));
        if (st == JPROM_OK || (st == JPROM_CANCELLED && w)) ADOPT(sweeps, jprom_sweep_result_free, w);
        else if (w != NULL) violation("jprom_sweep", "out written on failure");
    } else if (k < 310) { /* basis prediction */
        jprom_hbm_options o = hbm_opts(0);
        jprom_jp_options jo = jp_opts();
        b = NULL;
        if (chance(50))
            st = seen("jprom_basis_predict", jprom_basis_predict(PICK_MODEL(), chance(98) ? &o : NULL, romega(), romega(), chance(80) ? 1e3 : rdouble(),
                                                                 chance(80) ? 1 + below(10) : rsize(), chance(98) ? &b : NULL));
        else
            st = seen("jprom_basis_predict_opts", jprom_basis_predict_opts(PICK_MODEL(), chance(98) ? &o : NULL, chance(98) ? &jo : NULL, romega(), romega(), chance(98) ? &b : NULL));
        if (st == JPROM_OK) ADOPT(bases, jprom_basis_free, b);
        else if (b != NULL) violation("jprom_basis_predict", "out written on failure");
    } else if (k < 316) { /* basis of a solution */
        jprom_hbm_options o = hbm_opts(0);
        jprom_jp_options jo = jp_opts();
        b = NULL;
        note_options(&o, NULL, &jo);
        st = seen("jprom_basis_from_solution", jprom_basis_from_solution(PICK_MODEL(), PICK_SOLUTION(), &o, &jo, romega(), romega(), &b));
        if (st == JPROM_OK) ADOPT(bases, jprom_basis_free, b);
    } else if (k < 321) { /* ROM sweep */
        jprom_hbm_options o = hbm_opts(0);
        jprom_sweep_options so = sweep_opts();
        w = NULL;
        st = seen("jprom_rom_sweep", jprom_rom_sweep(PICK_MODEL(), PICK_BASIS(), chance(90) ? (int)below(2) : (int)rnd(), &o, &so, rcallback(), NULL, &w));
        if (st == JPROM_OK || (st == JPROM_CANCELLED && w)) ADOPT(sweeps, jprom_sweep_result_free, w);
    } else if (k < 323) { /* self-correcting sweep */
        jprom_hbm_options o = hbm_opts(0);
        jprom_sweep_options so = sweep_opts();
        jprom_jp_options jo = jp_opts();
        w = NULL;
        b = NULL;
        note_options(&o, &so, &jo);
        st = seen("jprom_rom_sweep_adaptive", jprom_rom_sweep_adaptive(PICK_MODEL(), chance(90) ? (int)below(2) : (int)rnd(), &o, &so, &jo, rcallback(), NULL,
                                                                         chance(98) ? &w : NULL, chance(50) ? &b : NULL));
        if (st == JPROM_OK || (st == JPROM_CANCELLED && w)) {
            ADOPT(sweeps, jprom_sweep_result_free, w);
            if (b) ADOPT(bases, jprom_basis_free, b);
        }
    } else if (k < 330) { /* actual error */
        jprom_hbm_options o = hbm_opts(0);
        len = chance(80) ? 2 + below(4) : rsize();
        seen("jprom_rom_actual_error", jprom_rom_actual_error(PICK_MODEL(), PICK_BASIS(), (int)below(3), &o, PICK_SOLUTION(), PICK_SOLUTION(), dbuf_for(len), len));
    } else if (k < 480) { /* sweep accessors */
        w = PICK_SWEEP();
        idx = chance(80) ? below(16) : rsize();
        h = chance(80) ? below(4) : rsize();
        j = chance(80) ? below(3) : rsize();
        len = chance(80) ? below(64) : rsize();
        size_t out, out2;
        int iout;
        switch (below(15)) {
        case 0: seen("jprom_sweep_result_n_points", jprom_sweep_result_n_points(w, chance(95) ? &out : NULL)); break;
        case 1: seen("jprom_sweep_result_reached_end", jprom_sweep_result_reached_end(w, chance(95) ? &iout : NULL)); break;
        case 2: { char text[64]; size_t l = chance(80) ? below(64) : 0;
                  seen("jprom_sweep_result_failure_copy", jprom_sweep_result_failure_copy(w, chance(90) ? text : NULL, l, chance(50) ? &out : NULL)); break; }
        case 3: s = NULL;
                if (seen("jprom_sweep_result_point", jprom_sweep_result_point(w, idx, chance(95) ? &s : NULL)) == JPROM_OK) ADOPT(solutions, jprom_solution_free, s);
                break;
        case 4: seen("jprom_sweep_result_point_omega", jprom_sweep_result_point_omega(w, idx, chance(95) ? &x : NULL)); break;
        case 5: seen("jprom_sweep_result_point_amplitude", jprom_sweep_result_point_amplitude(w, idx, h, j, chance(95) ? &x : NULL)); break;
        case 6: seen("jprom_sweep_result_point_output_coeffs", jprom_sweep_result_point_output_coeffs(w, idx, dbuf_for(len), len)); break;
        case 7: seen("jprom_sweep_result_point_dissipated_energy", jprom_sweep_result_point_dissipated_energy(w, idx, dbuf_for(len), len)); break;
        case 8: seen("jprom_sweep_result_point_convergence", jprom_sweep_result_point_convergence(w, idx, chance(50) ? &out : NULL, chance(50) ? &x : NULL)); break;
        case 9: seen("jprom_sweep_result_point_predicted_error", jprom_sweep_result_point_predicted_error(w, idx, h, chance(95) ? &x : NULL)); break;
        case 10: seen("jprom_sweep_result_n_corrections", jprom_sweep_result_n_corrections(w, chance(95) ? &out : NULL)); break;
        case 11: { int kind; double v, b1, b2;
                   seen("jprom_sweep_result_correction", jprom_sweep_result_correction(w, chance(80) ? below(3) : rsize(), chance(50) ? &kind : NULL, chance(50) ? &v : NULL,
                                                                        chance(50) ? &b1 : NULL, chance(50) ? &b2 : NULL, len <= 4096 && chance(80) ? zbuf : NULL, len));
                   break; }
        case 12: seen("jprom_sweep_result_free", jprom_sweep_result_free(w));
                 for (size_t i = 0; i < POOL; ++i) if (sweeps[i] == w) { sweeps[i] = NULL; bury(w); }
                 break;
        case 13: { jprom_correction_end e; double judged;
                   seen("jprom_sweep_result_correction_end", jprom_sweep_result_correction_end(w, chance(50) ? &e : NULL, chance(50) ? &judged : NULL));
                   seen("jprom_sweep_result_static_error", jprom_sweep_result_static_error(w, chance(50) ? &judged : NULL));
                   seen("jprom_sweep_result_correction_swept", jprom_sweep_result_correction_swept(w, chance(80) ? below(3) : rsize(), chance(90) ? &iout : NULL));
                   (void)jprom_correction_end_name((int)below(8) - 2);
                   (void)jprom_correction_kind_name((int)below(8) - 2);
                   break; }
        default: seen("jprom_live_handle_count", jprom_live_handle_count(chance(95) ? &out2 : NULL));
        }
    } else if (k < 600) { /* solution accessors */
        s = PICK_SOLUTION();
        h = chance(80) ? below(4) : rsize();
        j = chance(80) ? below(3) : rsize();
        len = chance(80) ? below(64) : rsize();
        size_t a1, a2, a3;
        switch (below(10)) {
        case 0: seen("jprom_solution_omega", jprom_solution_omega(s, chance(95) ? &x : NULL)); break;
        case 1: seen("jprom_solution_sizes", jprom_solution_sizes(s, chance(70) ? &a1 : NULL, chance(70) ? &a2 : NULL, chance(70) ? &a3 : NULL)); break;
        case 2: seen("jprom_solution_output_coeffs", jprom_solution_output_coeffs(s, dbuf_for(len), len)); break;
        case 3: seen("jprom_solution_amplitude", jprom_solution_amplitude(s, h, j, chance(95) ? &x : NULL)); break;
        case 4: seen("jprom_solution_convergence", jprom_solution_convergence(s, chance(50) ? &a1 : NULL, chance(50) ? &x : NULL)); break;
        case 5: seen("jprom_solution_dissipated_energy", jprom_solution_dissipated_energy(s, dbuf_for(len), len)); break;
        case 6: seen("jprom_solution_n_samples", jprom_solution_n_samples(s, chance(95) ? &a1 : NULL)); break;
        case 7: { size_t l = chance(80) ? below(1 << 17) : rsize();
                  seen("jprom_solution_contact_states", jprom_solution_contact_states(s, chance(80) ? below(3) : rsize(), l <= sizeof ubuf && chance(90) ? ubuf : NULL, l));
                  break; }
        case 8: seen("jprom_solution_free", jprom_solution_free(s));
                for (size_t i = 0; i < POOL; ++i) if (solutions[i] == s) { solutions[i] = NULL; bury(s); }
                break;
        default: seen("jprom_basis_sizes", jprom_basis_sizes(PICK_BASIS(), len <= 4096 && chance(90) ? zbuf : NULL, len, chance(50) ? &a1 : NULL));
        }
    } else if (k < 620) {
        b = PICK_BASIS();
        seen("jprom_basis_free", jprom_basis_free(b));
        for (size_t i = 0; i < POOL; ++i) if (bases[i] == b) { bases[i] = NULL; bury(b); }
    } else if (k < 700) { /* save */
        switch (below(4)) {
        case 0: seen("jprom_model_save_json", jprom_model_save_json(PICK_MODEL(), rpath())); break;
        case 1: seen("jprom_solution_save_json", jprom_solution_save_json(PICK_SOLUTION(), rpath())); break;
        case 2: seen("jprom_sweep_result_save_json", jprom_sweep_result_save_json(PICK_SWEEP(), rpath())); break;
        default: seen("jprom_basis_save_json", jprom_basis_save_json(PICK_BASIS(), rpath()));
        }
    } else if (k < 790) { /* load */
        const char *p = rpath();
        switch (below(4)) {
        case 0: m = NULL; if (seen("jprom_model_load_json", jprom_model_load_json(p, chance(95) ? &m : NULL)) == JPROM_OK) ADOPT(models, jprom_model_free, m); break;
        case 1: s = NULL; if (seen("jprom_solution_load_json", jprom_solution_load_json(p, chance(95) ? &s : NULL)) == JPROM_OK) ADOPT(solutions, jprom_solution_free, s); break;
        case 2: w = NULL; if (seen("jprom_sweep_result_load_json", jprom_sweep_result_load_json(p, chance(95) ? &w : NULL)) == JPROM_OK) ADOPT(sweeps, jprom_sweep_result_free, w); break;
        default: b = NULL; if (seen("jprom_basis_load_json", jprom_basis_load_json(p, chance(95) ? &b : NULL)) == JPROM_OK) ADOPT(bases, jprom_basis_free, b);
        }
    } else if (k < 830) {
        corrupt_a_file();
    } else if (k < 845) { /* options defaults into NULL or a struct */
        jprom_hbm_options o;
        jprom_sweep_options so;
        jprom_jp_options jo;
        switch (below(3)) {
        case 0: seen("jprom_hbm_options_default", jprom_hbm_options_default(chance(90) ? &o : NULL)); break;
        case 1: seen("jprom_sweep_options_default", jprom_sweep_options_default(chance(90) ? &so : NULL)); break;
        default: seen("jprom_jp_options_default", jprom_jp_options_default(chance(90) ? &jo : NULL));
        }
    } else if (k < 850) { /* the memory and time budgets, within sane bounds */
        static const size_t budgets[] = {0, 0, 0, 1000, 1 << 20, (size_t)1 << 30};
        seen("jprom_set_memory_budget", jprom_set_memory_budget(budgets[below(6)]));
        /* hostile values are refused and leave the harness's budget of 2 s in force */
        static const double seconds[] = {-1.0, 1e-300, 2.0, 2.0, 1.0 / 0.0};
        double sec = seconds[below(5)], now_budget = 0.0;
        jprom_status tb = seen("jprom_set_time_budget", jprom_set_time_budget(chance(10) ? NAN : sec));
        if (tb == JPROM_OK && sec != 2.0) jprom_set_time_budget(2.0);
        seen("jprom_time_budget", jprom_time_budget(chance(90) ? &now_budget : NULL));
        size_t out;
        seen("jprom_memory_budget", jprom_memory_budget(chance(90) ? &out : NULL));
        if (chance(20)) {
            int repro;
            seen("jprom_set_reproducible", jprom_set_reproducible(chance(50) ? 0 : (int)rnd()));
            seen("jprom_reproducible", jprom_reproducible(chance(90) ? &repro : NULL));
        }
    } else { /* message readers never fail badly */
        char text[32];
        size_t written;
        jprom_status before = chance(50) ? jprom_model_n_dof(NULL, &written) : JPROM_OK;
        (void)before;
        size_t l = below(33);
        jprom_status c = jprom_last_error_copy(chance(90) ? text : NULL, l, chance(50) ? &written : NULL);
        if (c != JPROM_OK && c != JPROM_BAD_SIZE && c != JPROM_NULL_ARGUMENT) violation("jprom_last_error_copy", "undocumented status");
        if (l > 0 && c != JPROM_NULL_ARGUMENT && strlen(text) >= l) violation("jprom_last_error_copy", "not NUL-terminated within the buffer");
        const char *name = jprom_status_name((int)rnd());
        if (name == NULL || name[0] == '\0') violation("jprom_status_name", "empty name");
        calls++;
    }
}

int main(int argc, char **argv) {
    long n = argc > 1 ? atol(argv[1]) : 100000;
    rng_state ^= argc > 2 ? strtoull(argv[2], NULL, 10) * 0x9E3779B97F4A7C15ull + 1 : 1;
    snprintf(scratch, sizeof scratch, "%s", argc > 3 ? argv[3] : "/tmp");
    signal(SIGTERM, on_term);
    setvbuf(stdout, NULL, _IOLBF, 0);
    for (size_t i = 0; i < 4; ++i) models[i] = chain(1 + i, (int)(i % 3));
    /* every stage that the time budget bounds stops within 2 s and one piece */
    jprom_set_time_budget(2.0);
    double slowest = 0.0;
    const char *slowest_name = "(none)";
    while (calls < n) {
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        one_call();
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double dt = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        if (dt > slowest) slowest = dt, slowest_name = last_returned;
    }
    printf("slowest call: %.2f s (%s)\n", slowest, slowest_name);
    jprom_set_time_budget(0.0);
    /* free everything left, then no handle may remain */
    for (size_t i = 0; i < POOL; ++i) {
        seen("jprom_model_free", jprom_model_free(models[i]));
        seen("jprom_solution_free", jprom_solution_free(solutions[i]));
        seen("jprom_sweep_result_free", jprom_sweep_result_free(sweeps[i]));
        seen("jprom_basis_free", jprom_basis_free(bases[i]));
    }
    jprom_set_memory_budget(0);
    jprom_set_reproducible(0);
    size_t live = 99;
    jprom_live_handle_count(&live);
    if (live != 0) { printf("VIOLATION: %zu handles left after freeing every pool\n", live); violations++; }
    printf("calls: %ld, violations: %ld, panics: %ld\nstatuses:", calls, violations, by_status[JPROM_PANIC]);
    for (int c = 0; c <= 11; ++c) printf(" %s=%ld", jprom_status_name(c), by_status[c]);
    printf("\n");
    if (violations == 0) printf("api_fuzz: no violation\n");
    return violations != 0;
}
