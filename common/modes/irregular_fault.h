/* irregular_fault: boundary.mode = irregular-fault, the listric mode's sculpted wall with the
 * vertices of a file (solver/modes/bc_listric.c, solver/modes/fault_file.c), with the fault
 * keys of planar_fault.h and the kinematics of listric_fault.h. Its row of the mode registry
 * and its parameter, read as modes.def says. */
#ifdef CDEM_PARAM_FIELDS
char fault_file[CDEM_PATH_MAX]; /* irregular: text file of x y vertices in m */
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "fault_file", CDEM_PTYPE_STRING, P_OFF(fault_file), CDEM_PATH_MAX, "", "", 0, 0, 0, 0, NULL,
     "irregular fault: text file of x y vertices in m, from the base up-dip", 0, 0},
#endif

#ifdef CDEM_MODE
CDEM_MODE(IRREGULAR_FAULT, irregular_fault, "irregular-fault", CDEM_CLOCK_DISPLACEMENT,
          "a fault of any shape: the listric fault's wall through the x y vertices of "
          "fault_file, constant heave or constant displacement")
#endif
    /* clang-format on */
