/* assert_near: double-precision closeness for cmocka tests (cmocka's assert_float_equal
 * works in single precision). Include after <cmocka.h>. */
#ifndef CDEM_ASSERT_NEAR_H
#define CDEM_ASSERT_NEAR_H

#include <math.h>

#define assert_near(a, b, tol) assert_near_impl((a), (b), (tol), #a, __FILE__, __LINE__)

__attribute__((unused)) static void assert_near_impl(double a, double b, double tol,
                                                     const char *expr, const char *file, int line) {
    if (!(fabs(a - b) <= tol) && !(a == b)) {
        print_error("%s:%d: %s = %.17g, expected %.17g within %g\n", file, line, expr, a, b, tol);
        fail();
    }
}

#endif
