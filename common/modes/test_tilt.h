/* test_tilt: a fixture of the tests (solver/modes/bc_test_tilt.c), not a mode of the model:
 * its row is CDEM_TEST_MODE, so no parameter file can name it. */
#ifdef CDEM_TEST_MODE
CDEM_TEST_MODE(TEST_TILT, test_tilt, "test-tilt", CDEM_CLOCK_DISPLACEMENT,
               "a fixture of the tests: gravity tilted 2 degrees by its derive, turned 1 degree "
               "more by its gravity hook")
#endif
