/* test_strain_cli: the cdem-strain command line ($CDEM_BUILD/cdem-strain, default
 * build/cdem-strain) on a small run written with the h5format writer: compute (CSV and the
 * file-first shorthand), element, limits, info, export-sspx, import-cdem2d, and the error
 * and usage exit codes with their messages. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "analysis_fixtures.h"
#include "h5format.h"
#include "scratch.h"

#include <hdf5.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define NINC 7

static scratch_dir g_scratch;
static char g_run[1100], g_exe[1024];

/* Runs cmd (2>&1) and returns its exit status; output (truncated) in out. */
static int run(const char *cmd, char *out, size_t n) {
    char full[4096];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    size_t got = fread(out, 1, n - 1, p);
    out[got] = '\0';
    while (fread(full, 1, sizeof full, p) > 0) {
    }
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int setup(void **state) {
    (void)state;
    if (scratch_dir_make(&g_scratch, "strain_cli") != 0)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    snprintf(g_exe, sizeof g_exe, "%s/cdem-strain", b ? b : "build");
    snprintf(g_run, sizeof g_run, "%s/run.h5", g_scratch.dir);
    cdem_state st[NINC] = {{0}};
    cdem_error err;
    make_packing(&st[0], 120, 2000.0, 1200.0, 5);
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "", "CLI test summary", "0", "test", 0};
    cdem_h5_writer *w;
    if (cdem_h5_writer_create(g_run, &meta, &w, &err) != CDEM_OK)
        return -1;
    for (int k = 0; k < NINC; k++) {
        if (k > 0)
            cdem_state_copy(&st[k], &st[k - 1], &err);
        if (k > 2) {
            const double F[4] = {1.01, 0, 0, 1 / 1.01};
            deform_affine(&st[k], F, 0, 0);
        }
        cdem_increment_info in;
        memset(&in, 0, sizeof in);
        in.number = k;
        in.step = 100 * k;
        in.time = k;
        in.phase = k <= 2 ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
        in.net_displacement = k > 2 ? 5.0 * (k - 2) : 0.0;
        in.sea_level = NAN;
        if (cdem_h5_writer_write_increment(w, &in, &st[k], &err) != CDEM_OK)
            return -1;
    }
    cdem_h5_writer_set_stop_reason(w, "completed", "", &err);
    cdem_h5_writer_close(w, &err);
    for (int k = 0; k < NINC; k++)
        cdem_state_free(&st[k]);
    return 0;
}

static int teardown(void **state) {
    (void)state;
    return scratch_dir_remove(&g_scratch);
}

static void test_strain_cli_compute_csv(void **state) {
    (void)state;
    char cmd[8192], out[65536];
    snprintf(cmd, sizeof cmd, "%s compute %s --increment last --quantity total-e1", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_true(strncmp(out, "id,x,y,value\n", 13) == 0);
    /* pure shear 1.01 from the end of equilibration (2) to 6: e1 = 1.01^4 - 1 */
    const char *line = strchr(out, '\n') + 1;
    int id;
    double x, y, v;
    int checked = 0;
    while (sscanf(line, "%d,%lf,%lf,%lf", &id, &x, &y, &v) == 4) {
        if (isfinite(v) && y > 0) {
            assert_true(fabs(v - (pow(1.01, 4) - 1)) < 1e-9);
            checked++;
        }
        line = strchr(line, '\n');
        if (!line)
            break;
        line++;
    }
    assert_true(checked > 50);
    /* the shorthand without "compute" gives the same output */
    char out2[65536];
    snprintf(cmd, sizeof cmd, "%s %s --increment last --quantity total-e1", g_exe, g_run);
    assert_int_equal(run(cmd, out2, sizeof out2), 0);
    assert_string_equal(out, out2);
    /* --increment all --format h5: one group per increment */
    snprintf(cmd, sizeof cmd,
             "%s compute %s --increment all --quantity cum-max-shear --format h5 "
             "-o %s/q.h5",
             g_exe, g_run, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    char path[1200];
    snprintf(path, sizeof path, "%s/q.h5", g_scratch.dir);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    hid_t g = H5Gopen2(f, "increments", H5P_DEFAULT);
    H5G_info_t gi;
    H5Gget_info(g, &gi);
    assert_int_equal(gi.nlinks, NINC);
    H5Gclose(g);
    /* every group has the n x 2 view of x and y for the XDMF 3 sidecar */
    hid_t xy = H5Dopen2(f, "increments/000006/xy", H5P_DEFAULT);
    assert_true(xy >= 0);
    H5Dclose(xy);
    H5Fclose(f);
    /* ... and the file its own sidecar (issue 18), which names it and resolves */
    char xmf[1300], text[65536];
    snprintf(xmf, sizeof xmf, "%s/q.xmf", g_scratch.dir);
    snprintf(cmd, sizeof cmd, "xmllint --noout --xinclude %s && cat %s", xmf, xmf);
    assert_int_equal(run(cmd, text, sizeof text), 0);
    assert_non_null(strstr(text, ">q.h5:/increments/000006/xy|0 0:1 1:"));
    assert_non_null(strstr(text, "<Attribute Name=\"cum-max-shear\""));
    assert_non_null(strstr(text, "<Grid Name=\"increment_000006\""));
}

/* cdem-strain xdmf: a renamed run file gets a sidecar naming it (issue 18: renaming the pair
 * broke the old one); --xdmf2 writes the legacy flavour; files that are neither a run nor a
 * compute file are refused. ParaView itself reads these in make validate. */
static void test_strain_cli_xdmf(void **state) {
    (void)state;
    char cmd[8192], out[65536];
    snprintf(cmd, sizeof cmd, "cp %s %s/renamed.h5 && %s xdmf %s/renamed.h5", g_run, g_scratch.dir,
             g_exe, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    char want[1300];
    snprintf(want, sizeof want, "%s/renamed.xmf\n", g_scratch.dir);
    assert_string_equal(out, want);
    snprintf(cmd, sizeof cmd,
             "xmllint --noout --xinclude %s/renamed.xmf && grep -c "
             "'>renamed.h5:/increments/xy|' %s/renamed.xmf",
             g_scratch.dir, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_int_equal(atoi(out), NINC);
    snprintf(cmd, sizeof cmd,
             "%s xdmf %s/renamed.h5 --xdmf2 -o %s/legacy.xdmf2 && grep -c "
             "'GeometryType=\"X_Y\"' %s/legacy.xdmf2",
             g_exe, g_scratch.dir, g_scratch.dir, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "legacy.xdmf2\n"));
    assert_int_equal(atoi(strchr(out, '\n') + 1), NINC);
    /* in the file's folder: the name as ParaView can open it, ./NAME (issue 35: pvpython's
     * OpenDataFile("renamed.xmf") aborts looking for "renamed.xmfrenamed.h5") */
    char exe[4096];
    assert_non_null(realpath(g_exe, exe)); /* the test may run with a relative CDEM_BUILD */
    snprintf(cmd, sizeof cmd, "cd %s && %s xdmf renamed.h5", g_scratch.dir, exe);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_string_equal(out, "./renamed.xmf\n");
    snprintf(cmd, sizeof cmd, "echo text > %s/not.h5 && %s xdmf %s/not.h5", g_scratch.dir, g_exe,
             g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "not.h5"));
}

static void test_strain_cli_element_limits_info(void **state) {
    (void)state;
    char cmd[8192], out[65536];
    snprintf(cmd, sizeof cmd, "%s element %s --increment 5 --element 10", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "element 10 at increment 5"));
    assert_non_null(strstr(out, "total-max-shear"));
    assert_non_null(strstr(out, "cum-dilation"));
    assert_null(strstr(out, "sigma1")); /* no stress in this run */
    snprintf(cmd, sizeof cmd, "%s limits %s --increment 5 --quantity incr-dilation", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "vmin -0.1"));
    assert_non_null(strstr(out, "vmax 0.1"));
    snprintf(cmd, sizeof cmd, "%s info %s", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "CLI test summary"));
    assert_non_null(strstr(out, "stop reason: completed"));
    assert_non_null(strstr(out, "end of equilibration: increment 2"));
    assert_non_null(strstr(out, "deformation"));
}

static void test_strain_cli_exports_and_import(void **state) {
    (void)state;
    char cmd[8192], out[65536], path[1200];
    snprintf(cmd, sizeof cmd, "%s export-sspx %s --increments equil-last --prefix mod %s/", g_exe,
             g_run, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    for (int k = 2; k < NINC; k++) {
        snprintf(path, sizeof path, "%s/mod%d.txt", g_scratch.dir, k);
        assert_int_equal(access(path, R_OK), 0);
    }
    snprintf(path, sizeof path, "%s/mod1.txt", g_scratch.dir);
    assert_int_not_equal(access(path, R_OK), 0);
    /* a folder that does not exist yet (two levels) is created (issue 18) */
    snprintf(cmd, sizeof cmd, "%s export-sspx %s --increments 3-4 %s/new/sspx", g_exe, g_run,
             g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    snprintf(path, sizeof path, "%s/new/sspx/cdem4.txt", g_scratch.dir);
    assert_int_equal(access(path, R_OK), 0);
    /* but not for a bad range: nothing is created then */
    snprintf(cmd, sizeof cmd, "%s export-sspx %s --increments 3-99 %s/never", g_exe, g_run,
             g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    snprintf(path, sizeof path, "%s/never", g_scratch.dir);
    assert_int_not_equal(access(path, F_OK), 0);
    /* a prefix is a file name, not a path out of the folder; refused before the folder is
     * made (issue 35, item 8: "../../etc/x" was taken and its folder left behind) */
    snprintf(cmd, sizeof cmd,
             "%s export-sspx %s --increments 3-4 --prefix ../../etc/x %s/never 2>&1", g_exe, g_run,
             g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "--prefix ../../etc/x: must be a file-name prefix"));
    assert_int_not_equal(access(path, F_OK), 0);
    const char *d = getenv("CDEM_TEST_DATA");
    snprintf(cmd, sizeof cmd,
             "%s import-cdem2d %s/cdem2d_basic -o %s/imp.h5 && %s compute "
             "%s/imp.h5 --increment 3 --quantity total-disp-x",
             g_exe, d ? d : "tests/data", g_scratch.dir, g_exe, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    /* element 0 starts at (100, 100) and moves 5 + 0.02 y = 7 m per increment; the end of
     * equilibration is increment 1, so at increment 3 it sits at x = 121 with u = 14 m */
    assert_non_null(strstr(out, "\n0,121.000000,100.000000,14\n"));
    /* info of an imported run: no step, time or displacement invented (issue 18) */
    snprintf(cmd, sizeof cmd, "%s info %s/imp.h5", g_exe, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    int number, elements;
    char step[16], time[16], phase[32], net[16];
    const char *row = strstr(out, "\n        3 ");
    assert_non_null(row);
    assert_int_equal(
        sscanf(row, "%d %15s %15s %31s %15s %d", &number, step, time, phase, net, &elements), 6);
    assert_string_equal(net, "-");
    assert_string_equal(step, "-");
}

static void test_strain_cli_export_biaxial(void **state) {
    (void)state;
    char path[1200], out_path[1200], cmd[8192], out[8192];
    snprintf(path, sizeof path, "%s/biax.h5", g_scratch.dir);
    snprintf(out_path, sizeof out_path, "%s/biax.txt", g_scratch.dir);
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_BIAXIAL;
    cdem_run_meta meta = {&p, "", "biaxial", "0", "test", 0};
    cdem_h5_writer *w;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    cdem_state s = {0};
    make_packing(&s, 30, 1000.0, 500.0, 1);
    for (int k = 0; k < 3; k++) {
        for (int j = 0; j < 4; j++) {
            cdem_series_sample smp;
            memset(&smp, 0, sizeof smp);
            smp.step = 40 * k + 10 * j;
            smp.axial_strain = 0.001 * (double)smp.step;
            smp.differential_stress = 1e5 * (double)smp.step;
            smp.sea_level = NAN;
            assert_int_equal(cdem_h5_writer_append_series(w, &smp, &err), CDEM_OK);
        }
        cdem_increment_info in;
        memset(&in, 0, sizeof in);
        in.number = k;
        in.step = 40 * k;
        in.sea_level = NAN;
        assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_OK);
    }
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
    cdem_state_free(&s);
    snprintf(cmd, sizeof cmd, "%s export-biaxial %s -o %s", g_exe, path, out_path);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    FILE *f = fopen(out_path, "r");
    assert_non_null(f);
    char line[256];
    assert_non_null(fgets(line, sizeof line, f));
    assert_non_null(strstr(line, "time_step axial_strain differential_stress"));
    int rows = 0;
    long long step;
    double e, sd;
    while (fscanf(f, "%lld %lf %lf", &step, &e, &sd) == 3) {
        assert_true(fabs(e - 0.001 * (double)step) < 1e-12);
        assert_true(fabs(sd - 1e5 * (double)step) < 1e-3);
        rows++;
    }
    fclose(f);
    assert_int_equal(rows, 12);
}

/* series (CSV of /series) and info --json (issue 18 item 8): checked against the file by
 * Debian's python (h5py, json). */
static void test_strain_cli_series_and_json(void **state) {
    (void)state;
    char cmd[8192], out[65536];
    snprintf(cmd, sizeof cmd, "%s/biax.h5", g_scratch.dir); /* written by the export-biaxial test */
    if (access(cmd, R_OK) != 0)
        skip();
    snprintf(
        cmd, sizeof cmd,
        "%s series %s/biax.h5 -o %s/series.csv && /usr/bin/python3 -c '"
        "import csv, h5py, math, sys\n"
        "rows = list(csv.DictReader(open(sys.argv[1])))\n"
        "f = h5py.File(sys.argv[2], \"r\")\n"
        "cols = list(f[\"series\"])\n"
        "assert sorted(rows[0]) == sorted(cols), (sorted(rows[0]), cols)\n"
        "assert len(rows) == len(f[\"series/step\"])\n"
        "for c in cols:\n"
        "    for r, v in zip(rows, f[\"series/\" + c][:]):\n"
        "        assert (math.isnan(v) and r[c] == \"nan\") or float(r[c]) == v, (c, r[c], v)\n"
        "print(len(rows))' %s/series.csv %s/biax.h5",
        g_exe, g_scratch.dir, g_scratch.dir, g_scratch.dir, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_int_equal(atoi(out), 12);
    snprintf(cmd, sizeof cmd,
             "%s info %s --json | /usr/bin/python3 -c '"
             "import json, sys\n"
             "d = json.load(sys.stdin)\n"
             "assert d[\"increment_count\"] == len(d[\"increments\"]) == %d\n"
             "assert d[\"first_increment\"] == 0 and d[\"last_increment\"] == %d\n"
             "assert d[\"end_of_equilibration\"] == 2 and d[\"stop_reason\"] == \"completed\"\n"
             "assert d[\"summary\"] == \"CLI test summary\"\n"
             "i = d[\"increments\"][4]\n"
             "assert i[\"phase\"] == \"deformation\" and i[\"net_displacement\"] == 10.0\n"
             "assert i[\"sea_level\"] is None and i[\"has_stress\"] is False\n"
             "print(\"ok\")'",
             g_exe, g_run, NINC, NINC - 1);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_string_equal(out, "ok\n");
}

static void test_strain_cli_errors(void **state) {
    (void)state;
    char cmd[8192], out[8192];
    snprintf(cmd, sizeof cmd, "%s compute %s --increment last --quantity total-max-sheer", g_exe,
             g_run);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "cdem-strain: unknown quantity 'total-max-sheer'; did you mean "
                                "'total-max-shear'?"));
    /* a name without its family: each family's, total first (issue 35, item 15: the nearest by
     * spelling was cum-max-shear) */
    snprintf(cmd, sizeof cmd, "%s compute %s --increment last --quantity max-shear", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "unknown quantity 'max-shear'; did you mean 'total-max-shear', "
                                "'incr-max-shear', 'cum-max-shear'?"));
    snprintf(cmd, sizeof cmd, "%s compute %s --increment 99 --quantity uplift", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "increment 99 does not exist"));
    snprintf(cmd, sizeof cmd, "%s compute %s --increment last --quantity sxx", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "needs stress"));
    /* nothing on stdout before such an error: no CSV header alone (issue 18) */
    const char *incs[] = {"last", "all"};
    for (int k = 0; k < 2; k++) {
        snprintf(cmd, sizeof cmd, "(%s compute %s --increment %s --quantity sxx 2>/dev/null)",
                 g_exe, g_run, incs[k]);
        assert_int_equal(run(cmd, out, sizeof out), 1);
        if (out[0])
            fail_msg("compute --increment %s --quantity sxx printed '%s' before failing", incs[k],
                     out);
        snprintf(cmd, sizeof cmd, "%s compute %s --increment %s --quantity sxx", g_exe, g_run,
                 incs[k]);
        assert_int_equal(run(cmd, out, sizeof out), 1);
        assert_non_null(strstr(out, "physics.calculate_stress = on"));
    }
    snprintf(cmd, sizeof cmd, "%s compute %s --quantity uplift", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "--increment"));
    snprintf(cmd, sizeof cmd, "%s frobnicate", g_exe);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "unknown command 'frobnicate' (and not an existing file)\n"));
    snprintf(cmd, sizeof cmd, "%s rendr", g_exe);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "unknown command 'rendr' (and not an existing file); did you "
                                "mean 'render'?"));
    snprintf(cmd, sizeof cmd, "%s render %s --colr x", g_exe, g_run);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "unknown option '--colr'; did you mean '--color'?"));
    snprintf(cmd, sizeof cmd, "%s info %s/missing.h5", g_exe, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "missing.h5"));
    const char *d = getenv("CDEM_TEST_DATA");
    snprintf(cmd, sizeof cmd, "%s import-cdem2d %s/cdem2d_malformed -o %s/bad.h5", g_exe,
             d ? d : "tests/data", g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "modelresults_1.txt:3:"));
    snprintf(cmd, sizeof cmd, "%s export-biaxial %s -o %s/b.txt", g_exe, g_run, g_scratch.dir);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "needs a biaxial test run"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_strain_cli_compute_csv),
        cmocka_unit_test(test_strain_cli_element_limits_info),
        cmocka_unit_test(test_strain_cli_exports_and_import),
        cmocka_unit_test(test_strain_cli_export_biaxial),
        cmocka_unit_test(test_strain_cli_series_and_json),
        cmocka_unit_test(test_strain_cli_errors),
        cmocka_unit_test(test_strain_cli_xdmf),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
