/* test_lift: a fixture of the tests (solver/modes/bc_test_lift.c), not a mode of the model: its
 * row is CDEM_TEST_MODE, so no parameter file can name it. It has one parameter of its own,
 * boundary.test_lift_ratio, a fixture's row (listed nowhere, recorded when set): the proof
 * that a mode's keys are its own file's (issue 45, item 2). */
#ifdef CDEM_PARAM_FIELDS
double test_lift_ratio; /* test-lift: base rise per metre of boundary displacement */
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "test_lift_ratio", CDEM_PTYPE_DOUBLE, P_OFF(test_lift_ratio), 0, "", "0.5", 0, 10, 0, 0, NULL,
     "test-lift (a fixture of the tests): the base rises this many metres per metre of boundary displacement", 1, 1},
#endif

#ifdef CDEM_TEST_MODE
CDEM_TEST_MODE(TEST_LIFT, test_lift, "test-lift", CDEM_CLOCK_DISPLACEMENT,
               "a fixture of the tests: the base rises test_lift_ratio metres per metre of "
               "boundary displacement")
#endif
    /* clang-format on */
