/* h5_layout: the tables that say what the run file holds (docs/format.md, "Layout"): the
 * /series columns, the per-element datasets of an increment (driven by CDEM_STATE_FIELDS,
 * state.h), the members of /increments/index and /checkpoint/index, and the checks every
 * index row must pass. Writer, reader and resume all walk these tables, so a new column or
 * index member is one row here (and its docs); a process's own columns are its rows
 * CDEM_PROCESS_SERIES (common/processes/<id>.h, h5format.h), read from processes.def. The physical
 * bounds of the values (an index row, an element, a series sample; CDEM_FILE_MAX_*, h5format.h) are
 * checked here too, by the reader on every value it reads and by the writer on every value it
 * writes, so that what one writes the other reads. The table lengths are fixed in h5_internal.h
 * (they size arrays of handles); the static_asserts below keep them honest.
 * Each increment starts at a chunk boundary (h5i_chunk_end), so compressed chunks are
 * written once. */
#include "h5_internal.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SCOL(field, type)                                                                          \
    { #field, type, offsetof(cdem_series_sample, field), 0, 0, 0.0, 0.0, NULL, NULL }
#define SCOL_OPTIONAL(field, type)                                                                 \
    { #field, type, offsetof(cdem_series_sample, field), 1, 0, 0.0, 0.0, NULL, NULL }
/* a process's column: optional (a file written before it, or by a run without the process's
 * code, lacks it) */
#define CDEM_PROCESS_SERIES(name, unit, lo, hi, label)                                             \
    {#name, COL_F64, offsetof(cdem_series_sample, name), 1, 1, lo, hi, #lo ".." #hi, unit},
const series_column h5i_series_columns[] = {
    SCOL(step, COL_I64),
    SCOL(time, COL_F64),
    SCOL(kinetic_energy, COL_F64),
    SCOL(contacts, COL_I64),
    SCOL(bonds, COL_I64),
    SCOL(n_elements, COL_I64),
    SCOL(net_displacement, COL_F64),
    SCOL(boundary_force_x, COL_F64),
    SCOL(boundary_force_y, COL_F64),
    SCOL(base_force_x, COL_F64),
    SCOL(base_force_y, COL_F64),
    SCOL(axial_strain, COL_F64),
    SCOL(differential_stress, COL_F64),
    SCOL(sea_level, COL_F64),
    SCOL_OPTIONAL(left_wall_force_x, COL_F64),
    SCOL_OPTIONAL(left_wall_force_y, COL_F64),
    SCOL_OPTIONAL(right_wall_force_x, COL_F64),
    SCOL_OPTIONAL(right_wall_force_y, COL_F64),
#include "processes.def"
};
#undef SCOL
#undef SCOL_OPTIONAL
#undef CDEM_PROCESS_SERIES
static_assert(sizeof h5i_series_columns / sizeof h5i_series_columns[0] == N_SERIES,
              "N_SERIES (h5_internal.h) is the length of the table");
static_assert(N_SERIES <= 32, "h5i_bad_sample's mask of absent columns has 32 bits");

/* The rows of CDEM_STATE_FIELDS marked in_increments, in table order (h5_internal.h). The
 * list is built by the preprocessor so that its length is a compile-time constant. */
#define IF_IN_INCREMENTS_0(...)
#define IF_IN_INCREMENTS_1(...) __VA_ARGS__
#define INCREMENT_FIELD(name, ctype, ftype, in_increments, stress)                                 \
    IF_IN_INCREMENTS_##in_increments(                                                              \
        {#name, "/increments/" #name, ftype, stress, offsetof(cdem_state, name)}, )
const element_field h5i_element_fields[] = {CDEM_STATE_FIELDS(INCREMENT_FIELD)};
#undef INCREMENT_FIELD
static_assert(sizeof h5i_element_fields / sizeof h5i_element_fields[0] == N_ELEMENT_FIELDS,
              "H5I_N_ELEMENT_FIELDS counts the same rows");

/* The array of element field k in s. */
void *h5i_element_array(const cdem_state *s, size_t k) {
    void *p;
    memcpy(&p, (const char *)s + h5i_element_fields[k].offset, sizeof p);
    return p;
}

/* Index of the first stress field (the stress datasets share one extent). */
size_t h5i_first_stress_field(void) {
    size_t k = 0;
    while (k < N_ELEMENT_FIELDS && !h5i_element_fields[k].optional)
        k++;
    return k;
}

hid_t h5i_el_file_type(cdem_field_type t) {
    return t == CDEM_FIELD_I32   ? H5T_STD_I32LE
           : t == CDEM_FIELD_U32 ? H5T_STD_U32LE
                                 : H5T_IEEE_F64LE;
}

hid_t h5i_el_mem_type(cdem_field_type t) {
    return t == CDEM_FIELD_I32   ? H5T_NATIVE_INT32
           : t == CDEM_FIELD_U32 ? H5T_NATIVE_UINT32
                                 : H5T_NATIVE_DOUBLE;
}

#define IXM(field, kind)                                                                           \
    { #field, offsetof(index_row, field), kind }
const index_member h5i_index_members[] = {
    IXM(number, IX_I32),
    IXM(step, IX_I64),
    IXM(time, IX_F64),
    IXM(phase, IX_I32),
    IXM(net_displacement, IX_F64),
    IXM(axial_strain, IX_F64),
    IXM(differential_stress, IX_F64),
    IXM(sea_level, IX_F64),
    IXM(offset, IX_I64),
    IXM(n, IX_I64),
    IXM(has_stress, IX_I32),
    IXM(stress_offset, IX_I64),
};
#undef IXM
static_assert(sizeof h5i_index_members / sizeof h5i_index_members[0] == N_INDEX_MEMBERS,
              "N_INDEX_MEMBERS (h5_internal.h) is the length of the table");

#define CKM(field, kind)                                                                           \
    { #field, offsetof(ckpt_row, field), kind }
const index_member h5i_ckpt_members[] = {
    CKM(sequence, IX_I64), CKM(increment, IX_I32), CKM(step, IX_I64),
    CKM(length, IX_I64),   CKM(checksum, IX_I64),
};
#undef CKM
static_assert(sizeof h5i_ckpt_members / sizeof h5i_ckpt_members[0] == N_CKPT_MEMBERS,
              "N_CKPT_MEMBERS (h5_internal.h) is the length of the table");

const char *const cdem_stop_reasons[] = {
    "running",           "completed",     "interrupted", "stopped-early",
    "numerical-failure", "write-failure", "error",       NULL};

int h5i_known_stop_reason(const char *reason) {
    if (!reason[0])
        return 1; /* none recorded */
    for (size_t k = 0; cdem_stop_reasons[k]; k++)
        if (!strcmp(reason, cdem_stop_reasons[k]))
            return 1;
    return 0;
}

/* |v| <= bound, and not NaN. */
static int within(double v, double bound) {
    return fabs(v) <= bound;
}

/* Formats into buf and returns it: the checks below name the value they refuse. */
static const char *say_why(char *buf, size_t cap, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static const char *say_why(char *buf, size_t cap, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, cap, fmt, ap);
    va_end(ap);
    return buf;
}

const char *h5i_bad_index_values(const index_row *row, const index_row *prev, char *buf,
                                 size_t cap) {
    if (row->number < 0 || (prev && row->number <= prev->number))
        return say_why(buf, cap,
                       "increment numbers must be >= 0 and increasing (number %d after %d)",
                       (int)row->number, prev ? (int)prev->number : -1);
    if (row->step < 0 || (prev && row->step < prev->step))
        return say_why(buf, cap,
                       "its step %lld is negative or smaller than the previous increment's (%lld)",
                       (long long)row->step, prev ? (long long)prev->step : 0LL);
    if (!(row->time >= 0.0 && row->time <= CDEM_FILE_MAX_TIME) || (prev && row->time < prev->time))
        return say_why(buf, cap,
                       "its time %.17g s must be a finite number of seconds in 0..1e9 s, >= the "
                       "previous increment's (%.17g s)",
                       row->time, prev ? prev->time : 0.0);
    if (row->phase < CDEM_PHASE_EQUILIBRATION || row->phase > CDEM_PHASE_SETTLING)
        return say_why(buf, cap, "its phase %d is not 0, 1 or 2", (int)row->phase);
    if (!within(row->net_displacement, CDEM_FILE_MAX_LENGTH))
        return say_why(buf, cap,
                       "its net displacement %.15g m must be finite and within -1e7..1e7 m",
                       row->net_displacement);
    if (!within(row->axial_strain, CDEM_FILE_MAX_STRAIN))
        return say_why(buf, cap, "its axial strain %.15g must be finite and within -1e6..1e6",
                       row->axial_strain);
    if (!within(row->differential_stress, CDEM_FILE_MAX_STRESS))
        return say_why(
            buf, cap, "its differential stress %.15g N/m must be finite and within -1e20..1e20 N/m",
            row->differential_stress);
    if (!isnan(row->sea_level) && !within(row->sea_level, CDEM_FILE_MAX_LENGTH))
        return say_why(buf, cap, "its sea level %.15g m must be NaN (none) or within -1e7..1e7 m",
                       row->sea_level);
    if (row->n < 0 || (hsize_t)row->n > MAX_ELEMENTS)
        return say_why(buf, cap, "its element count n = %lld is out of range", (long long)row->n);
    if (row->has_stress != 0 && row->has_stress != 1)
        return say_why(buf, cap, "has_stress is %d, neither 0 nor 1", (int)row->has_stress);
    return NULL;
}

/* Checks one index row against the previous row (NULL for the first) and the extents of
 * the element datasets; NULL when it is valid, otherwise what is wrong (in buf). Files
 * written before the index carried a checksum (Fletcher-32) rely on these checks alone: a
 * flipped bit gave a time of 461 s in a 220 s run, or a net displacement of 5.7e78 m. */
const char *h5i_bad_index_row(const index_row *row, const index_row *prev, hsize_t data_ext,
                              hsize_t stress_ext, char *buf, size_t cap) {
    const char *why = h5i_bad_index_values(row, prev, buf, cap);
    if (why)
        return why;
    if (row->offset < 0 || (hsize_t)row->offset > data_ext ||
        (hsize_t)row->n > data_ext - (hsize_t)row->offset)
        return say_why(buf, cap,
                       "rows offset..offset+n (%lld..%lld) lie beyond the element datasets (%llu "
                       "rows)",
                       (long long)row->offset, (long long)row->offset + (long long)row->n,
                       (unsigned long long)data_ext);
    if (row->has_stress && (row->stress_offset < 0 || (hsize_t)row->stress_offset > stress_ext ||
                            (hsize_t)row->n > stress_ext - (hsize_t)row->stress_offset))
        return say_why(buf, cap,
                       "rows stress_offset..stress_offset+n (%lld..%lld) lie beyond sxx, syy, sxy "
                       "(%llu rows)",
                       (long long)row->stress_offset,
                       (long long)row->stress_offset + (long long)row->n,
                       (unsigned long long)stress_ext);
    return NULL;
}

const char *h5i_bad_element(const cdem_state *s, size_t i, const char **field, char *buf,
                            size_t cap) {
    const double xy[2] = {s->x[i], s->y[i]};
    for (int k = 0; k < 2; k++)
        if (!within(xy[k], CDEM_FILE_MAX_LENGTH)) {
            *field = k ? "y" : "x";
            return say_why(buf, cap, "%s = %.15g m must be a finite position within -1e7..1e7 m",
                           *field, xy[k]);
        }
    *field = "radius";
    if (!(s->radius[i] > 0.0 && s->radius[i] <= CDEM_FILE_MAX_RADIUS))
        return say_why(buf, cap, "radius %.15g m must be finite, > 0 and at most 1e5 m",
                       s->radius[i]);
    *field = "layer";
    if (s->layer[i] < 0)
        return say_why(buf, cap, "layer %d must be >= 0", (int)s->layer[i]);
    if (!s->has_stress)
        return NULL;
    const double *stress[3] = {s->sxx, s->syy, s->sxy};
    static const char *const names[3] = {"sxx", "syy", "sxy"};
    for (int k = 0; k < 3; k++)
        if (!within(stress[k][i], CDEM_FILE_MAX_STRESS)) {
            *field = names[k];
            return say_why(buf, cap, "%s = %.15g N/m must be finite and within -1e20..1e20 N/m",
                           names[k], stress[k][i]);
        }
    return NULL;
}

typedef struct {
    int32_t id;
    size_t row;
} id_row;

static int cmp_id_row(const void *a, const void *b) {
    const id_row *x = a, *y = b;
    if (x->id != y->id)
        return (x->id > y->id) - (x->id < y->id);
    return (x->row > y->row) - (x->row < y->row);
}

int h5i_find_duplicate_id(const int32_t *id, size_t n, size_t *first, size_t *second) {
    int ascending = 1;
    for (size_t i = 1; i < n && ascending; i++)
        ascending = id[i - 1] < id[i];
    if (ascending)
        return 0;
    id_row *v = malloc(n * sizeof *v);
    if (!v)
        return -1;
    for (size_t i = 0; i < n; i++)
        v[i] = (id_row){id[i], i};
    qsort(v, n, sizeof *v, cmp_id_row);
    int found = 0;
    for (size_t i = 1; i < n && !found; i++)
        if (v[i].id == v[i - 1].id) {
            *first = v[i - 1].row;
            *second = v[i].row;
            found = 1;
        }
    free(v);
    return found;
}

const char *h5i_bad_sample(const cdem_series_sample *q, int blown_up, unsigned absent,
                           const char **column, char *buf, size_t cap) {
    const int64_t counts[3] = {q->contacts, q->bonds, q->n_elements};
    static const char *const count_names[3] = {"contacts", "bonds", "n_elements"};
    for (int k = 0; k < 3; k++)
        if (counts[k] < 0) {
            *column = count_names[k];
            return say_why(buf, cap, "%s = %lld must be >= 0", count_names[k],
                           (long long)counts[k]);
        }
    for (size_t c = 0; c < N_SERIES; c++) {
        const series_column *sc = &h5i_series_columns[c];
        if (sc->type != COL_F64 || !strcmp(sc->name, "time"))
            continue; /* step and time: the order checks of the reader */
        double v;
        memcpy(&v, (const char *)q + sc->offset, sizeof v);
        *column = sc->name;
        const int sea = !strcmp(sc->name, "sea_level");
        if (isnan(v) && (sea || sc->process || (absent >> c & 1u)))
            continue; /* no sedimentation, a process that is off; a column the file lacks */
        if (!isfinite(v)) {
            if (blown_up)
                continue; /* a run that blew up: its last samples may hold Inf or NaN */
            return say_why(buf, cap, "%s = %.15g must be a finite number", sc->name, v);
        }
        if ((sea || !strcmp(sc->name, "net_displacement")) && !within(v, CDEM_FILE_MAX_LENGTH))
            return say_why(buf, cap, "%s = %.15g m must be within -1e7..1e7 m", sc->name, v);
        if (!strcmp(sc->name, "kinetic_energy") && v < 0.0)
            return say_why(buf, cap, "kinetic_energy = %.15g J/m must be >= 0", v);
        if (sc->process && !(v >= sc->lo && v <= sc->hi))
            return say_why(buf, cap, "%s = %.15g %s must be within %s %s", sc->name, v, sc->unit,
                           sc->range, sc->unit);
        if (!strcmp(sc->name, "axial_strain") && !within(v, CDEM_FILE_MAX_STRAIN))
            return say_why(buf, cap, "axial_strain = %.15g must be within -1e6..1e6", v);
        if (!strcmp(sc->name, "differential_stress") && !within(v, CDEM_FILE_MAX_STRESS))
            return say_why(buf, cap,
                           "differential_stress = %.15g N/m must be within -1e20..1e20 N/m", v);
    }
    return NULL;
}

/* Each increment starts at a chunk boundary of the element datasets, so every compressed
 * chunk is written once and never rewritten (rewriting a partly filled compressed chunk
 * at every append moves it and, in SWMR mode, leaves the old space unused: the file grew
 * 2.4-fold). The padding rows belong to no increment; they cost little, but not nothing
 * (CHUNK_ELEMS, h5_internal.h). */
hsize_t h5i_chunk_end(hsize_t rows, hsize_t chunk_rows) {
    return (rows + chunk_rows - 1) / chunk_rows * chunk_rows;
}

/* Rows per chunk of the 1-D chunked dataset ds; 0 when it cannot be read. */
hsize_t h5i_chunk_rows_of(hid_t ds) {
    hid_t dcpl = H5Dget_create_plist(ds);
    hsize_t rows = 0;
    if (dcpl < 0 || H5Pget_layout(dcpl) != H5D_CHUNKED || H5Pget_chunk(dcpl, 1, &rows) != 1)
        rows = 0;
    if (dcpl >= 0)
        H5Pclose(dcpl);
    return rows;
}
