/* listric_fault: boundary.mode = listric-fault, a listric fault of the built-in shape
 * (solver/modes/bc_listric.c, solver/modes/fault_file.c) with the fault keys of
 * planar_fault.h. Its row of the mode registry and its parameter, read as modes.def says. */
#ifdef CDEM_PARAM_TYPES
typedef enum {
    CDEM_KIN_CH = 0,
    CDEM_KIN_CD = 1
} cdem_fault_kinematics; /* constant heave / displacement */
#endif

#ifdef CDEM_PARAM_FIELDS
cdem_fault_kinematics kinematics; /* listric/irregular: CH or CD */
#endif

#ifdef CDEM_PARAM_WORDS
static const char *const kin_words[] = {"ch", "cd", NULL};
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "kinematics", CDEM_PTYPE_ENUM, P_OFF(kinematics), 0, "", "ch", 0, 0, 0, 0, kin_words,
     "listric/irregular: constant heave (ch) or constant displacement (cd, mylar sheet)", 0, 0},
#endif

#ifdef CDEM_MODE
CDEM_MODE(LISTRIC_FAULT, listric_fault, "listric-fault", CDEM_CLOCK_DISPLACEMENT,
          "a listric fault from fault_location, its lowest segment dipping fault_dip and "
          "steepening to 90 degrees; constant heave (ch) or constant displacement (cd)")
#endif
    /* clang-format on */
