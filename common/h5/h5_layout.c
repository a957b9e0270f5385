/* h5_layout: the tables that say what the run file holds (docs/format.md, "Layout"): the
 * /series columns, the per-element datasets of an increment (driven by CDEM_STATE_FIELDS,
 * state.h), the members of /increments/index and /checkpoint/index, and the checks every
 * index row must pass. Writer, reader and resume all walk these tables, so a new column or
 * index member is one row here (and its docs). The table lengths are fixed in h5_internal.h
 * (they size arrays of handles); the static_asserts below keep them honest.
 * Each increment starts at a chunk boundary (h5i_chunk_end), so compressed chunks are
 * written once. */
#include "h5_internal.h"

#include <assert.h>
#include <math.h>
#include <string.h>

#define SCOL(field, type)                                                                          \
    { #field, type, offsetof(cdem_series_sample, field) }
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
};
#undef SCOL
static_assert(sizeof h5i_series_columns / sizeof h5i_series_columns[0] == N_SERIES,
              "N_SERIES (h5_internal.h) is the length of the table");

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

/* Checks one index row against the previous row (NULL for the first) and the extents of
 * the element datasets; NULL when it is valid, otherwise what is wrong. Files written
 * before the index carried a checksum (Fletcher-32) rely on these checks alone: a flipped
 * bit gave a time of 461 s in a 220 s run, or a net displacement of 5.7e78 m. */
const char *h5i_bad_index_row(const index_row *row, const index_row *prev, hsize_t data_ext,
                              hsize_t stress_ext) {
    if (row->number < 0 || (prev && row->number <= prev->number))
        return "increment numbers must be >= 0 and increasing";
    if (row->step < 0 || (prev && row->step < prev->step))
        return "its step is negative or smaller than the previous increment's";
    if (!isfinite(row->time) || row->time < 0.0 || (prev && row->time < prev->time))
        return "its time is not a finite number of seconds, >= 0 and >= the previous "
               "increment's";
    if (row->phase < CDEM_PHASE_EQUILIBRATION || row->phase > CDEM_PHASE_SETTLING)
        return "its phase is not 0, 1 or 2";
    if (!isfinite(row->net_displacement) || !isfinite(row->axial_strain) ||
        !isfinite(row->differential_stress) || isinf(row->sea_level))
        return "its net displacement, axial strain, differential stress or sea level is not a "
               "finite number";
    if (row->n < 0 || (hsize_t)row->n > MAX_ELEMENTS)
        return "element count n out of range";
    if (row->offset < 0 || (hsize_t)row->offset > data_ext ||
        (hsize_t)row->n > data_ext - (hsize_t)row->offset)
        return "rows offset..offset+n lie beyond the element datasets";
    if (row->has_stress != 0 && row->has_stress != 1)
        return "has_stress is neither 0 nor 1";
    if (row->has_stress && (row->stress_offset < 0 || (hsize_t)row->stress_offset > stress_ext ||
                            (hsize_t)row->n > stress_ext - (hsize_t)row->stress_offset))
        return "rows stress_offset..stress_offset+n lie beyond sxx, syy, sxy";
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
