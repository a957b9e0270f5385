/* still: boundary.mode = still, a box whose walls and base never move
 * (solver/modes/bc_still.c): the deformation is driven by what acts inside it, a regional tilt
 * ([tilt]) or a viscous substrate spreading under its load ([salt]). Its row of the mode
 * registry, read as modes.def says; it has no parameters of its own. Its clock is time: with
 * no moving boundary the display interval is in seconds, as in the repose mode. */
#ifdef CDEM_MODE
CDEM_MODE(STILL, still, "still", CDEM_CLOCK_TIME,
          "walls and base never move: the deformation is driven from inside the box, by a "
          "regional tilt ([tilt]) or a substrate spreading under its load ([salt]); "
          "time.display_interval in seconds")
#endif
