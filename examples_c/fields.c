/* Runs a Taylor scene and writes the final particle fields to a CSV file,
 * one row per particle, one column per field component (R, Z, density,
 * velocity_R, velocity_Z, ..., stress_RR, ...). Arrays are copied into
 * buffers the program owns, sized by the NULL/0 length query.
 *
 *   ./fields OUT.csv [NAME=VALUE ...]    (for example particles_radial=6)
 */
#include "util.h"

int main(int argc, char **argv) {
    mi_sim *sim = NULL;
    size_t nfields = 0, particles = 0, f, p, c;
    double **data;
    mi_field_info *info;
    FILE *out;

    if (argc < 2) {
        fprintf(stderr, "usage: %s OUT.csv [NAME=VALUE ...]\n", argv[0]);
        return 2;
    }
    check(NULL, mi_sim_new("taylor", &sim), "mi_sim_new");
    apply_settings(sim, argc - 1, argv + 1);
    check(sim, mi_sim_run(sim), "mi_sim_run");
    check(sim, mi_sim_particle_count(sim, &particles), "mi_sim_particle_count");
    check(sim, mi_sim_field_count(sim, &nfields), "mi_sim_field_count");

    info = (mi_field_info *)calloc(nfields, sizeof *info);
    data = (double **)calloc(nfields, sizeof *data);
    if (info == NULL || data == NULL) return 1;
    for (f = 0; f < nfields; ++f) {
        size_t needed = 0;
        check(sim, mi_sim_field_info(sim, f, &info[f]), "mi_sim_field_info");
        /* Size query, then the copy into our own buffer. */
        check(sim, mi_sim_field(sim, info[f].name, NULL, 0, &needed), info[f].name);
        if (needed != particles * info[f].components) {
            fprintf(stderr, "%s: %zu values for %zu particles\n", info[f].name, needed, particles);
            return 1;
        }
        data[f] = (double *)malloc(needed * sizeof(double));
        if (data[f] == NULL) return 1;
        check(sim, mi_sim_field(sim, info[f].name, data[f], needed, NULL), info[f].name);
    }

    out = fopen(argv[1], "w");
    if (out == NULL) {
        perror(argv[1]);
        return 1;
    }
    for (f = 0; f < nfields; ++f)
        for (c = 0; c < info[f].components; ++c) {
            const char *sep = (f == 0 && c == 0) ? "" : ",";
            if (f == 0) /* position: plain R, Z */
                fprintf(out, "%s%s", sep, info[f].component_names[c]);
            else if (info[f].components == 1)
                fprintf(out, "%s%s", sep, info[f].name);
            else
                fprintf(out, "%s%s_%s", sep, info[f].name, info[f].component_names[c]);
        }
    fprintf(out, "\n");
    for (p = 0; p < particles; ++p) {
        for (f = 0; f < nfields; ++f)
            for (c = 0; c < info[f].components; ++c)
                fprintf(out, "%s%.17g", (f == 0 && c == 0) ? "" : ",",
                        data[f][p * info[f].components + c]);
        fprintf(out, "\n");
    }
    fclose(out);
    printf("wrote %zu particles, %zu fields to %s\n", particles, nfields, argv[1]);

    for (f = 0; f < nfields; ++f) free(data[f]);
    free(data);
    free(info); /* the strings in info belong to the handle: freed with it */
    mi_sim_free(sim);
    return 0;
}
