/* run_file: see run_file.h. */
#include "run_file.h"

#include <stdlib.h>

static size_t h5_count(void *ctx) {
    return cdem_h5_reader_increment_count(ctx);
}
static cdem_status h5_info(void *ctx, size_t index, cdem_increment_info *info, cdem_error *err) {
    return cdem_h5_reader_increment_info(ctx, index, info, err);
}
static cdem_status h5_load(void *ctx, size_t index, cdem_state *s, cdem_error *err) {
    return cdem_h5_reader_load_increment(ctx, index, s, NULL, err);
}
static void h5_close(void *ctx) {
    cdem_h5_reader_close(ctx);
}
static cdem_h5_reader *h5_reader(void *ctx) {
    return ctx;
}

static const cdem_analysis_source h5_ops = {
    h5_count,  /* count */
    h5_info,   /* info */
    h5_load,   /* load */
    h5_close,  /* close: closes the reader with the context */
    h5_reader, /* reader */
};

cdem_status cdem_analysis_open(const char *path, cdem_analysis **out, cdem_error *err) {
    *out = NULL;
    cdem_h5_reader *r;
    CDEM_TRY(cdem_h5_reader_open(path, &r, err));
    return cdem_analysis_open_reader(r, path, out, err);
}

cdem_status cdem_analysis_open_reader(cdem_h5_reader *r, const char *path, cdem_analysis **out,
                                      cdem_error *err) {
    *out = NULL;
    cdem_params p;
    cdem_status st = cdem_h5_reader_params(r, &p, err);
    if (st != CDEM_OK) {
        cdem_h5_reader_close(r);
        return st;
    }
    st = cdem_analysis_open_source(&h5_ops, r, &p, out, err);
    if (st != CDEM_OK)
        cdem_error_prefix(err, "%s", path);
    else
        cdem_analysis_set_name(*out, path);
    return st;
}
