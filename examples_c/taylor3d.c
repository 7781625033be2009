/* Runs the 3-D Taylor impact (`taylor3d`, MLPG mixed method) at a coarse
 * resolution, prints the final observables as `name = value` lines (%.17g:
 * every double round-trips), then reads the 3-D particle fields: the name
 * and components of each field, and, from the `position` (x, y, z) and
 * `stress` (xx, yy, zz, xy, yz, zx) fields, the rod's extent along z, its
 * largest distance from the axis and how far the mean normal stress is
 * from minus the `pressure` field.
 *
 *   ./taylor3d                       # 4 nodes across the radius, ~5 s
 *   ./taylor3d particles_radial=3    # NAME=VALUE arguments set parameters
 */
#include "util.h"
#include <math.h>
#include <string.h>

int main(int argc, char **argv) {
    mi_sim *sim = NULL;
    size_t particles = 0, fields = 0, k, np = 0, ns = 0, nq = 0;
    size_t pos_comps = 0, stress_comps = 0;
    double l0 = 0.0, zmin = INFINITY, zmax = -INFINITY, rmax = 0.0;
    double smax = 0.0, residual = 0.0;
    double *pos, *stress, *pressure;

    check(NULL, mi_sim_new("taylor3d", &sim), "mi_sim_new");
    /* Coarse by default: 4 nodes across the radius (1147 nodes). */
    check(sim, mi_sim_set_param(sim, "particles_radial", 4.0), "particles_radial");
    apply_settings(sim, argc, argv);
    check(sim, mi_sim_run(sim), "mi_sim_run");

    print_observables(sim);
    check(sim, mi_sim_particle_count(sim, &particles), "mi_sim_particle_count");
    check(sim, mi_sim_get_param(sim, "initial_length", &l0), "initial_length");
    printf("nodes = %zu\n", particles);
    printf("initial_length = %.17g\n", l0);

    /* The fields, with their components. */
    check(sim, mi_sim_field_count(sim, &fields), "mi_sim_field_count");
    for (k = 0; k < fields; ++k) {
        mi_field_info info;
        size_t c;
        check(sim, mi_sim_field_info(sim, k, &info), "mi_sim_field_info");
        printf("field %s [%s]:", info.name, info.unit);
        for (c = 0; c < info.components; ++c) printf(" %s", info.component_names[c]);
        printf("\n");
        if (strcmp(info.name, "position") == 0) pos_comps = info.components;
        if (strcmp(info.name, "stress") == 0) stress_comps = info.components;
    }
    printf("position_components = %zu\n", pos_comps);
    printf("stress_components = %zu\n", stress_comps);
    if (pos_comps != 3 || stress_comps != 6) {
        fprintf(stderr, "not the 3-D fields\n");
        mi_sim_free(sim);
        return 1;
    }

    pos = read_field(sim, "position", &np);
    stress = read_field(sim, "stress", &ns);
    pressure = read_field(sim, "pressure", &nq);
    printf("position_values = %zu\n", np);
    printf("stress_values = %zu\n", ns);
    for (k = 0; k < particles && 3 * k + 2 < np && 6 * k + 5 < ns && k < nq; ++k) {
        const double *x = pos + 3 * k, *s = stress + 6 * k;
        double r = sqrt(x[0] * x[0] + x[1] * x[1]);
        size_t c;
        zmin = fmin(zmin, x[2]);
        zmax = fmax(zmax, x[2]);
        rmax = fmax(rmax, r);
        for (c = 0; c < 6; ++c) smax = fmax(smax, fabs(s[c]));
        /* The deviator is trace-free: the mean normal stress is -P. */
        residual = fmax(residual, fabs((s[0] + s[1] + s[2]) / 3.0 + pressure[k]));
    }
    /* Highest minus lowest node: the definition of rod_length. */
    printf("position_z_extent = %.17g\n", zmax - zmin);
    printf("position_max_radius = %.17g\n", rmax);
    printf("stress_max_abs = %.17g\n", smax);
    printf("stress_mean_plus_pressure_max = %.17g\n", residual);
    free(pos);
    free(stress);
    free(pressure);
    mi_sim_free(sim);
    return 0;
}
