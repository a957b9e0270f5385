/* repose: boundary.mode = repose, the angle-of-repose collapse: a lateral wall, or both,
 * removed after equilibration (solver/modes/bc_repose.c). Its row of the mode registry and
 * its parameter, read as modes.def says. */
#ifdef CDEM_PARAM_FIELDS
cdem_walls_choice repose_walls; /* right wall removed, or both */
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "repose_walls", CDEM_PTYPE_ENUM, P_OFF(repose_walls), 0, "", "right", 0, 0, 0, 0, walls_words,
     "repose-collapse: right wall removed, or both, after equilibration", 0, 0},
#endif

#ifdef CDEM_MODE
CDEM_MODE(REPOSE, repose, "repose", CDEM_CLOCK_TIME,
          "angle-of-repose collapse: the right wall, or both, removed after equilibration; the "
          "pile slumps to its slope (time.display_interval in seconds)")
#endif
    /* clang-format on */
