/* biaxial: boundary.mode = biaxial, the uni/biaxial test of the calibration: platens close on
 * a 10 x 5 sample under a confining pressure (solver/modes/bc_biaxial.c). Its row of the mode
 * registry and its parameter, read as modes.def says. */
#ifdef CDEM_PARAM_FIELDS
double confining_pressure; /* biaxial: N/m on the free edges, >= 0 */
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "confining_pressure", CDEM_PTYPE_DOUBLE, P_OFF(confining_pressure), 0, "N/m", "0", 0, 1e9, 0, 0, NULL,
     "biaxial: confining pressure on the free edges (Pa in 3-D; 0 = uniaxial)", 0, 0},
#endif

#ifdef CDEM_MODE
CDEM_MODE(BIAXIAL, biaxial, "biaxial", CDEM_CLOCK_AXIAL_STRAIN,
          "the uni/biaxial test of the calibration: platens close on a 10 x 5 sample under "
          "confining_pressure, without gravity")
#endif
    /* clang-format on */
