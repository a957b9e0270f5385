/* Tests of the compaction of a completed run's file (common/h5/h5_compact.c; docs/format.md,
 * "Completed runs"): close of a run whose stop reason is "completed" drops the checkpoints
 * and leaves every other value, chunking and filter as a file that keeps them
 * (CDEM_KEEP_CHECKPOINTS=1); any other stop reason keeps them; a crash while compacting (at
 * the two moments a copy exists) leaves the complete original; a compaction that cannot be
 * done leaves the file as it was, with a note. Files go to a private scratch folder. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "h5format.h"
#include "scratch.h"

#include <hdf5.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* ------------------------------------------------------------------ helpers */

static void path_in(void **state, const char *name, char *buf, size_t n) {
    scratch_dir *d = *state;
    snprintf(buf, n, "%s/%s", d->dir, name);
}

static cdem_snapshot *make_snapshot(int tag) {
    cdem_error err;
    cdem_snapshot *s = NULL;
    assert_int_equal(cdem_snapshot_alloc(&s, &err), CDEM_OK);
    double v[2000];
    for (int i = 0; i < 2000; i++)
        v[i] = 1.0 / (i + 1) + tag;
    assert_int_equal(cdem_snapshot_put(s, "state.v", CDEM_SNAP_F64, 2000, v, &err), CDEM_OK);
    return s;
}

/* A state of n elements, deterministic in k, with stress on odd increments. */
static void make_state(cdem_state *s, size_t n, int k) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, n, k % 2, &err), CDEM_OK);
    for (size_t i = 0; i < n; i++) {
        size_t at;
        assert_int_equal(cdem_state_append(s, -1, 1000.0 * (double)i / 7.0 + k * 0.5,
                                           333.3 * (double)(i % 13) - k * 0.25,
                                           50.0 + 25.0 * (double)(i % 4), 1.0, (int32_t)(i % 24),
                                           (uint32_t)(i % 5 == 0), 0, &at, &err),
                         CDEM_OK);
        if (k % 2) {
            s->sxx[at] = 1e6 + (double)i;
            s->syy[at] = 2e6 - (double)i;
            s->sxy[at] = (double)k;
        }
    }
}

/* A small run: 6 increments with series samples and a checkpoint after increments 2 and 4,
 * ended with stop reason reason (NULL: none recorded), closed; rep receives the report. */
static void write_run(const char *path, const char *reason, cdem_h5_close_report *rep) {
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "a = 1\n", "summary", "v", "cdem-run", 0};
    cdem_error err;
    cdem_h5_writer *w = NULL;
    if (cdem_h5_writer_create(path, &meta, &w, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    for (int k = 0; k < 6; k++) {
        cdem_series_sample smp = {.step = 100 * k, .time = 10.0 * k, .n_elements = 300};
        assert_int_equal(cdem_h5_writer_append_series(w, &smp, &err), CDEM_OK);
        cdem_state s;
        make_state(&s, 300 + 10 * (size_t)k, k);
        cdem_increment_info info = {.number = k,
                                    .step = 100 * k,
                                    .time = 10.0 * k,
                                    .phase = CDEM_PHASE_DEFORMATION,
                                    .sea_level = 0.0};
        assert_int_equal(cdem_h5_writer_write_increment(w, &info, &s, &err), CDEM_OK);
        cdem_state_free(&s);
        if (k == 2 || k == 4) {
            cdem_snapshot *snap = make_snapshot(k);
            assert_int_equal(cdem_h5_writer_write_checkpoint(w, snap, &err), CDEM_OK);
            cdem_snapshot_free(snap);
        }
    }
    if (reason)
        assert_int_equal(cdem_h5_writer_set_stop_reason(w, reason, "detail", &err), CDEM_OK);
    if (cdem_h5_writer_close_report(w, rep, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
}

/* What reading the newest checkpoint returns; on CDEM_OK it is the one of increment 4. */
static cdem_status checkpoint_status(const char *path, char *msg, size_t cap) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    cdem_snapshot *got = NULL, *want = make_snapshot(4);
    assert_int_equal(cdem_snapshot_alloc(&got, &err), CDEM_OK);
    int32_t inc = -1;
    cdem_status st = cdem_h5_reader_read_checkpoint(r, got, &inc, &err);
    if (st == CDEM_OK) {
        assert_int_equal(inc, 4);
        assert_true(cdem_snapshot_equal(got, want, NULL));
    }
    if (msg)
        snprintf(msg, cap, "%.500s", st == CDEM_OK ? "" : err.msg);
    cdem_snapshot_free(got);
    cdem_snapshot_free(want);
    cdem_h5_reader_close(r);
    return st;
}

static long file_size(const char *path) {
    struct stat sb;
    assert_int_equal(stat(path, &sb), 0);
    return (long)sb.st_size;
}

static int exists(const char *path) {
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* Every byte of dataset name in a and b (read in its file type) is the same, and so are its
 * chunking, filters and storage size (H5Ocopy copies chunks as stored). */
static void assert_same_dataset(hid_t fa, hid_t fb, const char *name) {
    hid_t da = H5Dopen2(fa, name, H5P_DEFAULT), db = H5Dopen2(fb, name, H5P_DEFAULT);
    if (da < 0 || db < 0)
        fail_msg("%s is missing", name);
    hid_t ta = H5Dget_type(da), sa = H5Dget_space(da), sb = H5Dget_space(db);
    hssize_t na = H5Sget_simple_extent_npoints(sa), nb = H5Sget_simple_extent_npoints(sb);
    if (na != nb)
        fail_msg("%s: %lld values against %lld", name, (long long)na, (long long)nb);
    size_t bytes = (size_t)na * H5Tget_size(ta);
    unsigned char *a = calloc(bytes + 1, 1), *b = calloc(bytes + 1, 1);
    assert_true(a && b);
    assert_true(H5Dread(da, ta, H5S_ALL, H5S_ALL, H5P_DEFAULT, a) >= 0);
    assert_true(H5Dread(db, ta, H5S_ALL, H5S_ALL, H5P_DEFAULT, b) >= 0);
    if (memcmp(a, b, bytes) != 0)
        fail_msg("%s differs", name);
    free(a);
    free(b);
    hid_t pa = H5Dget_create_plist(da), pb = H5Dget_create_plist(db);
    assert_int_equal(H5Pget_layout(pa), H5Pget_layout(pb));
    if (H5Pget_layout(pa) == H5D_CHUNKED) {
        hsize_t ca = 0, cb = 0;
        assert_int_equal(H5Pget_chunk(pa, 1, &ca), H5Pget_chunk(pb, 1, &cb));
        assert_int_equal(ca, cb);
        int nf = H5Pget_nfilters(pa);
        assert_int_equal(nf, H5Pget_nfilters(pb));
        for (int i = 0; i < nf; i++) {
            unsigned fl = 0, va[8], vb[8];
            size_t nva = 8, nvb = 8;
            H5Z_filter_t fa_ = H5Pget_filter2(pa, (unsigned)i, &fl, &nva, va, 0, NULL, NULL);
            H5Z_filter_t fb_ = H5Pget_filter2(pb, (unsigned)i, &fl, &nvb, vb, 0, NULL, NULL);
            assert_int_equal(fa_, fb_);
            assert_int_equal(nva, nvb);
            assert_memory_equal(va, vb, nva * sizeof va[0]);
        }
        if (H5Dget_storage_size(da) != H5Dget_storage_size(db))
            fail_msg("%s: %llu bytes stored against %llu", name,
                     (unsigned long long)H5Dget_storage_size(da),
                     (unsigned long long)H5Dget_storage_size(db));
    }
    H5Pclose(pa);
    H5Pclose(pb);
    H5Tclose(ta);
    H5Sclose(sa);
    H5Sclose(sb);
    H5Dclose(da);
    H5Dclose(db);
}

static char *read_text(const char *path) {
    char *buf = scratch_read_file(path);
    assert_non_null(buf);
    return buf;
}

/* ------------------------------------------------------------------ tests */

/* Completed: no checkpoint left (an empty /checkpoint saying why), every other dataset, root
 * attribute and the sidecar the same as in the file of the same writes kept whole. */
static void test_format_compact_completed_drops_checkpoints(void **state) {
    char kept[1100], comp[1100], leftover[1200];
    path_in(state, "kept.h5", kept, sizeof kept);
    path_in(state, "comp.h5", comp, sizeof comp);
    snprintf(leftover, sizeof leftover, "%s.compacting", comp);
    cdem_h5_close_report rk, rc;
    assert_int_equal(setenv("CDEM_KEEP_CHECKPOINTS", "1", 1), 0);
    write_run(kept, "completed", &rk);
    assert_int_equal(unsetenv("CDEM_KEEP_CHECKPOINTS"), 0);
    write_run(comp, "completed", &rc);
    assert_int_equal(rk.compacted, 0);
    assert_non_null(strstr(rk.note, "CDEM_KEEP_CHECKPOINTS"));
    if (!rc.compacted)
        fail_msg("not compacted: %s", rc.note);
    assert_string_equal(rc.note, "");
    assert_int_equal((long)rc.bytes_before, file_size(kept));
    assert_int_equal((long)rc.bytes_after, file_size(comp));
    printf("compacted: %ld bytes with checkpoints, %ld without\n", file_size(kept),
           file_size(comp));
    assert_true(file_size(comp) < file_size(kept) - 2 * 4096);
    assert_false(exists(leftover));

    char msg[600];
    assert_int_equal(checkpoint_status(kept, msg, sizeof msg), CDEM_OK);
    assert_int_equal(checkpoint_status(comp, msg, sizeof msg), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(msg, "the run completed and its checkpoints were dropped"));

    hid_t fa = H5Fopen(kept, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t fb = H5Fopen(comp, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(fa >= 0 && fb >= 0);
    static const char *const names[] = {
        "increments/id",    "increments/x",     "increments/y",      "increments/radius",
        "increments/layer", "increments/flags", "increments/born",   "increments/sxx",
        "increments/syy",   "increments/sxy",   "increments/index",  "increments/xy",
        "series/step",      "series/time",      "series/n_elements", "series/sea_level",
        "parameters",       "stop_reason",      "stop_detail",
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        assert_same_dataset(fa, fb, names[i]);
    /* the same objects: every root link and every link of the groups */
    H5G_info_t ga, gb;
    static const char *const groups[] = {"/", "increments", "series", "checkpoint"};
    for (size_t i = 0; i < 4; i++) {
        assert_true(H5Gget_info_by_name(fa, groups[i], &ga, H5P_DEFAULT) >= 0);
        assert_true(H5Gget_info_by_name(fb, groups[i], &gb, H5P_DEFAULT) >= 0);
        assert_int_equal(ga.nlinks, gb.nlinks);
    }
    /* the root attributes, in the same order, equal except the creation time */
    H5O_info_t oa, ob;
    assert_true(H5Oget_info(fa, &oa) >= 0 && H5Oget_info(fb, &ob) >= 0);
    assert_int_equal(oa.num_attrs, ob.num_attrs);
    for (hsize_t i = 0; i < oa.num_attrs; i++) {
        char na[64], nb[64];
        H5Aget_name_by_idx(fa, ".", H5_INDEX_NAME, H5_ITER_NATIVE, i, na, sizeof na, H5P_DEFAULT);
        H5Aget_name_by_idx(fb, ".", H5_INDEX_NAME, H5_ITER_NATIVE, i, nb, sizeof nb, H5P_DEFAULT);
        assert_string_equal(na, nb);
        if (strcmp(na, "created") == 0)
            continue;
        hid_t aa = H5Aopen(fa, na, H5P_DEFAULT), ab = H5Aopen(fb, nb, H5P_DEFAULT);
        hid_t t = H5Aget_type(aa), tb = H5Aget_type(ab);
        assert_true(H5Tequal(t, tb) > 0);
        size_t n = H5Tget_size(t);
        unsigned char *x = calloc(n, 1), *y = calloc(n, 1);
        assert_true(H5Aread(aa, t, x) >= 0 && H5Aread(ab, t, y) >= 0);
        if (memcmp(x, y, n) != 0)
            fail_msg("root attribute %s differs", na);
        free(x);
        free(y);
        H5Tclose(t);
        H5Tclose(tb);
        H5Aclose(aa);
        H5Aclose(ab);
    }
    /* /checkpoint: empty slots, index rows of sequence 0, the attribute saying why */
    hid_t s0 = H5Dopen2(fb, "checkpoint/slot0", H5P_DEFAULT);
    hid_t sp = H5Dget_space(s0);
    assert_int_equal(H5Sget_simple_extent_npoints(sp), 0);
    H5Sclose(sp);
    H5Dclose(s0);
    assert_true(H5Aexists_by_name(fb, "checkpoint", "dropped", H5P_DEFAULT) > 0);
    assert_true(H5Aexists_by_name(fa, "checkpoint", "dropped", H5P_DEFAULT) == 0);
    H5Fclose(fa);
    H5Fclose(fb);

    /* the sidecar (written before the compaction) still describes the file */
    char xa[1100], xb[1100];
    path_in(state, "kept.xmf", xa, sizeof xa);
    path_in(state, "comp.xmf", xb, sizeof xb);
    char *ta = read_text(xa), *tb = read_text(xb);
    for (char *p = ta; (p = strstr(p, "kept.h5")) != NULL; p += 7)
        memcpy(p, "comp", 4);
    assert_string_equal(ta, tb);
    free(ta);
    free(tb);

    /* readers see a complete, closed file */
    cdem_error err;
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(comp, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "completed");
    assert_int_equal(cdem_h5_reader_increment_count(r), 6);
    assert_int_equal(cdem_h5_reader_unclosed(r), 0);
    cdem_h5_reader_close(r);
}

/* Any other ending keeps the checkpoints for --resume. */
static void test_format_compact_only_completed(void **state) {
    static const char *const reasons[] = {"interrupted", "stopped-early", "numerical-failure",
                                          "error", NULL};
    for (size_t i = 0; i < sizeof reasons / sizeof reasons[0]; i++) {
        char path[1100];
        path_in(state, "other.h5", path, sizeof path);
        cdem_h5_close_report rep;
        write_run(path, reasons[i], &rep);
        assert_int_equal(rep.compacted, 0);
        assert_string_equal(rep.note, "");
        if (checkpoint_status(path, NULL, 0) != CDEM_OK)
            fail_msg("stop reason %s: the checkpoint was dropped", reasons[i] ? reasons[i] : "-");
    }
    /* "completed" recorded, then another ending: the last one counts */
    char path[1100];
    path_in(state, "late.h5", path, sizeof path);
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, NULL, "s", "v", "cdem-run", 0};
    cdem_error err;
    cdem_h5_writer *w = NULL;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    cdem_state s;
    make_state(&s, 100, 0);
    cdem_increment_info info = {.number = 0};
    assert_int_equal(cdem_h5_writer_write_increment(w, &info, &s, &err), CDEM_OK);
    cdem_state_free(&s);
    cdem_snapshot *snap = make_snapshot(0);
    assert_int_equal(cdem_h5_writer_write_checkpoint(w, snap, &err), CDEM_OK);
    cdem_snapshot_free(snap);
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "completed", "", &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "error", "later", &err), CDEM_OK);
    cdem_h5_close_report rep;
    assert_int_equal(cdem_h5_writer_close_report(w, &rep, &err), CDEM_OK);
    assert_int_equal(rep.compacted, 0);
}

/* A crash while compacting, once the copy is written and once it is synced but not renamed:
 * the complete original (closed, with its checkpoints) is at the path; the next writer of the
 * path removes the leftover copy. */
static void test_format_compact_crash_leaves_original(void **state) {
    static const char *const moments[] = {"copy", "rename"};
    for (size_t m = 0; m < 2; m++) {
        char path[1100], leftover[1200];
        path_in(state, "crash.h5", path, sizeof path);
        snprintf(leftover, sizeof leftover, "%s.compacting", path);
        fflush(NULL);
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            setenv("CDEM_TEST_COMPACT_CRASH", moments[m], 1);
            cdem_h5_close_report rep;
            write_run(path, "completed", &rep);
            _exit(0); /* not reached: killed inside the compaction */
        }
        int st = 0;
        assert_int_equal(waitpid(pid, &st, 0), pid);
        if (!WIFSIGNALED(st) || WTERMSIG(st) != SIGKILL)
            fail_msg("%s: the writer was not killed while compacting", moments[m]);
        assert_true(exists(leftover));
        cdem_error err;
        cdem_h5_reader *r = NULL;
        if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
            fail_msg("%s: %s", moments[m], err.msg);
        assert_string_equal(cdem_h5_reader_stop_reason(r), "completed");
        assert_int_equal(cdem_h5_reader_increment_count(r), 6);
        assert_int_equal(cdem_h5_reader_unclosed(r), 0);
        cdem_state s;
        memset(&s, 0, sizeof s);
        cdem_increment_info info;
        assert_int_equal(cdem_h5_reader_load_increment(r, 5, &s, &info, &err), CDEM_OK);
        assert_int_equal(s.n, 350);
        cdem_state_free(&s);
        cdem_h5_reader_close(r);
        assert_int_equal(checkpoint_status(path, NULL, 0), CDEM_OK);
        /* the next run of the path: the leftover goes, its own file is compacted */
        cdem_h5_close_report rep;
        write_run(path, "completed", &rep);
        assert_int_equal(rep.compacted, 1);
        assert_false(exists(leftover));
    }
}

/* A compaction that cannot be done (here: a folder in the way of the copy) is no error: the
 * file stays whole, with its checkpoints, and the report says why. */
static void test_format_compact_failure_keeps_file(void **state) {
    char path[1100], blocker[1200], inside[1300];
    path_in(state, "blocked.h5", path, sizeof path);
    snprintf(blocker, sizeof blocker, "%s.compacting", path);
    snprintf(inside, sizeof inside, "%s/x", blocker);
    assert_int_equal(mkdir(blocker, 0755), 0);
    FILE *f = fopen(inside, "w");
    assert_non_null(f);
    fclose(f);
    cdem_h5_close_report rep;
    write_run(path, "completed", &rep);
    assert_int_equal(rep.compacted, 0);
    assert_non_null(strstr(rep.note, "keeps its checkpoints"));
    assert_non_null(strstr(rep.note, "blocked.h5.compacting"));
    assert_int_equal(checkpoint_status(path, NULL, 0), CDEM_OK);
    remove(inside);
    remove(blocker);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_format_compact_completed_drops_checkpoints,
                                        scratch_setup, scratch_teardown),
        cmocka_unit_test_setup_teardown(test_format_compact_only_completed, scratch_setup,
                                        scratch_teardown),
        cmocka_unit_test_setup_teardown(test_format_compact_crash_leaves_original, scratch_setup,
                                        scratch_teardown),
        cmocka_unit_test_setup_teardown(test_format_compact_failure_keeps_file, scratch_setup,
                                        scratch_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
