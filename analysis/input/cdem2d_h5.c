/* cdem2d_h5: writes an imported cdem2D folder (cdem2d.h) into a cdem file with the
 * h5format writer, so it then behaves as a native run. Parameters are the defaults with the
 * recognised keys applied (mode; calculate_stress when forces are present); the summary is
 * modelparameters.txt verbatim. Kept apart from cdem2d.c so the parser links without HDF5. */
#include "cdem2d.h"

#include "outfile.h"
#include "params.h"

#include <stdio.h>
#include <string.h>

#ifndef CDEM_VERSION
#define CDEM_VERSION "0.0.0"
#endif

typedef struct {
    const char *dir;   /* the folder, for the file's source attribute */
    const char *out;   /* output path */
    cdem_h5_writer *w; /* created at the first increment (the meta is known by then) */
    cdem_params p;     /* parameters written into the file */
    const cdem_cdem2d_meta *meta;
} h5_sink_ctx;

static cdem_status write_sink(void *user, const cdem_increment_info *info, const cdem_state *s,
                              cdem_error *err) {
    h5_sink_ctx *c = user;
    if (!c->w) {
        cdem_params_defaults(&c->p);
        if (c->meta->mode >= 0)
            c->p.mode = (cdem_mode)c->meta->mode;
        c->p.calculate_stress = c->meta->has_forces;
        char source[CDEM_PATH_MAX + 32];
        snprintf(source, sizeof source, "cdem2d-import:%s", c->dir);
        cdem_run_meta rm = {&c->p, c->meta->params_text, c->meta->params_text, CDEM_VERSION,
                            source, (long)c->meta->n_increments};
        CDEM_TRY(cdem_h5_writer_create(c->out, &rm, &c->w, err));
    }
    return cdem_h5_writer_write_increment(c->w, info, s, err);
}

/* The meta (params text, mode) is read before the first increment is delivered, so the
 * writer can be created lazily inside the sink; meta is passed by pointer to the context. */
cdem_status cdem_cdem2d_import_h5(const char *dir, const char *out_path, cdem_error *err) {
    /* The HDF5 writer keeps a sidecar (.xmf) that names the file, so the import is written
     * under its final name and removed on failure (with the sidecar) instead of renamed. */
    cdem_outfile of;
    CDEM_TRY(cdem_outfile_begin(&of, out_path, err)); /* writable destination, up front */
    cdem_cdem2d_meta meta;
    h5_sink_ctx c;
    memset(&c, 0, sizeof c);
    c.dir = dir;
    c.out = out_path;
    c.meta = &meta;
    cdem_status st = cdem_cdem2d_import(dir, write_sink, &c, &meta, err);
    if (c.w) {
        if (st == CDEM_OK)
            st = cdem_h5_writer_set_stop_reason(c.w, "completed", "imported from cdem2D", err);
        cdem_error e2;
        cdem_status st2 = cdem_h5_writer_close(c.w, &e2);
        if (st == CDEM_OK && st2 != CDEM_OK) {
            *err = e2;
            st = st2;
        }
    }
    cdem_cdem2d_meta_free(&meta);
    if (st != CDEM_OK && c.w) {
        remove(out_path);
        char xmf[CDEM_OUTFILE_PATH_MAX + 8];
        size_t stem = strlen(out_path);
        const char *dot = strrchr(out_path, '.'), *slash = strrchr(out_path, '/');
        if (dot && (!slash || dot > slash) &&
            (!strcmp(dot, ".h5") || !strcmp(dot, ".hdf5") || !strcmp(dot, ".hdf")))
            stem = (size_t)(dot - out_path);
        snprintf(xmf, sizeof xmf, "%.*s.xmf", (int)stem, out_path);
        remove(xmf);
    }
    return st;
}
