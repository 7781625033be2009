/* Checkpointing from C: a host steps a run and writes a checkpoint file
 * every 20 steps (mi_sim_checkpoint_save: written whole, a temporary file
 * renamed over the last one); a second handle continues from the last
 * checkpoint (mi_sim_checkpoint_load, as after a kill) and ends on the bits
 * of the run that was never stopped. A checkpoint cut short is refused with
 * MI_BAD_CHECKPOINT and leaves the handle's run as it was.
 *
 *   checkpoint DIR [name=value ...]     (the Taylor scene; settings as taylor.c)
 */
#include "util.h"
#include <string.h>

int main(int argc, char **argv) {
    mi_sim *whole = NULL, *first = NULL, *again = NULL;
    char path[4096], cut[4096], *msg;
    double *va, *vb, t_saved = 0.0, t = 0.0;
    size_t count = 0, k;
    uint64_t steps = 0, total = 0;
    bool finished = false;
    FILE *f;
    long len;
    char *bytes;
    if (argc < 2) {
        fprintf(stderr, "usage: checkpoint DIR [name=value ...]\n");
        return 2;
    }
    snprintf(path, sizeof path, "%s/taylor.ckpt", argv[1]);
    snprintf(cut, sizeof cut, "%s/cut.ckpt", argv[1]);

    check(NULL, mi_sim_new("taylor", &whole), "mi_sim_new");
    apply_settings(whole, argc - 1, argv + 1);
    check(whole, mi_sim_run(whole), "mi_sim_run");
    check(whole, mi_sim_steps(whole, &total), "mi_sim_steps");

    /* The host's loop: a checkpoint every 20 steps; stopped at 70% of the
     * steps, as a kill would stop it. */
    check(NULL, mi_sim_new("taylor", &first), "mi_sim_new");
    apply_settings(first, argc - 1, argv + 1);
    while (10 * steps < 7 * total) {
        check(first, mi_sim_step(first), "mi_sim_step");
        check(first, mi_sim_steps(first, &steps), "mi_sim_steps");
        check(first, mi_sim_time(first, &t), "mi_sim_time");
        if (steps % 20 == 0) {
            check(first, mi_sim_checkpoint_save(first, path), "mi_sim_checkpoint_save");
            t_saved = t;
        }
    }
    mi_sim_free(first);

    /* The restart: a new handle of the scene, the checkpoint loaded. */
    check(NULL, mi_sim_new("taylor", &again), "mi_sim_new");
    check(again, mi_sim_checkpoint_load(again, path), "mi_sim_checkpoint_load");
    check(again, mi_sim_time(again, &t), "mi_sim_time");
    if (t != t_saved) {
        fprintf(stderr, "restored at t = %.17g, saved at %.17g\n", t, t_saved);
        return 1;
    }
    check(again, mi_sim_run(again), "mi_sim_run");
    check(again, mi_sim_finished(again, &finished), "mi_sim_finished");
    check(whole, mi_sim_observable_count(whole, &count), "mi_sim_observable_count");
    va = (double *)malloc(count * sizeof(double));
    vb = (double *)malloc(count * sizeof(double));
    if (va == NULL || vb == NULL) return 1;
    check(whole, mi_sim_observables(whole, va, count, NULL), "mi_sim_observables");
    check(again, mi_sim_observables(again, vb, count, NULL), "mi_sim_observables");
    for (k = 0; k < count; ++k) {
        if (memcmp(&va[k], &vb[k], sizeof(double)) != 0) {
            fprintf(stderr, "observable %zu: %.17g restarted, %.17g whole\n", k, vb[k], va[k]);
            return 1;
        }
    }
    free(va);
    free(vb);
    printf("restarted from t = %.6g s: %zu observables bit for bit, finished %d\n", t_saved,
           count, (int)finished);

    /* The checkpoint cut to half its length: refused by name. */
    f = fopen(path, "rb");
    if (f == NULL || fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) <= 0) return 1;
    rewind(f);
    bytes = (char *)malloc((size_t)len);
    if (bytes == NULL || fread(bytes, 1, (size_t)len, f) != (size_t)len) return 1;
    fclose(f);
    f = fopen(cut, "wb");
    if (f == NULL || fwrite(bytes, 1, (size_t)len / 2, f) != (size_t)len / 2) return 1;
    fclose(f);
    free(bytes);
    if (mi_sim_checkpoint_load(again, cut) != MI_BAD_CHECKPOINT) {
        fprintf(stderr, "a cut checkpoint was not refused\n");
        return 1;
    }
    msg = last_error(again);
    printf("cut checkpoint: %s\n", msg);
    if (msg == NULL || strstr(msg, "truncated") == NULL) return 1;
    free(msg);
    check(again, mi_sim_finished(again, &finished), "mi_sim_finished");
    if (!finished) return 1; /* the handle kept its run */
    mi_sim_free(again);
    mi_sim_free(whole);
    return 0;
}
