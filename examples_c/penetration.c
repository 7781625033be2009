/* Runs the 3-D ballistic penetration scene (`penetration`, MLPG: a tungsten
 * cylinder striking an AD85 ceramic plate) coarse and short, prints the
 * final observables as `name = value` lines (%.17g: every double
 * round-trips), then reads the `body`, `mass` and `velocity` fields and
 * prints, per body (0 projectile, 1 plate), its node count, its mass (kg)
 * and its axial momentum sum m v_z (kg m/s), the total axial momentum, and
 * the axial velocity of the projectile's centre of mass from these fields,
 * positive in its direction of flight (-sum m v_z / sum m over body 0). That
 * is the definition of the `projectile_velocity` observable: the example
 * stops with status 1 when the two differ by more than 1e-12 relative.
 *
 *   ./penetration                     # 3 nodes across the radius, 1 us, < 1 s
 *   ./penetration end_time=2e-6       # NAME=VALUE arguments set parameters
 */
#include "util.h"
#include <math.h>

int main(int argc, char **argv) {
    mi_sim *sim = NULL;
    size_t particles = 0, nb = 0, nm = 0, nv = 0, k, nodes[2] = {0, 0};
    double mass[2] = {0.0, 0.0}, momentum[2] = {0.0, 0.0};
    double observed = 0.0, from_fields, difference;
    double *body, *m, *v;
    int b, status = 0;

    check(NULL, mi_sim_new("penetration", &sim), "mi_sim_new");
    /* Coarse and short by default: 3 nodes across the projectile's radius
     * (2546 nodes in both bodies), 1 us after impact (4 steps). */
    check(sim, mi_sim_set_param(sim, "particles_radial", 3.0), "particles_radial");
    check(sim, mi_sim_set_param(sim, "end_time", 1e-6), "end_time");
    apply_settings(sim, argc, argv);
    check(sim, mi_sim_run(sim), "mi_sim_run");

    print_observables(sim);
    check(sim, mi_sim_particle_count(sim, &particles), "mi_sim_particle_count");
    printf("nodes = %zu\n", particles);

    body = read_field(sim, "body", &nb);
    m = read_field(sim, "mass", &nm);
    v = read_field(sim, "velocity", &nv); /* x, y, z per node */
    if (nb != particles || nm != particles || nv != 3 * particles) {
        fprintf(stderr, "field lengths %zu, %zu, %zu for %zu nodes\n", nb, nm, nv, particles);
        status = 1;
        goto done;
    }
    /* Node order, as the library sums: the same sums bit for bit. */
    for (k = 0; k < particles; ++k) {
        if (body[k] != 0.0 && body[k] != 1.0) {
            fprintf(stderr, "node %zu: body %g is neither 0 nor 1\n", k, body[k]);
            status = 1;
            goto done;
        }
        b = (int)body[k];
        nodes[b] += 1;
        mass[b] += m[k];
        momentum[b] += m[k] * v[3 * k + 2];
    }
    for (b = 0; b < 2; ++b) {
        printf("body%d_nodes = %zu\n", b, nodes[b]);
        printf("body%d_mass = %.17g\n", b, mass[b]);
        printf("body%d_momentum_z = %.17g\n", b, momentum[b]);
    }
    printf("momentum_z = %.17g\n", momentum[0] + momentum[1]);

    /* The projectile flies toward -z: its velocity of flight is -v_z. */
    from_fields = -momentum[0] / mass[0];
    check(sim, mi_sim_observable(sim, "projectile_velocity", &observed), "projectile_velocity");
    difference = fabs(from_fields - observed) / fabs(observed);
    printf("projectile_velocity_from_fields = %.17g\n", from_fields);
    printf("projectile_velocity_observable = %.17g\n", observed);
    printf("projectile_velocity_relative_difference = %.17g\n", difference);
    if (!(difference <= 1e-12)) {
        fprintf(stderr, "projectile_velocity: %.17g from the fields, %.17g observed\n", from_fields,
                observed);
        status = 1;
    }

done:
    free(body);
    free(m);
    free(v);
    mi_sim_free(sim);
    return status;
}
