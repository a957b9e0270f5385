/* test_absurd: run files whose bytes pass every checksum but whose values are absurd (issue 35,
 * item 7: 11 h5py-edited outputs were accepted: positions NaN, Inf or 1e300, radius <= 0 with
 * compute printing 1288 nan, a net displacement of 1.75e78 m in a checksum-less index, an
 * index replaced by a 5 x 5 float dataset read as "increments: 0", kinetic energy Inf, a float
 * /series/step, a stop reason of the bytes 0xFF 0xFE printed raw). Each case is made here
 * with the HDF5 C API on a file the writer wrote, and the reader must refuse it with a
 * message naming the file, the dataset, the row (and increment or element id) and the value
 * (docs/format.md, "Physical bounds"). The other side of the promise: the writer refuses to
 * write such values (a run that produced them has blown up), and a run that blew up, whose
 * last samples may hold Inf or NaN, stays readable. Files go to $CDEM_TEST_TMP. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "h5format.h"
#include "scratch.h"

#include <hdf5.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#define N_ELEM 30
#define N_INC  4

/* Element i of increment k: a row of discs moving right, ids 10.., stress in every one. */
static void make_state(cdem_state *s, int k) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, N_ELEM, 1, &err), CDEM_OK);
    for (size_t i = 0; i < N_ELEM; i++) {
        size_t at = 0;
        assert_int_equal(cdem_state_append(s, (int32_t)(10 + i), 100.0 * (double)i + k,
                                           50.0 + (double)(i % 3), 50.0, 1.0, (int32_t)(1 + i % 24),
                                           0, 0, &at, &err),
                         CDEM_OK);
        s->sxx[at] = 1e7 + (double)i;
        s->syy[at] = -2e6;
        s->sxy[at] = 3e5;
    }
}

static cdem_increment_info make_info(int k) {
    cdem_increment_info in;
    memset(&in, 0, sizeof in);
    in.number = k;
    in.step = 100 * k;
    in.time = 2.5 * k;
    in.phase = k < 2 ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
    in.net_displacement = k < 2 ? 0.0 : 5.0 * (k - 1);
    in.sea_level = NAN;
    return in;
}

static cdem_series_sample make_sample(int i) {
    cdem_series_sample q;
    memset(&q, 0, sizeof q);
    q.step = 25 * i;
    q.time = 0.625 * i;
    q.kinetic_energy = 1e4 / (1.0 + i);
    q.contacts = 40;
    q.n_elements = N_ELEM;
    q.sea_level = NAN;
    return q;
}

/* A closed run file of N_INC increments, 4 samples before each, the stop reason given. */
static void write_run(const char *path, const char *reason) {
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "", "summary of the absurd test", "9.9.9", "cdem-run", 0};
    cdem_h5_writer *w = NULL;
    cdem_error err;
    if (cdem_h5_writer_create(path, &meta, &w, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    for (int k = 0; k < N_INC; k++) {
        for (int j = 0; j < 4; j++) {
            cdem_series_sample q = make_sample(4 * k + j);
            assert_int_equal(cdem_h5_writer_append_series(w, &q, &err), CDEM_OK);
        }
        cdem_state s;
        make_state(&s, k);
        cdem_increment_info in = make_info(k);
        if (cdem_h5_writer_write_increment(w, &in, &s, &err) != CDEM_OK)
            fail_msg("%s", err.msg);
        cdem_state_free(&s);
    }
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, reason, "4 increments", &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
}

static void remove_run(const char *path) {
    char xmf[1100];
    snprintf(xmf, sizeof xmf, "%.*s.xmf", (int)(strlen(path) - 3), path);
    remove(path);
    remove(xmf);
}

/* The first row of increment k in the element datasets (a member of its commit row). */
static hsize_t offset_of(hid_t f, int k) {
    hid_t ds = H5Dopen2(f, "increments/index", H5P_DEFAULT);
    assert_true(ds >= 0);
    hid_t t = H5Tcreate(H5T_COMPOUND, sizeof(int64_t));
    H5Tinsert(t, "offset", 0, H5T_NATIVE_INT64);
    hsize_t start = (hsize_t)k, one = 1;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &one, NULL);
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &one, NULL);
    int64_t off = -1;
    assert_true(H5Dread(ds, t, ms, fs, H5P_DEFAULT, &off) >= 0);
    H5Sclose(ms);
    H5Sclose(fs);
    H5Tclose(t);
    H5Dclose(ds);
    return (hsize_t)off;
}

/* Writes one value (memory type mt) at row of dataset name, as h5py's d[row] = v does. */
static void poke(const char *path, const char *name, hsize_t row, hid_t mt, const void *v) {
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(f >= 0);
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(ds >= 0);
    hsize_t one = 1;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &one, NULL);
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &row, NULL, &one, NULL);
    assert_true(H5Dwrite(ds, mt, ms, fs, H5P_DEFAULT, v) >= 0);
    H5Sclose(ms);
    H5Sclose(fs);
    H5Dclose(ds);
    H5Fclose(f);
}

/* Value r of the element dataset field of increment k set to v (a double or an int32). */
static void poke_element_f64(const char *path, int k, const char *field, hsize_t r, double v) {
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    const hsize_t row = offset_of(f, k) + r;
    H5Fclose(f);
    char name[64];
    snprintf(name, sizeof name, "increments/%s", field);
    poke(path, name, row, H5T_NATIVE_DOUBLE, &v);
}

/* What opening path and loading every increment and the series gives: CDEM_OK, or the
 * first failure (its message in msg). */
static cdem_status read_all(const char *path, char *msg, size_t cap) {
    cdem_error err;
    cdem_error_clear(&err);
    cdem_h5_reader *r = NULL;
    cdem_status st = cdem_h5_reader_open(path, &r, &err);
    for (size_t i = 0; st == CDEM_OK && i < cdem_h5_reader_increment_count(r); i++) {
        cdem_state s;
        memset(&s, 0, sizeof s);
        st = cdem_h5_reader_load_increment(r, i, &s, NULL, &err);
        cdem_state_free(&s);
    }
    cdem_series_sample *q = NULL;
    size_t nq = 0;
    if (st == CDEM_OK)
        st = cdem_h5_reader_read_series(r, &q, &nq, &err);
    free(q);
    cdem_h5_reader_close(r);
    snprintf(msg, cap, "%s", st == CDEM_OK ? "" : err.msg);
    return st;
}

/* read_all must refuse path as damage with a message holding the file name and every one of
 * the NULL-terminated texts. */
static void assert_refused(const char *path, ...) {
    char msg[CDEM_ERROR_MSG_MAX];
    const cdem_status st = read_all(path, msg, sizeof msg);
    if (st != CDEM_ERR_FORMAT)
        fail_msg("%s was not refused (status %d): %s", path, (int)st, msg);
    if (!strstr(msg, path))
        fail_msg("the message does not name the file: %s", msg);
    va_list ap;
    va_start(ap, path);
    for (const char *want; (want = va_arg(ap, const char *)) != NULL;)
        if (!strstr(msg, want))
            fail_msg("the message lacks \"%s\": %s", want, msg);
    va_end(ap);
}

static void assert_reads(const char *path) {
    char msg[CDEM_ERROR_MSG_MAX];
    if (read_all(path, msg, sizeof msg) != CDEM_OK)
        fail_msg("%s does not read: %s", path, msg);
}

/* ------------------------------------------------------------------ element values */

static void test_absurd_positions(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_pos.h5");
    write_run(path, "completed");
    assert_reads(path);
    const struct {
        const char *field;
        double v;
        const char *shown;
    } cases[] = {{"x", NAN, "x = nan m"},
                 {"x", INFINITY, "x = inf m"},
                 {"y", 1e300, "y = 1e+300 m"},
                 {"y", -2e7, "y = -20000000 m"}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        write_run(path, "completed");
        poke_element_f64(path, 2, cases[c].field, 5, cases[c].v);
        char where[64];
        snprintf(where, sizeof where, "/increments/%s row %llu", cases[c].field,
                 (unsigned long long)(2 * 4096 + 5));
        assert_refused(path, "increment 2", where, "element id 15", cases[c].shown,
                       "within -1e7..1e7 m", NULL);
    }
    remove_run(path);
}

static void test_absurd_radius_layer_stress(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_radius.h5");
    const double radii[] = {0.0, -5.0, 2e5, NAN};
    for (size_t c = 0; c < sizeof radii / sizeof radii[0]; c++) {
        write_run(path, "completed");
        poke_element_f64(path, 1, "radius", 3, radii[c]);
        char shown[128];
        snprintf(shown, sizeof shown, "radius %.17g m must be finite, > 0 and at most 1e5 m",
                 radii[c]);
        assert_refused(path, "increment 1", "/increments/radius row 4099", "element id 13", shown,
                       NULL);
    }
    write_run(path, "completed");
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    const hsize_t row = offset_of(f, 3) + 7;
    H5Fclose(f);
    const int32_t layer = -4;
    poke(path, "increments/layer", row, H5T_NATIVE_INT32, &layer);
    assert_refused(path, "increment 3", "/increments/layer row 12295", "element id 17",
                   "layer -4 must be >= 0", NULL);
    write_run(path, "completed");
    poke_element_f64(path, 0, "sxy", 0, INFINITY);
    assert_refused(path, "increment 0", "/increments/sxy row 0", "element id 10", "sxy = inf N/m",
                   NULL);
    remove_run(path);
}

/* A duplicated id once failed inside the strain code as "duplicate element id 7 at slots 0
 * and 1", naming no file or increment (issue 35, item 10). */
static void test_absurd_duplicate_ids(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_dup.h5");
    write_run(path, "completed");
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    const hsize_t row = offset_of(f, 2);
    H5Fclose(f);
    const int32_t id = 10;
    poke(path, "increments/id", row + 1, H5T_NATIVE_INT32, &id);
    assert_refused(path, "increment 2", "element id 10 appears twice",
                   "/increments/id row 8192 and at row 8193", NULL);
    remove_run(path);
}

/* ------------------------------------------------------------------ the list of increments */

/* A commit row's member set to a value, its checksum made to match again (what a forger, or
 * a writer's bug, can do: docs/format.md, "/increments/commit"). */
static void forge_commit_f64(const char *path, int k, const char *member, double v) {
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t ds = H5Dopen2(f, "increments/commit", H5P_DEFAULT);
    hid_t ft = H5Dget_type(ds);
    const size_t size = H5Tget_size(ft);
    unsigned char row[256];
    assert_true(size == 92 && size <= sizeof row);
    hsize_t start = (hsize_t)k, one = 1;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &one, NULL);
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &one, NULL);
    assert_true(H5Dread(ds, ft, ms, fs, H5P_DEFAULT, row) >= 0);
    const int at = H5Tget_member_index(ft, member);
    assert_true(at >= 0);
    memcpy(row + H5Tget_member_offset(ft, (unsigned)at), &v, 8); /* little-endian host */
    uint64_t h = 0xcbf29ce484222325ull; /* FNV-1a 64 of the 84 bytes and the position */
    unsigned char pos[8];
    for (int i = 0; i < 8; i++)
        pos[i] = (unsigned char)((uint64_t)k >> (8 * i));
    for (int i = 0; i < 92; i++) {
        const unsigned char b = i < 84 ? row[i] : pos[i - 84];
        h = (h ^ b) * 0x100000001b3ull;
    }
    memcpy(row + 84, &h, 8);
    assert_true(H5Dwrite(ds, ft, ms, fs, H5P_DEFAULT, row) >= 0);
    H5Sclose(ms);
    H5Sclose(fs);
    H5Tclose(ft);
    H5Dclose(ds);
    H5Fclose(f);
}

static void test_absurd_commit_row_values(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_commit.h5");
    const struct {
        const char *member;
        double v;
        const char *want;
    } cases[] = {
        {"net_displacement", 1.75e78, "net displacement 1.75e+78 m must be finite and within"},
        {"time", 1e300, "time 1.0000000000000001e+300 s must be a finite number of seconds"},
        {"sea_level", INFINITY, "sea level inf m must be NaN (none) or within -1e7..1e7 m"},
        {"differential_stress", NAN, "differential stress nan N/m must be finite"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        write_run(path, "completed");
        forge_commit_f64(path, 3, cases[c].member, cases[c].v);
        assert_refused(path, "/increments/commit row 3 (increment 3)", cases[c].want, NULL);
    }
    remove_run(path);
}

/* A file written before the commit record, whose index has no checksum either (before issue
 * 19): made from a new file by dropping the record and rewriting the index unfiltered. */
static void make_old_layout(const char *path) {
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t ds = H5Dopen2(f, "increments/index", H5P_DEFAULT);
    hid_t ft = H5Dget_type(ds);
    const hsize_t n = N_INC;
    unsigned char *rows = malloc(n * H5Tget_size(ft));
    assert_true(H5Dread(ds, ft, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) >= 0);
    H5Dclose(ds);
    assert_true(H5Ldelete(f, "increments/index", H5P_DEFAULT) >= 0);
    assert_true(H5Ldelete(f, "increments/commit", H5P_DEFAULT) >= 0);
    hsize_t max = H5S_UNLIMITED, chunk = 64;
    hid_t sp = H5Screate_simple(1, &n, &max), cp = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(cp, 1, &chunk);
    ds = H5Dcreate2(f, "increments/index", ft, sp, H5P_DEFAULT, cp, H5P_DEFAULT);
    assert_true(ds >= 0);
    assert_true(H5Dwrite(ds, ft, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) >= 0);
    free(rows);
    H5Pclose(cp);
    H5Sclose(sp);
    H5Tclose(ft);
    H5Dclose(ds);
    H5Fclose(f);
}

static void test_absurd_old_index(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_old.h5");
    write_run(path, "completed");
    make_old_layout(path);
    assert_reads(path);
    /* the audit's 1.75e78 m net displacement in a checksum-less index */
    hid_t t = H5Tcreate(H5T_COMPOUND, sizeof(double));
    H5Tinsert(t, "net_displacement", 0, H5T_NATIVE_DOUBLE);
    const double huge = 1.75e78;
    poke(path, "increments/index", 2, t, &huge);
    H5Tclose(t);
    assert_refused(path, "/increments/index row 2 (increment 2)",
                   "net displacement 1.75e+78 m must be finite and within -1e7..1e7 m", NULL);
    /* the index replaced by a 5 x 5 float dataset: "increments: 0" beside "completed" */
    write_run(path, "completed");
    make_old_layout(path);
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(H5Ldelete(f, "increments/index", H5P_DEFAULT) >= 0);
    hsize_t dims[2] = {5, 5};
    hid_t sp = H5Screate_simple(2, dims, NULL);
    hid_t ds = H5Dcreate2(f, "increments/index", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                          H5P_DEFAULT);
    double zeros[25] = {0};
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros);
    H5Dclose(ds);
    H5Sclose(sp);
    H5Fclose(f);
    assert_refused(path, "/increments/index (the list of increments) is a 2-D float dataset", NULL);
    remove_run(path);
}

/* A closed file's commit record blanked (every row zero passes as "never written"): the
 * run's index still lists its increments, and its stop reason says they were written. */
static void test_absurd_blank_commit_record(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_blank.h5");
    write_run(path, "completed");
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t ds = H5Dopen2(f, "increments/commit", H5P_DEFAULT);
    hid_t ft = H5Dget_type(ds), sp = H5Dget_space(ds);
    hsize_t rows = 0;
    H5Sget_simple_extent_dims(sp, &rows, NULL);
    void *zeros = calloc(rows, H5Tget_size(ft));
    assert_true(H5Dwrite(ds, ft, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros) >= 0);
    free(zeros);
    H5Sclose(sp);
    H5Tclose(ft);
    H5Dclose(ds);
    H5Fclose(f);
    assert_refused(path, "/increments/commit holds 0 committed rows but /increments/index 4", NULL);
    /* an old-layout file whose index is empty, and whose stop reason is "completed" */
    write_run(path, "completed");
    make_old_layout(path);
    f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    ds = H5Dopen2(f, "increments/index", H5P_DEFAULT);
    hsize_t none = 0;
    assert_true(H5Dset_extent(ds, &none) >= 0);
    H5Dclose(ds);
    H5Fclose(f);
    assert_refused(path, "stop reason is \"completed\"", "lists none", NULL);
    remove_run(path);
}

/* ------------------------------------------------------------------ the series */

static void test_absurd_series(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_series.h5");
    write_run(path, "completed");
    const double inf = INFINITY;
    poke(path, "series/kinetic_energy", 7, H5T_NATIVE_DOUBLE, &inf);
    assert_refused(path, "/series/kinetic_energy sample 7 (step 175)", "kinetic_energy = inf",
                   NULL);
    /* a run that blew up may end on such samples: its file stays readable */
    write_run(path, "numerical-failure");
    poke(path, "series/kinetic_energy", 15, H5T_NATIVE_DOUBLE, &inf);
    const double nan = NAN;
    poke(path, "series/base_force_x", 15, H5T_NATIVE_DOUBLE, &nan);
    assert_reads(path);
    /* ... but not with a time that is not one */
    poke(path, "series/time", 15, H5T_NATIVE_DOUBLE, &nan);
    assert_refused(path, "/series sample 15", "time nan s", NULL);
    /* a negative count; a net displacement beyond any model */
    write_run(path, "completed");
    const int64_t minus = -3;
    poke(path, "series/contacts", 2, H5T_NATIVE_INT64, &minus);
    assert_refused(path, "/series/contacts sample 2", "contacts = -3 must be >= 0", NULL);
    write_run(path, "completed");
    const double far = 3e9;
    poke(path, "series/net_displacement", 9, H5T_NATIVE_DOUBLE, &far);
    assert_refused(path, "/series/net_displacement sample 9", "3000000000 m must be within", NULL);
    /* /series/step as floats */
    write_run(path, "completed");
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(H5Ldelete(f, "series/step", H5P_DEFAULT) >= 0);
    hsize_t n = 4 * N_INC, max = H5S_UNLIMITED, chunk = 128;
    hid_t sp = H5Screate_simple(1, &n, &max), cp = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(cp, 1, &chunk);
    hid_t ds = H5Dcreate2(f, "series/step", H5T_IEEE_F64LE, sp, H5P_DEFAULT, cp, H5P_DEFAULT);
    double steps[4 * N_INC];
    for (int i = 0; i < 4 * N_INC; i++)
        steps[i] = 25.0 * i;
    assert_true(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, steps) >= 0);
    H5Dclose(ds);
    H5Pclose(cp);
    H5Sclose(sp);
    H5Fclose(f);
    assert_refused(path, "/series/step is a 1-D float dataset", "integer (int64)", NULL);
    remove_run(path);
}

/* ------------------------------------------------------------------ texts */

/* Overwrites the fixed-length string dataset name (/stop_reason, /stop_detail) with bytes. */
static void poke_text(const char *path, const char *name, const char *bytes) {
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    hid_t ft = H5Dget_type(ds);
    char buf[4096] = {0};
    assert_true(H5Tget_size(ft) <= sizeof buf && strlen(bytes) < H5Tget_size(ft));
    memcpy(buf, bytes, strlen(bytes));
    assert_true(H5Dwrite(ds, ft, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    H5Tclose(ft);
    H5Dclose(ds);
    H5Fclose(f);
}

static void test_absurd_stop_texts(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_text.h5");
    write_run(path, "completed");
    poke_text(path, "stop_reason", "\xff\xfe");
    assert_refused(path, "/stop_reason is \"\\xFF\\xFE\"", "not a stop reason", NULL);
    write_run(path, "completed");
    poke_text(path, "stop_reason", "finished");
    assert_refused(path, "/stop_reason is \"finished\"", NULL);
    /* the detail is free text: read, but printable (a terminal is not sent 0xFF or ESC) */
    write_run(path, "interrupted");
    poke_text(path, "stop_detail", "bad \xff\xfe \x1b[31mred\x1b[0m, caf\xc3\xa9\tok");
    assert_reads(path);
    cdem_error err;
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_detail(r),
                        "bad \\xFF\\xFE \\x1B[31mred\\x1B[0m, caf\xc3\xa9\tok");
    cdem_h5_reader_close(r);
    char cmd[2400], out[8192];
    const char *b = getenv("CDEM_BUILD");
    snprintf(cmd, sizeof cmd, "%s/cdem-strain info %s --json 2>&1", b ? b : "build", path);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    const size_t got = fread(out, 1, sizeof out - 1, p);
    out[got] = '\0';
    assert_int_equal(pclose(p), 0);
    for (size_t i = 0; i < got; i++)
        assert_true((unsigned char)out[i] != 0xff && out[i] != 0x1b);
    assert_non_null(strstr(out, "\"stop_detail\": \"bad \\\\xFF\\\\xFE"));
    remove_run(path);
}

/* ------------------------------------------------------------------ the writer */

/* What the reader refuses is never written: the writer refuses it (CDEM_ERR_NUMERIC for
 * values a blown-up run makes, CDEM_ERR_INVALID for a caller's mistake), writes nothing, and
 * the file keeps what it had. */
static void test_absurd_writer_refuses(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "absurd_writer.h5");
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "", "", "9.9.9", "cdem-run", 0};
    cdem_h5_writer *w = NULL;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    cdem_state s;
    make_state(&s, 0);
    cdem_increment_info in = make_info(0);
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_OK);
    in = make_info(1);
    s.x[4] = NAN;
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "increment 1 is not written: element id 14: x = nan m"));
    s.x[4] = 400.0;
    s.radius[2] = 0.0;
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "radius 0 m"));
    s.radius[2] = 50.0;
    s.id[3] = s.id[9]; /* not in ascending order, two equal */
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "element id 19 is in rows"));
    s.id[3] = 13;
    in.net_displacement = INFINITY;
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "net displacement inf m"));
    in = make_info(1);
    in.time = 0.5 * make_info(0).time - 1.0; /* before increment 0 */
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_ERR_INVALID);
    in = make_info(1);
    cdem_series_sample q = make_sample(0);
    q.kinetic_energy = INFINITY;
    assert_int_equal(cdem_h5_writer_append_series(w, &q, &err), CDEM_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "kinetic_energy = inf"));
    q = make_sample(0);
    assert_int_equal(cdem_h5_writer_append_series(w, &q, &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_append_series(w, &q, &err), CDEM_ERR_INVALID); /* step again */
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "finished", "", &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "numerical-failure", "", &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
    cdem_state_free(&s);
    assert_reads(path);
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_increment_count(r), 2);
    cdem_h5_reader_close(r);
    remove_run(path);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_absurd_positions),
        cmocka_unit_test(test_absurd_radius_layer_stress),
        cmocka_unit_test(test_absurd_duplicate_ids),
        cmocka_unit_test(test_absurd_commit_row_values),
        cmocka_unit_test(test_absurd_old_index),
        cmocka_unit_test(test_absurd_blank_commit_record),
        cmocka_unit_test(test_absurd_series),
        cmocka_unit_test(test_absurd_stop_texts),
        cmocka_unit_test(test_absurd_writer_refuses),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
