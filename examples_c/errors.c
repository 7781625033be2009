/* The error paths of the C ABI: every result code is produced, checked
 * against the expected value, and shown with its message. Outputs must be
 * left untouched on failure. Exits non-zero on the first mismatch.
 */
#include "util.h"
#include <math.h>
#include <string.h>

static int failures = 0;

/* Checks that `got` is `want` and that the handle's message (if any)
 * contains `needle`; prints one line per check. */
static void expect(mi_sim *sim, mi_result got, mi_result want, const char *needle,
                   const char *what) {
    char *msg = sim != NULL ? last_error(sim) : NULL;
    int ok = got == want && (needle == NULL || (msg != NULL && strstr(msg, needle) != NULL));
    printf("%-4s %-26s %-28s %s\n", ok ? "ok" : "FAIL", mi_result_name(got), what,
           msg != NULL ? msg : "");
    if (!ok) {
        fprintf(stderr, "%s: expected %s, got %s\n", what, mi_result_name(want),
                mi_result_name(got));
        failures++;
    }
    free(msg);
}

static mi_sim *make(const char *scene, double particles_radial) {
    mi_sim *sim = NULL;
    check(NULL, mi_sim_new(scene, &sim), "mi_sim_new");
    check(sim, mi_sim_set_param(sim, "particles_radial", particles_radial), "particles_radial");
    return sim;
}

static mi_result run_and_free(mi_sim *sim, const char *needle, mi_result want, const char *what) {
    mi_result r = mi_sim_run(sim);
    expect(sim, r, want, needle, what);
    mi_sim_free(sim);
    return r;
}

static bool cancel_after_5(void *user_data, double time, double end_time, uint64_t steps) {
    (void)time;
    (void)end_time;
    ++*(int *)user_data;
    return steps < 5;
}

/* A saved state with the `component` of particle `particle`'s velocity set to
 * `value` (the state is JSON; the text surgery is for this test only), loaded
 * into a new handle and stepped once: the solver's own checks stop it. With
 * `load` = MI_INVALID_STATE the load itself is refused (a velocity beyond
 * the physical bound of a restored state). */
static void patched_state(int particle, int component, const char *value, mi_result load,
                          mi_result want, const char *needle, const char *what) {
    mi_sim *sim = make("taylor", 5), *copy = NULL;
    size_t n = 0, head;
    uint8_t *bytes, *patched;
    char *p, *end;
    int k;
    check(sim, mi_sim_advance_to(sim, 1e-6), "mi_sim_advance_to");
    check(sim, mi_sim_state_save(sim, NULL, 0, &n), "state size");
    bytes = (uint8_t *)malloc(n + 1);
    patched = (uint8_t *)malloc(n + 64);
    if (bytes == NULL || patched == NULL) exit(1);
    check(sim, mi_sim_state_save(sim, bytes, n, NULL), "mi_sim_state_save");
    bytes[n] = 0;
    p = strstr((char *)bytes, "\"vel\":[");
    if (p == NULL) exit(1);
    p += strlen("\"vel\":[");
    for (k = 0; k < particle; ++k) p = strchr(p, ']') + 2; /* skip `[a,b],` */
    p += 1;                                              /* past `[` */
    if (component == 1) p = strchr(p, ',') + 1;
    end = p + strcspn(p, ",]");
    head = (size_t)(p - (char *)bytes);
    memcpy(patched, bytes, head);
    memcpy(patched + head, value, strlen(value));
    memcpy(patched + head + strlen(value), end, n - (size_t)(end - (char *)bytes));
    n = head + strlen(value) + (n - (size_t)(end - (char *)bytes));
    check(NULL, mi_sim_new("taylor", &copy), "mi_sim_new");
    if (load == MI_OK) {
        check(copy, mi_sim_state_load(copy, patched, n), "mi_sim_state_load");
        expect(copy, mi_sim_step(copy), want, needle, what);
    } else {
        expect(copy, mi_sim_state_load(copy, patched, n), load, needle, what);
    }
    free(bytes);
    free(patched);
    mi_sim_free(copy);
    mi_sim_free(sim);
}

int main(void) {
    mi_sim *sim = NULL, *s;
    double v = -1.0, small[2] = {-1.0, -1.0};
    size_t n = 0;
    int calls = 0;
    const unsigned char not_utf8[] = {0xff, 0xfe, 0};
    char buf[8];

    /* Creation: no handle on failure, so only the code. */
    expect(NULL, mi_sim_new("taylor", NULL), MI_NULL_POINTER, NULL, "new(out = NULL)");
    expect(NULL, mi_sim_new(NULL, &sim), MI_NULL_POINTER, NULL, "new(scene = NULL)");
    expect(NULL, mi_sim_new("tailor", &sim), MI_UNKNOWN_SCENE, NULL, "new(\"tailor\")");
    expect(NULL, mi_sim_new((const char *)not_utf8, &sim), MI_INVALID_UTF8, NULL, "new(bad UTF-8)");
    expect(NULL, mi_sim_new_toml("scene = ", &sim), MI_SCENE_FILE, NULL, "new_toml(syntax)");
    expect(NULL, mi_sim_new_toml("scene = \"taylor\"\n[parameters]\nimpact_speed = \"fast\"\n", &sim),
           MI_PARSE_VALUE, NULL, "new_toml(string value)");
    expect(NULL, mi_sim_new_file("/nonexistent/scene.toml", &sim), MI_IO, NULL, "new_file(missing)");
    if (sim != NULL) {
        fprintf(stderr, "out written on failure\n");
        return 1;
    }
    expect(NULL, mi_sim_run(NULL), MI_NULL_POINTER, NULL, "run(NULL)");

    /* Parameters, names, buffers. */
    check(NULL, mi_sim_new("taylor", &sim), "mi_sim_new");
    expect(sim, mi_sim_set_param(sim, "impact_sped", 1.0), MI_UNKNOWN_PARAMETER, "impact_speed",
           "set(impact_sped)");
    expect(sim, mi_sim_set_param(sim, "impact_speed", -1.0), MI_OUT_OF_RANGE, "[0.01, 2000]",
           "set(impact_speed = -1)");
    expect(sim, mi_sim_set_param(sim, "impact_speed", NAN), MI_OUT_OF_RANGE, "NaN",
           "set(impact_speed = NaN)");
    expect(sim, mi_sim_get_param(sim, "density", NULL), MI_NULL_POINTER, "value",
           "get(value = NULL)");
    expect(sim, mi_sim_observable(sim, "rod_lenght", &v), MI_UNKNOWN_OBSERVABLE, "rod_length",
           "observable(rod_lenght)");
    expect(sim, mi_sim_field(sim, "strain", NULL, 0, NULL), MI_UNKNOWN_FIELD, "plastic_strain",
           "field(strain)");
    expect(sim, mi_sim_observables(sim, small, 2, &n), MI_BUFFER_TOO_SMALL, "needed",
           "observables(len = 2)");
    if (n != 13 || small[0] != -1.0 || v != -1.0) {
        fprintf(stderr, "needed = %zu (13 expected), or an output written on failure\n", n);
        failures++;
    }
    expect(sim, mi_sim_last_error(sim, buf, sizeof buf, &n), MI_BUFFER_TOO_SMALL, NULL,
           "last_error(8 bytes)");
    expect(sim, mi_sim_state_load(sim, (const uint8_t *)"not a state", 11), MI_INVALID_STATE,
           "invalid", "state_load(garbage)");
    expect(sim, mi_sim_advance_to(sim, INFINITY), MI_OUT_OF_RANGE, "finite", "advance_to(inf)");
    check(sim, mi_sim_set_param(sim, "room_temperature", 1300.0), "room_temperature");
    expect(sim, mi_sim_run(sim), MI_INCONSISTENT, "melt_temperature", "run(room > melt)");
    mi_sim_free(sim);

    /* Wrong order: parameters are fixed after the first step. */
    s = make("taylor", 5);
    check(s, mi_sim_step(s), "mi_sim_step");
    expect(s, mi_sim_set_param(s, "jc_a", 1e9), MI_WRONG_ORDER, "started", "set after step");
    mi_sim_free(s);

    /* Solver stops: each a named code, never garbage. */
    s = make("taylor", 5);
    check(s, mi_sim_set_param(s, "smoothing_ratio", 0.6), "smoothing_ratio");
    run_and_free(s, "singular", MI_SINGULAR_MOMENT_MATRIX, "run(smoothing_ratio 0.6)");
    s = make("taylor", 6);
    check(s, mi_sim_set_param(s, "smoothing_coefficient", 0.0), "smoothing_coefficient");
    run_and_free(s, "energy error", MI_ENERGY_DRIFT, "run(no smoothing)");
    s = make("noh", 50);
    check(s, mi_sim_set_param(s, "viscosity_quadratic", 0.0), "viscosity_quadratic");
    check(s, mi_sim_set_param(s, "viscosity_linear", 0.0), "viscosity_linear");
    check(s, mi_sim_set_param(s, "smoothing_coefficient", 0.0), "smoothing_coefficient");
    run_and_free(s, "time step collapsed", MI_TIME_STEP_COLLAPSE, "run(noh, no viscosity)");
    /* Mie-Gruneisen chosen by name; a soft, steep curve hit at 2000 m/s
     * reaches its singular compression 1 / (eos_s - 1) at the face. */
    s = make("taylor", 5);
    expect(s, mi_sim_set_material(s, "eos", "gruneisen"), MI_UNKNOWN_MATERIAL, "mie_gruneisen",
           "set_material(eos = gruneisen)");
    expect(s, mi_sim_set_material(s, "preset", "ofhc_copper"), MI_UNKNOWN_MATERIAL,
           "ofhc_copper_jc", "set_material(preset = ofhc_copper)");
    expect(s, mi_sim_set_scheme(s, "fast"), MI_UNKNOWN_MATERIAL, "large_strain, paper",
           "set_scheme(fast)");
    check(s, mi_sim_set_material(s, "eos", "mie_gruneisen"), "mi_sim_set_material");
    expect(s, mi_sim_set_param(s, "bulk_modulus", 1e11), MI_UNKNOWN_PARAMETER, "eos_c0",
           "set(bulk_modulus) with MG");
    check(s, mi_sim_set_param(s, "eos_c0", 500.0), "eos_c0");
    check(s, mi_sim_set_param(s, "eos_s", 10.0), "eos_s");
    check(s, mi_sim_set_param(s, "impact_speed", 2000.0), "impact_speed");
    run_and_free(s, "Mie-Gr", MI_COMPRESSION_LIMIT, "run(MG, eos_c0 500, 2000 m/s)");
    patched_state(6, 1, "-5e4", MI_OK, MI_THROUGH_BOUNDARY, "anvil", "step(v_Z = -5e4)");
    patched_state(11, 0, "1e308", MI_INVALID_STATE, MI_INVALID_STATE, "faster than",
                  "state_load(v_R = 1e308)");

    /* Soft, heavy bodies at 10 km/s: a temperature overflows within 1 us; such
     * a run has no state to save (issue 48). */
    s = make("penetration", 3);
    check(s, mi_sim_set_param(s, "impact_speed", 1e4), "impact_speed");
    check(s, mi_sim_set_param(s, "end_time", 1e-6), "end_time");
    check(s, mi_sim_set_param(s, "projectile_density", 1e5), "projectile_density");
    check(s, mi_sim_set_param(s, "plate_density", 1e5), "plate_density");
    check(s, mi_sim_set_param(s, "projectile_shear_modulus", 1e6), "projectile_shear_modulus");
    check(s, mi_sim_set_param(s, "projectile_bulk_modulus", 1e6), "projectile_bulk_modulus");
    check(s, mi_sim_set_param(s, "plate_shear_modulus", 1e6), "plate_shear_modulus");
    check(s, mi_sim_set_param(s, "projectile_yield_stress", 0.0), "projectile_yield_stress");
    expect(s, mi_sim_run(s), MI_NON_FINITE, "non-finite", "run(soft, heavy, 10 km/s)");
    expect(s, mi_sim_state_save(s, NULL, 0, &n), MI_NON_FINITE, "non-finite",
           "state_save after a non-finite stop");
    mi_sim_free(s);

    /* 6.3 million nodes: refused by the memory budget before allocating. */
    s = make("taylor3d", 60);
    run_and_free(s, "memory budget", MI_MEMORY_BUDGET, "run(taylor3d, 60 across)");

    /* Cancel from the progress callback. */
    s = make("taylor", 5);
    check(s, mi_sim_set_progress(s, cancel_after_5, &calls), "mi_sim_set_progress");
    expect(s, mi_sim_run(s), MI_CANCELLED, "cancelled", "run(callback says stop)");
    expect(s, mi_sim_step(s), MI_CANCELLED, "cancelled", "step after cancel");
    if (calls != 5) {
        fprintf(stderr, "callback called %d times, 5 expected\n", calls);
        failures++;
    }
    mi_sim_free(s);

    /* A panic inside the library is caught and poisons the handle. */
    check(NULL, mi_sim_new("taylor", &s), "mi_sim_new");
    expect(s, mi_sim_debug_panic(s), MI_PANIC, "mi_sim_debug_panic", "debug_panic");
    expect(s, mi_sim_run(s), MI_PANIC, "unusable", "run after panic");
    mi_sim_free(s);
    mi_sim_free(NULL); /* allowed */

    printf("%s\n", failures == 0 ? "all error paths behave" : "FAILURES");
    return failures == 0 ? 0 : 1;
}
