/* detachment: boundary.mode = detachment, the right wall or both lateral walls moving inward
 * (shortening) or outward (extension) over a fixed base (solver/modes/bc_detachment.c). Its
 * row of the mode registry and its parameters, read as modes.def says. */
#ifdef CDEM_PARAM_TYPES
/* the moving walls go inward (shortening) or outward (extension, a cover spreading over its
 * detachment) */
typedef enum { CDEM_DETACH_SHORTENING = 0, CDEM_DETACH_EXTENSION = 1 } cdem_detachment_sense;
#endif

#ifdef CDEM_PARAM_FIELDS
cdem_walls_choice detachment_walls;     /* right wall moving, or both */
cdem_detachment_sense detachment_sense; /* walls inward (shortening) or outward */
#endif

#ifdef CDEM_PARAM_WORDS
static const char *const detach_sense_words[] = {"shortening", "extension", NULL};
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"boundary", "detachment_walls", CDEM_PTYPE_ENUM, P_OFF(detachment_walls), 0, "", "right", 0, 0, 0, 0, walls_words,
     "detachment: right wall moving, or both walls moving inward (each at the boundary speed)", 0, 0},
    {"boundary", "detachment_sense", CDEM_PTYPE_ENUM, P_OFF(detachment_sense), 0, "", "shortening", 0, 0, 0, 0, detach_sense_words,
     "detachment: the moving walls go inward (shortening) or outward (extension)", 0, 0},
#endif

#ifdef CDEM_MODE
CDEM_MODE(DETACHMENT, detachment, "detachment", CDEM_CLOCK_DISPLACEMENT,
          "the right wall, or both lateral walls, moving inward (shortening) or outward "
          "(extension) over a fixed base")
#endif
    /* clang-format on */
