/* tilt: the parameters of the regional tilt ([tilt]; solver/tilt/, docs/solver.md, "Regional
 * tilt"), read as processes.def says: its section's name, its fields of cdem_params and its
 * rows of the parameter table. Every key is recorded only when set, so that the parameter
 * records of runs without a tilt stay as they were (params.c leaves the section out of them). */
/* clang-format off */
#ifdef CDEM_PARAM_SECTIONS
"tilt",
#endif

#ifdef CDEM_PARAM_FIELDS
double tilt_angle;    /* degrees, [-45, 45]: the frame's rotation at the end of the tilting,
                         positive when the margin comes to dip toward +x; 0: off */
double tilt_onset;    /* s of deformation time before the tilting begins, >= 0 */
double tilt_duration; /* s of deformation time over which it tilts at a constant rate, > 0;
                         NaN = the rest of the run ("rest") */
#endif

#ifdef CDEM_PARAM_WORDS
/* tilt.duration's word: from onset to the run's last deformation step */
static const char *const tilt_rest_words[] = {"rest", NULL};
#endif

#ifdef CDEM_PARAM_ROWS
    {"tilt", "angle", CDEM_PTYPE_DOUBLE, P_OFF(tilt_angle), 0, "degrees", "0", -45, 45, 0, 0, NULL,
     "regional tilt: the whole model rotates rigidly by this angle relative to gravity (gravity turns in the model's frame); positive: the margin dips toward +x, so the cover is pulled toward +x; 0: off", 1, 0},
    {"tilt", "onset", CDEM_PTYPE_DOUBLE, P_OFF(tilt_onset), 0, "s", "0", 0, 1e6, 0, 0, NULL,
     "deformation time (model time after equilibration: the boundaries' clock) at which the tilting begins", 1, 0},
    {"tilt", "duration", CDEM_PTYPE_DOUBLE, P_OFF(tilt_duration), 0, "s", "rest", 0, 1e6, 1, 0, tilt_rest_words,
     "deformation time over which the model tilts at a constant rate; rest: from onset to the run's end", 1, 0},
#endif
    /* clang-format on */
