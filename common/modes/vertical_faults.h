/* vertical_faults: boundary.mode = vertical-faults, two vertical faults bounding a block that
 * moves down (caldera) or up (piston) (solver/modes/bc_vertical_faults.c). Its row of the mode
 * registry and its parameters, read as modes.def says. */
#ifdef CDEM_PARAM_TYPES
typedef enum { CDEM_VERT_CALDERA = 0, CDEM_VERT_PISTON = 1 } cdem_vertical_sense;
#endif

#ifdef CDEM_PARAM_FIELDS
double vertical_fault_location;     /* two vertical faults: first fault, fraction of base */
double vertical_fault_spacing;      /* distance to the second fault, fraction of base */
cdem_vertical_sense vertical_sense; /* caldera (block down) or piston (block up) */
#endif

#ifdef CDEM_PARAM_WORDS
static const char *const vert_words[] = {"caldera", "piston", NULL};
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "vertical_fault_location", CDEM_PTYPE_DOUBLE, P_OFF(vertical_fault_location), 0, "", "0.35", 0, 1, 1, 1, NULL,
     "two vertical faults: first fault, fraction of the base length", 0, 0},
    {"boundary", "vertical_fault_spacing", CDEM_PTYPE_DOUBLE, P_OFF(vertical_fault_spacing), 0, "", "0.3", 0, 1, 1, 1, NULL,
     "two vertical faults: distance to the second fault, fraction of the base length", 0, 0},
    {"boundary", "vertical_sense", CDEM_PTYPE_ENUM, P_OFF(vertical_sense), 0, "", "caldera", 0, 0, 0, 0, vert_words,
     "two vertical faults: caldera (block down, extension) or piston (block up, compression)", 0, 0},
#endif

#ifdef CDEM_MODE
CDEM_MODE(VERTICAL_FAULTS, vertical_faults, "vertical-faults", CDEM_CLOCK_DISPLACEMENT,
          "two vertical faults through the base: the block between them moves down (caldera) "
          "or up (piston)")
#endif
    /* clang-format on */
