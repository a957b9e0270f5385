/* test_still: a fixture of the tests (solver/modes/bc_test_still.c), not a mode of the model:
 * its row is CDEM_TEST_MODE, so no parameter file can name it. */
#ifdef CDEM_TEST_MODE
CDEM_TEST_MODE(TEST_STILL, test_still, "test-still", CDEM_CLOCK_DISPLACEMENT,
               "a fixture of the tests: a mode with only the required hooks; nothing moves")
#endif
