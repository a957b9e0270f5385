/* h5_reader_v1: the version-1 layout, still read (docs/format.md, "Version 1"): one group
 * /increments/NNNNNN per increment, its info in the group's attributes and one dataset per
 * element field. Increments are listed by iterating the groups (an unclosed file's
 * incompletely flushed group is left out) and sorted by number. Nothing writes version 1. */
#include "h5_internal.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_incr(const void *a, const void *b) {
    int32_t x = ((const incr_entry *)a)->info.number, y = ((const incr_entry *)b)->info.number;
    return (x > y) - (x < y);
}

typedef struct {
    cdem_h5_reader *r;  /* reader being filled */
    cdem_error *err;    /* where a failure goes */
    cdem_status status; /* first failure */
} scan_ctx;

/* Reads the info attributes of one increment group. */
static cdem_status read_incr_info(cdem_h5_reader *r, hid_t g, const char *name,
                                  cdem_increment_info *info, cdem_error *err) {
    memset(info, 0, sizeof *info);
    info->sea_level = NAN;
    int64_t n = -1;
    struct {
        const char *key; /* attribute name */
        hid_t type;      /* memory type to read as */
        void *dst;       /* destination field of info */
    } fields[] = {
        {"number", H5T_NATIVE_INT32, &info->number},
        {"step", H5T_NATIVE_INT64, &info->step},
        {"time", H5T_NATIVE_DOUBLE, &info->time},
        {"phase", H5T_NATIVE_INT32, &info->phase},
        {"net_displacement", H5T_NATIVE_DOUBLE, &info->net_displacement},
        {"axial_strain", H5T_NATIVE_DOUBLE, &info->axial_strain},
        {"differential_stress", H5T_NATIVE_DOUBLE, &info->differential_stress},
        {"sea_level", H5T_NATIVE_DOUBLE, &info->sea_level},
        {"n", H5T_NATIVE_INT64, &n},
    };
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        int rc = h5i_get_num_attr(g, fields[i].key, fields[i].type, fields[i].dst);
        if (rc != 0)
            return H5FAIL(err, CDEM_ERR_FORMAT,
                          "%s: /increments/%s: attribute '%s' is %s (a numeric scalar is "
                          "required)",
                          r->path, name, fields[i].key, rc > 0 ? "missing" : "unreadable");
    }
    if (n < 0 || (hsize_t)n > MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: /increments/%s: attribute n = %lld (allowed 0..%d)", r->path, name,
                         (long long)n, INT32_MAX);
    info->n_elements = n;
    htri_t hs = H5Lexists(g, "sxx", H5P_DEFAULT);
    if (hs < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: /increments/%s: cannot look for sxx", r->path,
                      name);
    info->has_stress = hs > 0;
    return CDEM_OK;
}

static herr_t scan_increment(hid_t group, const char *name, const H5L_info_t *li, void *data) {
    (void)li;
    scan_ctx *c = data;
    cdem_h5_reader *r = c->r;
    if (r->n_incr == r->cap_incr) {
        size_t cap = r->cap_incr ? 2 * r->cap_incr : 64;
        incr_entry *e = realloc(r->incr, cap * sizeof *e);
        if (!e) {
            c->status = CDEM_FAIL(c->err, CDEM_ERR_NOMEM, "out of memory listing increments");
            return -1;
        }
        r->incr = e;
        r->cap_incr = cap;
    }
    if (strlen(name) >= sizeof r->incr[0].name) {
        c->status =
            CDEM_FAIL(c->err, CDEM_ERR_FORMAT,
                      "%s: /increments/%.40s...: name too long for an increment", r->path, name);
        return -1;
    }
    hid_t g = H5Gopen2(group, name, H5P_DEFAULT);
    incr_entry *e = &r->incr[r->n_incr];
    snprintf(e->name, sizeof e->name, "%s", name);
    if (g < 0)
        c->status =
            H5FAIL(c->err, CDEM_ERR_FORMAT, "%s: cannot open group /increments/%s", r->path, name);
    else
        c->status = read_incr_info(r, g, name, &e->info, c->err);
    if (g >= 0)
        H5Gclose(g);
    if (c->status != CDEM_OK && r->unclosed) {
        /* The writer died while flushing this increment: leave it out. */
        r->n_skipped++;
        c->status = CDEM_OK;
        cdem_error_clear(c->err);
        return 0;
    }
    if (c->status != CDEM_OK)
        return -1;
    r->n_incr++;
    return 0;
}

/* Opens /increments/<g>/<name>, checks class and length, reads it into dst. */
static cdem_status read_element_dataset(cdem_h5_reader *r, hid_t g, const char *gname, size_t k,
                                        hsize_t n, void *dst, cdem_error *err) {
    const element_field *fd = &h5i_element_fields[k];
    hid_t ds = H5Dopen2(g, fd->name, H5P_DEFAULT);
    if (ds < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: dataset /increments/%s/%s is missing or corrupt",
                      r->path, gname, fd->name);
    cdem_status st = CDEM_OK;
    hid_t t = H5Dget_type(ds), sp = H5Dget_space(ds);
    H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
    H5T_class_t want = fd->type == CDEM_FIELD_F64 ? H5T_FLOAT : H5T_INTEGER;
    hsize_t dims[2] = {0, 0};
    int rank = sp >= 0 ? H5Sget_simple_extent_ndims(sp) : -1;
    if (rank >= 0 && rank <= 2)
        H5Sget_simple_extent_dims(sp, dims, NULL);
    if (cls != want)
        st = H5FAIL(err, CDEM_ERR_FORMAT,
                    "%s: dataset /increments/%s/%s has type class %d (expected %s)", r->path, gname,
                    fd->name, (int)cls, want == H5T_FLOAT ? "float" : "integer");
    else if (rank != 1 || dims[0] != n)
        st = H5FAIL(err, CDEM_ERR_FORMAT,
                    "%s: dataset /increments/%s/%s has rank %d and length %llu (expected a 1-D "
                    "dataset of %llu values, the element count)",
                    r->path, gname, fd->name, rank, (unsigned long long)dims[0],
                    (unsigned long long)n);
    else if (n > 0 &&
             H5Dread(ds, h5i_el_mem_type(fd->type), H5S_ALL, H5S_ALL, H5P_DEFAULT, dst) < 0)
        st = H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot read dataset /increments/%s/%s (corrupt?)",
                    r->path, gname, fd->name);
    if (t >= 0)
        H5Tclose(t);
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    return st;
}

static cdem_status load_into(cdem_h5_reader *r, hid_t g, const incr_entry *e, cdem_state *s,
                             cdem_error *err) {
    hsize_t n = (hsize_t)e->info.n_elements;
    int nstress = 0;
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        if (!h5i_element_fields[k].optional)
            continue;
        htri_t ex = H5Lexists(g, h5i_element_fields[k].name, H5P_DEFAULT);
        if (ex < 0)
            return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot look up /increments/%s/%s", r->path,
                          e->name, h5i_element_fields[k].name);
        nstress += ex > 0;
    }
    if (nstress != 0 && nstress != 3)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: /increments/%s has %d of the 3 stress datasets sxx, syy, sxy (all "
                         "or none allowed)",
                         r->path, e->name, nstress);
    /* Check the length before allocating for it: n comes from an attribute. */
    hid_t ids = H5Dopen2(g, "id", H5P_DEFAULT);
    hid_t sp = ids >= 0 ? H5Dget_space(ids) : -1;
    hssize_t len = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    /* A dataspace can claim any length while its storage was never written (HDF5 then
     * returns fill values): an 89 kB file claiming 2e9 elements made the reader allocate
     * ~100 GB (fuzz_h5). A written dataset has storage. */
    hsize_t stored = ids >= 0 && len > 0 ? H5Dget_storage_size(ids) : 0;
    if (sp >= 0)
        H5Sclose(sp);
    if (ids >= 0)
        H5Dclose(ids);
    if (len < 0 || (hsize_t)len != n)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: dataset /increments/%s/id is %s (attribute n = %llu)", r->path,
                         e->name, len < 0 ? "missing or unreadable" : "of another length",
                         (unsigned long long)n);
    if (n > READER_MAX_ELEMENTS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: /increments/%s claims %llu elements; this reader refuses more than "
                         "%llu (corrupt file?)",
                         r->path, e->name, (unsigned long long)n,
                         (unsigned long long)READER_MAX_ELEMENTS);
    if (n > 0 && stored == 0)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: dataset /increments/%s/id claims %llu elements but none was ever "
                         "written (truncated or corrupt file)",
                         r->path, e->name, (unsigned long long)n);
    cdem_state_free(s);
    CDEM_TRY(cdem_state_init(s, (size_t)n, nstress == 3, err));
    for (size_t k = 0; k < N_ELEMENT_FIELDS; k++) {
        if (h5i_element_fields[k].optional && nstress == 0)
            continue;
        CDEM_TRY(read_element_dataset(r, g, e->name, k, n, h5i_element_array(s, k), err));
    }
    s->n = (size_t)n;
    int32_t next = 0;
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] >= next)
            next = s->id[i] == INT32_MAX ? INT32_MAX : s->id[i] + 1;
    s->next_id = next;
    return CDEM_OK;
}

/* Declared in h5_internal.h (what it does is said there). */
cdem_status h5i_v1_list_increments(cdem_h5_reader *r, cdem_error *err) {
    const char *path = r->path;
    htri_t ex = H5Lexists(r->file, "increments", H5P_DEFAULT);
    if (ex <= 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: group /increments is missing", path);
    scan_ctx c = {r, err, CDEM_OK};
    hsize_t idx = 0;
    if (H5Literate_by_name(r->file, "increments", H5_INDEX_NAME, H5_ITER_INC, &idx, scan_increment,
                           &c, H5P_DEFAULT) < 0) {
        if (c.status != CDEM_OK)
            return c.status;
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot list group /increments", path);
    }
    if (r->n_incr > 1)
        qsort(r->incr, r->n_incr, sizeof *r->incr, cmp_incr);
    /* the values of each group's attributes, as those of an index row (h5_layout.c) */
    index_row prev = {0};
    for (size_t i = 0; i < r->n_incr; i++) {
        const cdem_increment_info *in = &r->incr[i].info;
        const index_row row = {.number = in->number,
                               .phase = in->phase,
                               .step = in->step,
                               .time = in->time,
                               .net_displacement = in->net_displacement,
                               .axial_strain = in->axial_strain,
                               .differential_stress = in->differential_stress,
                               .sea_level = in->sea_level,
                               .n = in->n_elements,
                               .has_stress = in->has_stress};
        char buf[300];
        const char *why = h5i_bad_index_values(&row, i ? &prev : NULL, buf, sizeof buf);
        if (why)
            return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                             "%s: /increments/%s (increment %d): %s: damaged file", path,
                             r->incr[i].name, (int)in->number, why);
        prev = row;
    }
    return CDEM_OK;
}

/* Declared in h5_internal.h (what it does is said there). */
cdem_status h5i_v1_load(cdem_h5_reader *r, const incr_entry *e, cdem_state *s, cdem_error *err) {
    char gpath[64];
    snprintf(gpath, sizeof gpath, "increments/%s", e->name);
    hid_t g = H5Gopen2(r->file, gpath, H5P_DEFAULT);
    if (g < 0)
        return H5FAIL(err, CDEM_ERR_FORMAT, "%s: cannot open group /%s", r->path, gpath);
    cdem_status st = load_into(r, g, e, s, err);
    H5Gclose(g);
    if (st != CDEM_OK)
        cdem_state_free(s);
    return st;
}
