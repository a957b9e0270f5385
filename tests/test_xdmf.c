/* Tests of common/xdmf: both flavours of the sidecar text from a described document (the
 * layout the Xdmf3 readers need, the XDMF 2 HyperSlabs, empty grids left out, escaping, a
 * failing grid callback), the reference to the HDF5 file, the sidecar name, and the xy view
 * (fixed and growing with its sources). test_format checks real run files' sidecars;
 * make validate opens them in ParaView. Scratch files in $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "xdmf.h"
#include "scratch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Two grids of 3 and 0 points, then one of 5; the one of 0 must be left out. */
static int grid_cb(void *ctx, size_t k, cdem_xdmf_grid *g) {
    int *fail_at = ctx;
    if ((int)k == *fail_at)
        return -1;
    static const long long n[3] = {3, 0, 5}, off[3] = {0, 8192, 8192};
    g->number = (int)k * 10;
    g->time = 1.5 * (double)k;
    g->n = n[k];
    g->x = (cdem_xdmf_data){"/increments/x", off[k], 16384, "Float", 8};
    g->y = (cdem_xdmf_data){"/increments/y", off[k], 16384, "Float", 8};
    g->xy = (cdem_xdmf_data){"/increments/xy", off[k], 16384, "Float", 8};
    g->n_attributes = 2;
    g->attribute_names[0] = "flags";
    g->attributes[0] = (cdem_xdmf_data){"/increments/flags", off[k], 16384, "UInt", 4};
    g->attribute_names[1] = "a&b";
    g->attributes[1] = (cdem_xdmf_data){"/increments/ab", off[k], 16384, "Int", 4};
    return 0;
}

static char *write_doc(cdem_xdmf_flavour fl, int fail_at, int *rc) {
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    const cdem_xdmf_doc doc = {"r&n.h5", fl, 3, grid_cb, &fail_at};
    *rc = cdem_xdmf_write(f, &doc);
    fclose(f);
    return buf;
}

static void test_xdmf_flavour_3(void **state) {
    (void)state;
    int rc;
    char *t = write_doc(CDEM_XDMF3, -1, &rc);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(t, "<Xdmf Version=\"3.0\""));
    /* the shared vertex list: 0..4 (the most points of a grid) */
    assert_non_null(strstr(t, "<DataItem Name=\"vertices\" Dimensions=\"5\" NumberType=\"Int\" "
                              "Precision=\"4\" Format=\"XML\">0 1 2 3 4 </DataItem>"));
    assert_non_null(strstr(t, "<Grid Name=\"increment_000000\""));
    assert_null(strstr(t, "increment_000010")); /* no points: left out */
    assert_non_null(strstr(t, "<Grid Name=\"increment_000020\""));
    assert_non_null(strstr(t, "<Time Value=\"3\"/>"));
    assert_non_null(strstr(t, "<DataItem Dimensions=\"3 1\" Format=\"XML\">0 1 3</DataItem>\n"
                              "          <xi:include xpointer=\"xpointer(/Xdmf/Domain/"
                              "DataItem[@Name=&quot;vertices&quot;])\"/>"));
    assert_non_null(strstr(t, "<Geometry GeometryType=\"XY\">\n        <DataItem Dimensions=\"5 "
                              "2\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">r&amp;n.h5:"
                              "/increments/xy|8192 0:1 1:5 2:16384 2</DataItem>"));
    assert_non_null(strstr(t, "<Attribute Name=\"flags\" AttributeType=\"Scalar\" "
                              "Center=\"Node\">\n        <DataItem Dimensions=\"5\" "
                              "NumberType=\"UInt\" Precision=\"4\" Format=\"HDF\">r&amp;n.h5:"
                              "/increments/flags|8192:1:5:16384</DataItem>"));
    assert_non_null(strstr(t, "<Attribute Name=\"a&amp;b\""));
    assert_null(strstr(t, "HyperSlab\" Dimensions=\"5\" Type=\"HyperSlab\">\n          "
                          "<DataItem Dimensions=\"3 1\" Format=\"XML\">8192"));
    free(t);
}

static void test_xdmf_flavour_2(void **state) {
    (void)state;
    int rc;
    char *t = write_doc(CDEM_XDMF2, -1, &rc);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(t, "<Xdmf Version=\"2.0\""));
    assert_null(strstr(t, "vertices"));
    assert_null(strstr(t, "|"));
    assert_non_null(strstr(t, "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"5\" "
                              "NodesPerElement=\"1\"/>"));
    assert_non_null(strstr(t, "<Geometry GeometryType=\"X_Y\">"));
    assert_non_null(strstr(t, "<DataItem ItemType=\"HyperSlab\" Dimensions=\"5\" "
                              "Type=\"HyperSlab\">\n          <DataItem Dimensions=\"3 1\" "
                              "Format=\"XML\">8192 1 5</DataItem>\n          <DataItem "
                              "Dimensions=\"16384\" NumberType=\"Float\" Precision=\"8\" "
                              "Format=\"HDF\">r&amp;n.h5:/increments/y</DataItem>"));
    free(t);
    /* a grid that cannot be described fails the write */
    t = write_doc(CDEM_XDMF2, 2, &rc);
    assert_int_equal(rc, -1);
    free(t);
}

static void test_xdmf_names_and_references(void **state) {
    (void)state;
    char *p = cdem_xdmf_path_for("dir.h5/run.h5");
    assert_string_equal(p, "dir.h5/run.xmf");
    free(p);
    p = cdem_xdmf_path_for("run.hdf5");
    assert_string_equal(p, "run.xmf");
    free(p);
    p = cdem_xdmf_path_for("run.data");
    assert_string_equal(p, "run.data.xmf");
    free(p);
    char h5[1024], other[1500], ref[4096];
    cdem_error err;
    scratch_path(h5, sizeof h5, "ref.h5");
    assert_true(snprintf(other, sizeof other, "%s.d", h5) < (int)sizeof other);
    assert_int_equal(mkdir(other, 0777), 0);
    char xmf[1400];
    assert_true(snprintf(xmf, sizeof xmf, "%.*s.xmf", (int)(strlen(h5) - 3), h5) < (int)sizeof xmf);
    assert_int_equal(cdem_xdmf_reference(h5, xmf, ref, sizeof ref, &err), CDEM_OK);
    assert_string_equal(ref, strrchr(h5, '/') + 1); /* the same folder: the name */
    assert_true(snprintf(xmf, sizeof xmf, "%s/side.xmf", other) < (int)sizeof xmf);
    assert_int_equal(cdem_xdmf_reference(h5, xmf, ref, sizeof ref, &err), CDEM_OK);
    assert_true(ref[0] == '/' && strstr(ref, strrchr(h5, '/'))); /* elsewhere: absolute */
    assert_int_equal(cdem_xdmf_reference("/nonexistent-dir/run.h5", xmf, ref, sizeof ref, &err),
                     CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "/nonexistent-dir/run.h5"));
    rmdir(other);
    /* the file writer: through .tmp, renamed; an unwritable place names the file */
    int fail_at = -1;
    const cdem_xdmf_doc doc = {"r.h5", CDEM_XDMF3, 3, grid_cb, &fail_at};
    assert_int_equal(cdem_xdmf_write_file("/nonexistent-dir/x.xmf", &doc, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "/nonexistent-dir/x.xmf"));
    assert_true(snprintf(xmf, sizeof xmf, "%s.xmf", h5) < (int)sizeof xmf);
    assert_int_equal(cdem_xdmf_write_file(xmf, &doc, &err), CDEM_OK);
    assert_true(snprintf(other, sizeof other, "%s.tmp", xmf) < (int)sizeof other);
    assert_int_equal(access(xmf, R_OK), 0);
    assert_int_equal(access(other, F_OK), -1);
    remove(xmf);
}

static hid_t vector(hid_t loc, const char *name, const double *v, hsize_t n, int grow) {
    hsize_t max = grow ? H5S_UNLIMITED : n, chunk = 4;
    hid_t sp = H5Screate_simple(1, &n, &max), dcpl = H5Pcreate(H5P_DATASET_CREATE);
    if (grow)
        H5Pset_chunk(dcpl, 1, &chunk);
    hid_t d = H5Dcreate2(loc, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    assert_true(d >= 0);
    if (n)
        assert_true(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0);
    H5Pclose(dcpl);
    H5Sclose(sp);
    return d;
}

/* Rows of loc/name (n x 2) into out; returns the row count. */
static hsize_t read_xy(hid_t file, const char *name, double *out) {
    hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
    assert_true(d >= 0);
    hid_t sp = H5Dget_space(d);
    hsize_t dims[2];
    assert_int_equal(H5Sget_simple_extent_dims(sp, dims, NULL), 2);
    assert_int_equal(dims[1], 2);
    if (dims[0])
        assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0);
    H5Sclose(sp);
    H5Dclose(d);
    return dims[0];
}

static void test_xdmf_xy_view(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "view.h5");
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_libver_bounds(fapl, H5F_LIBVER_V110, H5F_LIBVER_V110);
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    assert_true(f >= 0);
    const double x[3] = {1, 2, 3}, y[3] = {-1, -2, -3};
    hid_t g = H5Gcreate2(f, "fixed", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(vector(g, "x", x, 3, 0));
    H5Dclose(vector(g, "y", y, 3, 0));
    hid_t v = cdem_xdmf_create_xy_view(g, "/fixed/x", "/fixed/y", "xy", 0);
    assert_true(v >= 0);
    H5Dclose(v);
    hid_t h = H5Gcreate2(f, "grow", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t gx = vector(h, "x", x, 0, 1), gy = vector(h, "y", y, 0, 1);
    v = cdem_xdmf_create_xy_view(h, "/grow/x", "/grow/y", "xy", 1);
    assert_true(v >= 0);
    H5Dclose(v);
    /* the sources grow after the view was made */
    hsize_t n = 3;
    assert_true(H5Dset_extent(gx, &n) >= 0 && H5Dset_extent(gy, &n) >= 0);
    assert_true(H5Dwrite(gx, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x) >= 0);
    assert_true(H5Dwrite(gy, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, y) >= 0);
    H5Dclose(gx);
    H5Dclose(gy);
    assert_true(cdem_xdmf_create_xy_view(h, "/grow/none", "/grow/y", "bad", 0) < 0);
    H5Gclose(g);
    H5Gclose(h);
    H5Fclose(f);
    f = H5Fopen(path, H5F_ACC_RDONLY, fapl); /* the views resolve on a fresh open */
    H5Pclose(fapl);
    double xy[6];
    const char *names[2] = {"fixed/xy", "grow/xy"};
    for (int k = 0; k < 2; k++) {
        memset(xy, 0, sizeof xy);
        assert_int_equal(read_xy(f, names[k], xy), 3);
        for (int i = 0; i < 3; i++)
            assert_true(xy[2 * i] == x[i] && xy[2 * i + 1] == y[i]);
    }
    H5Fclose(f);
    remove(path);
}

int main(void) {
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* the refused view prints nothing */
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_xdmf_flavour_3),
        cmocka_unit_test(test_xdmf_flavour_2),
        cmocka_unit_test(test_xdmf_names_and_references),
        cmocka_unit_test(test_xdmf_xy_view),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
