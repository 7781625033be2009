/* Runs the default scene (House et al. test 7) to the end condition and
 * prints the final observables as `name = value` lines (%.17g: every double
 * round-trips). Optional NAME=VALUE arguments set parameters first.
 *
 *   ./taylor                       # the default scene, ~25 s
 *   ./taylor particles_radial=5    # a coarse, fast run
 */
#include "util.h"
#include <string.h>

int main(int argc, char **argv) {
    mi_sim *sim = NULL;
    size_t count = 0, k;
    uint64_t steps = 0;
    double t = 0.0;

    if (strcmp(mi_version(), MI_VERSION) != 0) {
        fprintf(stderr, "library %s, header %s\n", mi_version(), MI_VERSION);
        return 1;
    }
    check(NULL, mi_sim_new("taylor", &sim), "mi_sim_new");
    apply_settings(sim, argc, argv);
    check(sim, mi_sim_run(sim), "mi_sim_run");

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
    mi_sim_free(sim);
    return 0;
}
