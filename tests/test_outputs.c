/* test_outputs: outputs appear complete or not at all (common/outfile.h) and every error
 * names the file and exits non-zero. The outfile module directly (commit, failure, an
 * unwritable or missing folder, a folder in place of the file), then the cdem-strain
 * commands ($CDEM_BUILD/cdem-strain) forced to fail midway: a run whose last increment has
 * lost a dataset (its listing reads fine, loading it fails after earlier increments were
 * written), a malformed cdem2D folder, and missing output folders. After each failure
 * neither the output nor its ".tmp" may exist. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "analysis_fixtures.h"
#include "h5format.h"
#include "outfile.h"
#include "scratch.h"

#include <hdf5.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define NINC 5

typedef struct {
    scratch_dir scratch; /* private folder of this test binary */
    char run[1100];      /* a valid run file */
    char broken[1100];   /* the same run, last increment's x dataset deleted */
    char exe[1024];      /* cdem-strain */
    char out[8192];      /* output of the last command */
} fixture;

static int exists(const char *path) {
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* Runs cmd (2>&1) into g->out; returns its exit status (-1 when killed by a signal). */
static int run(fixture *g, const char *cmd) {
    char full[4096];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    size_t got = fread(g->out, 1, sizeof g->out - 1, p);
    g->out[got] = '\0';
    while (fread(full, 1, sizeof full, p) > 0) {
    }
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Number of entries (other than . and ..) in dir. */
static int count_entries(const char *dir) {
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            n++;
    closedir(d);
    return n;
}

/* Writes a run of NINC increments of a small packing to path. */
static int write_run(const char *path) {
    cdem_state s = {0};
    cdem_error err;
    make_packing(&s, 80, 2000.0, 1200.0, 3);
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "", "outputs test", "0", "test", 0};
    cdem_h5_writer *w;
    if (cdem_h5_writer_create(path, &meta, &w, &err) != CDEM_OK)
        return -1;
    int rc = 0;
    for (int k = 0; k < NINC && rc == 0; k++) {
        const double F[4] = {1.01, 0, 0, 1 / 1.01};
        if (k > 0)
            deform_affine(&s, F, 0, 0);
        cdem_increment_info in;
        memset(&in, 0, sizeof in);
        in.number = k;
        in.step = 100 * k;
        in.time = k;
        in.phase = k == 0 ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
        in.net_displacement = 5.0 * k;
        in.sea_level = NAN;
        if (cdem_h5_writer_write_increment(w, &in, &s, &err) != CDEM_OK)
            rc = -1;
    }
    cdem_h5_writer_set_stop_reason(w, "completed", "", &err);
    cdem_h5_writer_close(w, &err);
    cdem_state_free(&s);
    return rc;
}

/* Corrupts the last increment of a format-2 file so that the listing still reads and only
 * loading that increment fails: every increment starts at a chunk boundary of the ragged
 * element datasets, so the chunk of /increments/x holding the last row belongs to the last
 * increment alone; its compressed bytes are overwritten (a bad sector, say). */
static int break_last_increment(const char *path) {
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return -1;
    hid_t ds = H5Dopen2(f, "/increments/x", H5P_DEFAULT);
    hid_t sp = ds >= 0 ? H5Dget_space(ds) : H5I_INVALID_HID;
    hid_t dcpl = ds >= 0 ? H5Dget_create_plist(ds) : H5I_INVALID_HID;
    hsize_t dims[1] = {0}, chunk[1] = {0}, coord[1] = {0}, size = 0;
    haddr_t addr = HADDR_UNDEF;
    unsigned mask = 0;
    int ok = sp >= 0 && dcpl >= 0 && H5Sget_simple_extent_dims(sp, dims, NULL) == 1 &&
             dims[0] > 0 && H5Pget_chunk(dcpl, 1, chunk) == 1 && chunk[0] > 0;
    if (ok) {
        coord[0] = (dims[0] - 1) / chunk[0] * chunk[0];
        ok = H5Dget_chunk_info_by_coord(ds, coord, &mask, &addr, &size) >= 0 &&
             addr != HADDR_UNDEF && size > 0;
    }
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    H5Fclose(f);
    if (!ok)
        return -1;
    FILE *fp = fopen(path, "r+b");
    if (!fp)
        return -1;
    int rc = fseek(fp, (long)addr, SEEK_SET) == 0 ? 0 : -1;
    for (hsize_t i = 0; rc == 0 && i < size; i++)
        if (fputc(0xA5, fp) == EOF)
            rc = -1;
    if (fclose(fp) != 0)
        rc = -1;
    return rc;
}

static int setup(void **state) {
    fixture *g = calloc(1, sizeof *g);
    if (!g)
        return -1;
    *state = g;
    if (scratch_dir_make(&g->scratch, "outputs") != 0)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    snprintf(g->exe, sizeof g->exe, "%s/cdem-strain", b ? b : "build");
    snprintf(g->run, sizeof g->run, "%s/run.h5", g->scratch.dir);
    snprintf(g->broken, sizeof g->broken, "%s/broken.h5", g->scratch.dir);
    if (write_run(g->run) != 0 || write_run(g->broken) != 0)
        return -1;
    return break_last_increment(g->broken);
}

static int teardown(void **state) {
    fixture *g = *state;
    int rc = scratch_dir_remove(&g->scratch);
    free(g);
    return rc;
}

/* ------------------------------------------------------------- the module */

static void test_outputs_outfile_commit(void **state) {
    fixture *g = *state;
    char path[1200];
    snprintf(path, sizeof path, "%s/commit.txt", g->scratch.dir);
    cdem_outfile of;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_outfile_begin(&of, path, &err), CDEM_OK);
    FILE *f = fopen(of.tmp, "w");
    assert_non_null(f);
    fputs("complete\n", f);
    fclose(f);
    assert_false(exists(path)); /* nothing under the final name while writing */
    assert_int_equal(cdem_outfile_end(&of, CDEM_OK, &err), CDEM_OK);
    assert_true(exists(path));
    assert_false(exists(of.tmp));
    char buf[32] = "";
    f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(fgets(buf, sizeof buf, f));
    fclose(f);
    assert_string_equal(buf, "complete\n");
    remove(path);
}

static void test_outputs_outfile_failure_removes_tmp(void **state) {
    fixture *g = *state;
    char path[1200];
    snprintf(path, sizeof path, "%s/failed.txt", g->scratch.dir);
    cdem_outfile of;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_outfile_begin(&of, path, &err), CDEM_OK);
    FILE *f = fopen(of.tmp, "w");
    assert_non_null(f);
    fputs("half", f);
    fclose(f);
    CDEM_FAIL(&err, CDEM_ERR_PARSE, "writer failed on %s", path);
    assert_int_equal(cdem_outfile_end(&of, CDEM_ERR_PARSE, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, "writer failed")); /* the writer's message is kept */
    assert_false(exists(path));
    assert_false(exists(of.tmp));
}

static void test_outputs_outfile_stale_tmp_removed(void **state) {
    fixture *g = *state;
    char path[1200], tmp[1300];
    snprintf(path, sizeof path, "%s/stale.txt", g->scratch.dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    assert_non_null(f);
    fputs("left by a killed writer", f);
    fclose(f);
    cdem_outfile of;
    cdem_error err;
    assert_int_equal(cdem_outfile_begin(&of, path, &err), CDEM_OK);
    assert_false(exists(tmp));
    cdem_outfile_discard(&of);
    cdem_outfile_discard(NULL);
}

static void test_outputs_outfile_bad_destination(void **state) {
    fixture *g = *state;
    cdem_outfile of;
    cdem_error err;
    char path[1200];
    /* missing folder */
    snprintf(path, sizeof path, "%s/no-such-folder/out.csv", g->scratch.dir);
    cdem_error_clear(&err);
    assert_int_equal(cdem_outfile_begin(&of, path, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, "No such file"));
    /* a regular file where the folder should be */
    snprintf(path, sizeof path, "%s/run.h5/out.csv", g->scratch.dir);
    assert_int_equal(cdem_outfile_begin(&of, path, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, path));
    /* the output itself is a folder */
    assert_int_equal(cdem_outfile_begin(&of, g->scratch.dir, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "is a folder"));
    /* empty and overlong paths */
    assert_int_equal(cdem_outfile_begin(&of, "", &err), CDEM_ERR_INVALID);
    char *longp = malloc(CDEM_OUTFILE_PATH_MAX + 10);
    assert_non_null(longp);
    memset(longp, 'a', CDEM_OUTFILE_PATH_MAX + 9);
    longp[CDEM_OUTFILE_PATH_MAX + 9] = '\0';
    assert_int_equal(cdem_outfile_begin(&of, longp, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "characters long"));
    free(longp);
}

/* ------------------------------------------------------------- the commands */

/* Asserts the last command failed with status 1, named `needle`, and left neither out nor
 * out.tmp. */
static void expect_failed_clean(const fixture *g, int rc, const char *needle, const char *out) {
    if (rc != 1 || !strstr(g->out, needle))
        fail_msg("expected exit 1 and '%s' in the message; got %d: %s", needle, rc, g->out);
    char tmp[1300];
    snprintf(tmp, sizeof tmp, "%s.tmp", out);
    assert_false(exists(out));
    assert_false(exists(tmp));
}

static void test_outputs_compute_csv_fails_midway(void **state) {
    fixture *g = *state;
    char out[1200], cmd[4096];
    snprintf(out, sizeof out, "%s/values.csv", g->scratch.dir);
    /* the valid run: the file appears, no .tmp left */
    snprintf(cmd, sizeof cmd,
             "'%s' compute '%s' --increment all --quantity total-max-shear -o '%s'", g->exe, g->run,
             out);
    assert_int_equal(run(g, cmd), 0);
    assert_true(exists(out));
    remove(out);
    /* the broken run fails at the last increment, after the others were written */
    snprintf(cmd, sizeof cmd,
             "'%s' compute '%s' --increment all --quantity total-max-shear -o '%s'", g->exe,
             g->broken, out);
    expect_failed_clean(g, run(g, cmd), g->broken, out);
    assert_non_null(strstr(g->out, "/x"));
}

static void test_outputs_compute_h5_fails_midway(void **state) {
    fixture *g = *state;
    char out[1200], cmd[4096];
    snprintf(out, sizeof out, "%s/values.h5", g->scratch.dir);
    snprintf(cmd, sizeof cmd,
             "'%s' compute '%s' --increment all --quantity total-max-shear --format h5 -o '%s'",
             g->exe, g->broken, out);
    expect_failed_clean(g, run(g, cmd), g->broken, out);
}

static void test_outputs_unwritable_destinations(void **state) {
    fixture *g = *state;
    char out[1200], cmd[4096];
    snprintf(out, sizeof out, "%s/missing/values.csv", g->scratch.dir);
    snprintf(cmd, sizeof cmd,
             "'%s' compute '%s' --increment last --quantity total-max-shear -o '%s'", g->exe,
             g->run, out);
    expect_failed_clean(g, run(g, cmd), out, out);
    snprintf(out, sizeof out, "%s/missing/picture.png", g->scratch.dir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --increment last -o '%s'", g->exe, g->run, out);
    expect_failed_clean(g, run(g, cmd), out, out);
    snprintf(out, sizeof out, "%s/missing/movie.gif", g->scratch.dir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --gif '%s'", g->exe, g->run, out);
    expect_failed_clean(g, run(g, cmd), out, out);
    snprintf(out, sizeof out, "%s/missing/series.svg", g->scratch.dir);
    snprintf(cmd, sizeof cmd, "'%s' plot-series '%s' --y kinetic_energy -o '%s'", g->exe, g->run,
             out);
    int rc = run(g, cmd);
    /* this run has no series samples: either reason is an error naming a file */
    assert_int_equal(rc, 1);
    assert_false(exists(out));
    snprintf(out, sizeof out, "%s/missing/biaxial.txt", g->scratch.dir);
    snprintf(cmd, sizeof cmd, "'%s' export-biaxial '%s' -o '%s'", g->exe, g->run, out);
    rc = run(g, cmd);
    assert_int_equal(rc, 1); /* not a biaxial run: refused, naming the run file */
    assert_non_null(strstr(g->out, g->run));
    assert_false(exists(out));
}

static void test_outputs_render_series_fails_midway(void **state) {
    fixture *g = *state;
    char dir[1200], gif[1200], cmd[4096];
    snprintf(dir, sizeof dir, "%s/pictures", g->scratch.dir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --increment all --zoom -100,2100,-100,1300 -o '%s'",
             g->exe, g->broken, dir);
    int rc = run(g, cmd);
    if (rc != 1 || !strstr(g->out, g->broken))
        fail_msg("render: expected exit 1 naming %s; got %d: %s", g->broken, rc, g->out);
    assert_int_equal(count_entries(dir), 0); /* earlier pictures of this call removed */
    snprintf(gif, sizeof gif, "%s/movie.gif", g->scratch.dir);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --zoom -100,2100,-100,1300 --gif '%s'", g->exe,
             g->broken, gif);
    expect_failed_clean(g, run(g, cmd), g->broken, gif);
}

static void test_outputs_export_sspx_fails_midway(void **state) {
    fixture *g = *state;
    char dir[1200], cmd[4096];
    snprintf(dir, sizeof dir, "%s/sspx", g->scratch.dir);
    assert_int_equal(mkdir(dir, 0777), 0);
    snprintf(cmd, sizeof cmd, "'%s' export-sspx '%s' --increments first-last '%s'", g->exe,
             g->broken, dir);
    int rc = run(g, cmd);
    if (rc != 1 || !strstr(g->out, g->broken))
        fail_msg("export-sspx: expected exit 1 naming %s; got %d: %s", g->broken, rc, g->out);
    assert_int_equal(count_entries(dir), 0);
    /* the valid run writes all NINC files */
    snprintf(cmd, sizeof cmd, "'%s' export-sspx '%s' --increments first-last '%s'", g->exe, g->run,
             dir);
    assert_int_equal(run(g, cmd), 0);
    assert_int_equal(count_entries(dir), NINC);
}

static void test_outputs_import_cdem2d_fails_midway(void **state) {
    fixture *g = *state;
    const char *d = getenv("CDEM_TEST_DATA");
    char out[1200], xmf[1200], cmd[4096];
    snprintf(out, sizeof out, "%s/imported.h5", g->scratch.dir);
    snprintf(xmf, sizeof xmf, "%s/imported.xmf", g->scratch.dir);
    /* modelresults_0.txt is valid (written), modelresults_1.txt is malformed */
    snprintf(cmd, sizeof cmd, "'%s' import-cdem2d '%s/cdem2d_malformed' -o '%s'", g->exe,
             d && *d ? d : "tests/data", out);
    expect_failed_clean(g, run(g, cmd), "modelresults_1.txt", out);
    assert_false(exists(xmf));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_outputs_outfile_commit),
        cmocka_unit_test(test_outputs_outfile_failure_removes_tmp),
        cmocka_unit_test(test_outputs_outfile_stale_tmp_removed),
        cmocka_unit_test(test_outputs_outfile_bad_destination),
        cmocka_unit_test(test_outputs_compute_csv_fails_midway),
        cmocka_unit_test(test_outputs_compute_h5_fails_midway),
        cmocka_unit_test(test_outputs_unwritable_destinations),
        cmocka_unit_test(test_outputs_render_series_fails_midway),
        cmocka_unit_test(test_outputs_export_sspx_fails_midway),
        cmocka_unit_test(test_outputs_import_cdem2d_fails_midway),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
