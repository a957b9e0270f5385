/* planar_fault: boundary.mode = planar-fault, a planar normal or reverse fault through the
 * base with optional inversion (solver/modes/bc_planar_fault.c). Its row of the mode registry
 * and its parameters, read as modes.def says. The keys of a fault on the base (sense,
 * location, dip, inversion) are this mode's; the listric and the irregular fault take them
 * too (listric_fault.h, irregular_fault.h add theirs). */
#ifdef CDEM_PARAM_TYPES
typedef enum { CDEM_SENSE_NORMAL = 0, CDEM_SENSE_REVERSE = 1 } cdem_fault_sense;
#endif

#ifdef CDEM_PARAM_FIELDS
cdem_fault_sense fault_sense; /* planar/listric/irregular: normal or reverse */
double fault_location;        /* fraction of the base length, 0-1 (exclusive) */
double fault_dip;             /* degrees, planar: dip; listric: basal dip */
int inversion;                /* 0/1: reverse the sense during the run */
double inversion_percent;     /* % of total displacement at which it inverts, 0-100 */
#endif

#ifdef CDEM_PARAM_WORDS
static const char *const sense_words[] = {"normal", "reverse", NULL};
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "fault_sense", CDEM_PTYPE_ENUM, P_OFF(fault_sense), 0, "", "normal", 0, 0, 0, 0, sense_words,
     "planar/listric/irregular fault: normal or reverse displacement", 0, 0},
    {"boundary", "fault_location", CDEM_PTYPE_DOUBLE, P_OFF(fault_location), 0, "", "0.5", 0, 1, 1, 1, NULL,
     "fault location at the base, fraction of the base length", 0, 0},
    {"boundary", "fault_dip", CDEM_PTYPE_DOUBLE, P_OFF(fault_dip), 0, "degrees", "30", 0, 90, 1, 0, NULL,
     "planar: fault dip; listric: dip of the lowest segment (it steepens to 90)", 0, 0},
    {"boundary", "inversion", CDEM_PTYPE_BOOL, P_OFF(inversion), 0, "", "off", 0, 1, 0, 0, NULL,
     "invert the fault sense during the run (planar/listric/irregular)", 0, 0},
    {"boundary", "inversion_percent", CDEM_PTYPE_DOUBLE, P_OFF(inversion_percent), 0, "%", "50", 0, 100, 1, 1, NULL,
     "% of the total displacement at which the sense inverts", 0, 0},
#endif

#ifdef CDEM_MODE
CDEM_MODE(PLANAR_FAULT, planar_fault, "planar-fault", CDEM_CLOCK_DISPLACEMENT,
          "a planar normal or reverse fault through the base at fault_location, dipping "
          "fault_dip; the hanging-wall block moves along it, and may invert")
#endif
    /* clang-format on */
