/* A sweep of impact speeds, one handle per speed, on several POSIX threads
 * at once (handles share nothing). Prints one row per speed, in speed order:
 *
 *   speed rod_length mushroom_radius undeformed_length max_plastic_strain steps
 *
 *   ./sweep [--serial] [particles_radial]   (default 6; --serial runs the
 *                                            speeds one after another)
 */
#include "util.h"
#include <pthread.h>
#include <string.h>

#define NSPEEDS 6
#define NTHREADS 3
static const double SPEEDS[NSPEEDS] = {150.0, 170.0, 181.0, 200.0, 220.0, 240.0};
static const char *const COLUMNS[] = {"rod_length", "mushroom_radius", "undeformed_length",
                                      "max_plastic_strain"};
#define NCOLUMNS (sizeof COLUMNS / sizeof COLUMNS[0])

typedef struct {
    double speed;
    double particles_radial;
    double values[NCOLUMNS];
    uint64_t steps;
    mi_result result;
} job;

typedef struct {
    job *jobs;
    int first, stride;
} worker;

static void run_job(job *j) {
    mi_sim *sim = NULL;
    size_t c;
    j->result = mi_sim_new("taylor", &sim);
    if (j->result != MI_OK) return;
    if ((j->result = mi_sim_set_param(sim, "particles_radial", j->particles_radial)) == MI_OK &&
        (j->result = mi_sim_set_param(sim, "impact_speed", j->speed)) == MI_OK &&
        (j->result = mi_sim_run(sim)) == MI_OK &&
        (j->result = mi_sim_steps(sim, &j->steps)) == MI_OK) {
        for (c = 0; c < NCOLUMNS && j->result == MI_OK; ++c)
            j->result = mi_sim_observable(sim, COLUMNS[c], &j->values[c]);
    }
    if (j->result != MI_OK) {
        char *msg = last_error(sim);
        fprintf(stderr, "speed %g: %s: %s\n", j->speed, mi_result_name(j->result),
                msg != NULL ? msg : "");
        free(msg);
    }
    mi_sim_free(sim);
}

static void *work(void *arg) {
    worker *w = (worker *)arg;
    int k;
    for (k = w->first; k < NSPEEDS; k += w->stride) run_job(&w->jobs[k]);
    return NULL;
}

int main(int argc, char **argv) {
    job jobs[NSPEEDS];
    int serial = 0, k, status = 0;
    double n = 6.0;
    for (k = 1; k < argc; ++k) {
        if (strcmp(argv[k], "--serial") == 0) serial = 1;
        else n = atof(argv[k]);
    }
    for (k = 0; k < NSPEEDS; ++k) {
        memset(&jobs[k], 0, sizeof jobs[k]);
        jobs[k].speed = SPEEDS[k];
        jobs[k].particles_radial = n;
    }
    if (serial) {
        for (k = 0; k < NSPEEDS; ++k) run_job(&jobs[k]);
    } else {
        pthread_t threads[NTHREADS];
        worker workers[NTHREADS];
        for (k = 0; k < NTHREADS; ++k) {
            workers[k].jobs = jobs;
            workers[k].first = k;
            workers[k].stride = NTHREADS;
            if (pthread_create(&threads[k], NULL, work, &workers[k]) != 0) return 1;
        }
        for (k = 0; k < NTHREADS; ++k) pthread_join(threads[k], NULL);
    }
    printf("speed");
    for (k = 0; k < (int)NCOLUMNS; ++k) printf(" %s", COLUMNS[k]);
    printf(" steps\n");
    for (k = 0; k < NSPEEDS; ++k) {
        size_t c;
        if (jobs[k].result != MI_OK) {
            status = 1;
            continue;
        }
        printf("%.17g", jobs[k].speed);
        for (c = 0; c < NCOLUMNS; ++c) printf(" %.17g", jobs[k].values[c]);
        printf(" %llu\n", (unsigned long long)jobs[k].steps);
    }
    return status;
}
