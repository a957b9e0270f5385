/* test_qexport: CSV and HDF5 output of computed quantities, read back. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"
#include "qexport.h"
#include "scratch.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void make_state(cdem_state *s) {
    cdem_error err;
    cdem_state_init(s, 4, 0, &err);
    cdem_state_append(s, 4, 1.5, 2.25, 50, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(s, 9, -3.0, 7.0, 75, 1, 2, 0, 0, NULL, &err);
}

static void test_qexport_csv(void **st) {
    (void)st;
    cdem_state s = {0};
    make_state(&s);
    const double v[2] = {0.125, NAN};
    FILE *f = tmpfile();
    cdem_error err;
    assert_int_equal(cdem_qexport_csv_header(f, 1, &err), CDEM_OK);
    assert_int_equal(cdem_qexport_csv_rows(f, 1, 56, &s, v, &err), CDEM_OK);
    rewind(f);
    char buf[256];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    assert_string_equal(buf, "increment,id,x,y,value\n56,4,1.500000,2.250000,0.125\n"
                             "56,9,-3.000000,7.000000,nan\n");
    fclose(f);
    cdem_state_free(&s);
}

static void test_qexport_h5_round_trip(void **st) {
    (void)st;
    cdem_state s = {0};
    make_state(&s);
    const double v[2] = {0.5, NAN};
    const cdem_quantity *q;
    cdem_error err;
    cdem_quantity_find("total-max-shear", &q, &err);
    char path[1024];
    scratch_path(path, sizeof path, "qexport.h5");
    cdem_qexport_h5 *h;
    assert_int_equal(cdem_qexport_h5_create(path, q, &h, &err), CDEM_OK);
    assert_int_equal(cdem_qexport_h5_write(h, 282, 1234.5, &s, v, &err), CDEM_OK);
    assert_int_equal(cdem_qexport_h5_close(h, &err), CDEM_OK);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    hid_t d = H5Dopen2(file, "increments/000282/value", H5P_DEFAULT);
    double back[2];
    assert_true(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, back) >= 0);
    H5Dclose(d);
    assert_near(back[0], 0.5, 0);
    assert_true(isnan(back[1]));
    int32_t ids[2];
    d = H5Dopen2(file, "increments/000282/id", H5P_DEFAULT);
    H5Dread(d, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids);
    H5Dclose(d);
    assert_int_equal(ids[1], 9);
    H5Fclose(file);
    remove(path);
    assert_int_equal(cdem_qexport_h5_create("/nonexistent/q.h5", q, &h, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "cannot create /nonexistent/q.h5"));
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_qexport_csv),
        cmocka_unit_test(test_qexport_h5_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
