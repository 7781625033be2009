/* Small helpers shared by the examples: report a failed call with the
 * handle's last error message and stop. */
#ifndef MI_EXAMPLES_UTIL_H
#define MI_EXAMPLES_UTIL_H

#include "meshless_impact.h"
#include <stdio.h>
#include <stdlib.h>

/* The handle's last error message, in a malloc'ed string (caller frees). */
static inline char *last_error(const mi_sim *sim) {
    size_t n = 0;
    char *msg;
    if (mi_sim_last_error(sim, NULL, 0, &n) != MI_OK) return NULL; /* size query */
    msg = (char *)malloc(n);
    if (msg != NULL && mi_sim_last_error(sim, msg, n, NULL) != MI_OK) {
        free(msg);
        return NULL;
    }
    return msg;
}

/* Stops the program when `r` is not MI_OK. */
static inline void check(mi_sim *sim, mi_result r, const char *what) {
    char *msg;
    if (r == MI_OK) return;
    msg = sim != NULL ? last_error(sim) : NULL;
    fprintf(stderr, "%s: %s: %s\n", what, mi_result_name(r), msg != NULL ? msg : "");
    free(msg);
    mi_sim_free(sim);
    exit(1);
}

/* The field `name` in a malloc'ed array (caller frees); its length in *n. */
static inline double *read_field(mi_sim *sim, const char *name, size_t *n) {
    double *v;
    check(sim, mi_sim_field(sim, name, NULL, 0, n), name); /* size query */
    v = (double *)malloc(*n * sizeof *v);
    if (v == NULL) {
        mi_sim_free(sim);
        exit(1);
    }
    check(sim, mi_sim_field(sim, name, v, *n, NULL), name);
    return v;
}

/* Applies NAME=VALUE arguments as parameters. */
static inline void apply_settings(mi_sim *sim, int argc, char **argv) {
    int i;
    for (i = 1; i < argc; ++i) {
        char name[128], text[128];
        double value;
        /* `scheme=NAME` chooses the numerical scheme by name. */
        if (sscanf(argv[i], "scheme=%127s", text) == 1) {
            check(sim, mi_sim_set_scheme(sim, text), "mi_sim_set_scheme");
            continue;
        }
        if (sscanf(argv[i], "%127[^=]=%lf", name, &value) != 2) {
            fprintf(stderr, "expected NAME=VALUE, got `%s`\n", argv[i]);
            mi_sim_free(sim);
            exit(2);
        }
        check(sim, mi_sim_set_param(sim, name, value), name);
    }
}

/* Prints every observable as `name = value` (%.17g: every double
 * round-trips), then `steps = ` and `time = `. */
static inline void print_observables(mi_sim *sim) {
    size_t count = 0, k;
    uint64_t steps = 0;
    double t = 0.0;
    check(sim, mi_sim_observable_count(sim, &count), "mi_sim_observable_count");
    for (k = 0; k < count; ++k) {
        mi_observable_info info;
        double v;
        check(sim, mi_sim_observable_info(sim, k, &info), "mi_sim_observable_info");
        check(sim, mi_sim_observable(sim, info.name, &v), info.name);
        printf("%s = %.17g\n", info.name, v);
    }
    check(sim, mi_sim_steps(sim, &steps), "mi_sim_steps");
    check(sim, mi_sim_time(sim, &t), "mi_sim_time");
    printf("steps = %llu\n", (unsigned long long)steps);
    printf("time = %.17g\n", t);
}

#endif
