/* Runs the default scene (House et al. test 7) to the end condition and
 * prints the final observables as `name = value` lines (%.17g: every double
 * round-trips). Optional NAME=VALUE arguments set parameters first.
 *
 *   ./taylor                       # the default scene, ~25 s
 *   ./taylor particles_radial=5    # a coarse, fast run
 *   ./taylor scheme=paper          # Batra & Zhang's scheme exactly
 */
#include "util.h"
#include <string.h>

int main(int argc, char **argv) {
    mi_sim *sim = NULL;

    if (strcmp(mi_version(), MI_VERSION) != 0) {
        fprintf(stderr, "library %s, header %s\n", mi_version(), MI_VERSION);
        return 1;
    }
    check(NULL, mi_sim_new("taylor", &sim), "mi_sim_new");
    apply_settings(sim, argc, argv);
    check(sim, mi_sim_run(sim), "mi_sim_run");

    print_observables(sim);
    mi_sim_free(sim);
    return 0;
}
