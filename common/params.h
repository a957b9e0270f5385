/* params: every user-settable parameter of a cdem-c model, and the one table that
 * describes them.
 *
 * The table (params.c, one static const row per parameter: section, key, type, unit,
 * default, range or allowed words, one-line help, offset into cdem_params) is the single
 * source of truth: parsing, validation, --print-defaults, docs/parameters.md, the
 * parameter record stored in every output file and the summary all read it.
 * Gathered into it: a law, a mode or a process that has parameters of its own declares them
 * in its own file (common/laws/law_<name>.h, common/modes/<id>.h, common/processes/<id>.h),
 * in four parts that this header and params.c include through the registries (laws.def,
 * modes.def, processes.def): its enums (CDEM_PARAM_TYPES), its fields of cdem_params
 * (CDEM_PARAM_FIELDS, in its section's place: a law's in [material], a mode's in
 * [boundary], a process's in its own section, CDEM_PARAM_SECTIONS), the words of its enum
 * keys (CDEM_PARAM_WORDS) and its rows (CDEM_PARAM_ROWS, written as the table's, with
 * P_OFF(field) and NOMAX). Adding one touches no line here or in params.c. The fields keep
 * flat names (p->fault_dip), so a key's owner can change without its readers changing.
 * Parameter files are INI ("[section]" then "key = value"; '#' or ';' start comments;
 * CRLF accepted). Values are SI units (m, s, kg/m^3, N, N/m) unless the unit says otherwise.
 * Ownership: cdem_params is a plain value (no pointers except fault_file, a fixed buffer);
 * copy it freely. Thread safety: no shared state; the table is const. */
#ifndef CDEM_PARAMS_H
#define CDEM_PARAMS_H

#include "cdem_error.h"

#include <stddef.h>
#include <stdio.h>

#define CDEM_PATH_MAX 1024

/* Boundary actors (docs/solver.md, "Boundaries on a timeline"): [boundary] is the first, and
 * [boundary.2] ... [boundary.8] add one each, stepped in order, each a mode with its own keys
 * and its own window of the run's boundary displacement (start, stop). */
#define CDEM_BOUNDARY_ACTORS 8
/* The text an actor's section may hold: its "key = value" lines. */
#define CDEM_ACTOR_TEXT 2048

typedef enum { CDEM_MATERIAL_GRANULAR = 0, CDEM_MATERIAL_BONDED = 1 } cdem_material_model;

/* Granular contact laws: how the cohesion C0 enters the shear strength of a contact, one
 * CDEM_LAW_<ID> per row of common/laws/laws.def (docs/solver.md section 1): the laws of
 * parameter files first, then the tests' fixtures (CDEM_TEST_LAW). */
typedef enum {
#define CDEM_LAW(ID, word, description, scalar, lanes) CDEM_LAW_##ID,
#include "laws/laws.def"
#undef CDEM_LAW
    CDEM_LAW_WORDS, /* the number of laws a parameter file can name */
    CDEM_LAW_TESTS_BEFORE = CDEM_LAW_WORDS - 1,
#define CDEM_TEST_LAW(ID, word, description, scalar, lanes) CDEM_LAW_##ID,
#include "laws/laws.def"
#undef CDEM_TEST_LAW
    CDEM_LAW_COUNT /* every registered law, the tests' included */
} cdem_granular_law;

/* Granular: which contacts carry the cohesion C0. */
typedef enum {
    CDEM_COHESIVE_EQUILIBRATED = 0, /* contacts touching at the end of equilibration */
    CDEM_COHESIVE_FORMED = 1,       /* those, and every contact formed after it */
    CDEM_COHESIVE_INITIAL = 2,      /* contacts of the built assembly still touching then */
} cdem_cohesive_contacts;

/* What an increment of a mode's run is measured by (its row in common/modes/<id>.h): the
 * boundary displacement (m), the time (s: a mode without moving boundaries, whose display
 * interval is in seconds) or the axial strain (the biaxial test). The analysis labels an
 * increment with it. */
typedef enum {
    CDEM_CLOCK_DISPLACEMENT = 0,
    CDEM_CLOCK_TIME = 1,
    CDEM_CLOCK_AXIAL_STRAIN = 2,
} cdem_mode_clock;

/* Boundary (faulting) modes, one CDEM_MODE_<ID> per row of common/modes.def (docs/solver.md
 * section 4): the modes of parameter files first, then the tests' fixtures. */
typedef enum {
#define CDEM_MODE(ID, id, word, clock, description) CDEM_MODE_##ID,
#include "modes.def"
#undef CDEM_MODE
    CDEM_MODE_WORDS, /* the number of modes a parameter file can name */
    CDEM_MODE_TESTS_BEFORE = CDEM_MODE_WORDS - 1,
#define CDEM_TEST_MODE(ID, id, word, clock, description) CDEM_MODE_##ID,
#include "modes.def"
#undef CDEM_TEST_MODE
    CDEM_MODE_COUNT /* every registered mode, the tests' included */
} cdem_mode;

/* Which lateral walls a mode moves or removes: the right one, or both (a word several modes'
 * keys share). */
typedef enum { CDEM_WALLS_RIGHT = 0, CDEM_WALLS_BOTH = 1 } cdem_walls_choice;
typedef enum { CDEM_WEAK_OFF = 0, CDEM_WEAK_LOWER = 1, CDEM_WEAK_UPPER = 2 } cdem_weak_interval;
/* What damps the elements' motion (docs/solver.md, "Damping"). */
typedef enum {
    CDEM_DAMPING_ABSOLUTE = 0, /* the paper's: a drag c v on each free element's velocity */
    CDEM_DAMPING_CONTACT = 1,  /* a normal dashpot on each contact: relative motion only */
} cdem_damping_mode;
/* Which contacts flexural slip makes strengthless. */
typedef enum {
    CDEM_FLEX_LAYER_CONTACTS = 0, /* every contact between two different pre-growth layers */
    CDEM_FLEX_WEAK_LAYERS = 1,    /* every contact of an element of layer 4, 8, 12, 16 or 20 */
} cdem_flexural_style;
typedef enum {
    CDEM_SEA_NULL = 0, /* factor 0.0 */
    CDEM_SEA_LOW,      /* factor 0.25 */
    CDEM_SEA_MID,      /* factor 0.5 */
    CDEM_SEA_HIGH,     /* factor 0.75 */
    CDEM_SEA_VERY_HIGH /* factor 1.0 */
} cdem_sea_level_rise;

/* The enums of the parameters that laws, modes and processes own (their files' part
 * CDEM_PARAM_TYPES; modes.def says what the parts are). */
#define CDEM_PARAM_TYPES
#include "laws/laws.def"
#include "modes.def"
#include "processes.def"
#undef CDEM_PARAM_TYPES

/* Per-contact-class material values (element-element, element-wall, element-fault). */
typedef struct {
    double friction;        /* Coulomb friction coefficient mu, >= 0 */
    double cohesion;        /* cohesion force C0 in N (per metre of thickness), >= 0 */
    double breaking_strain; /* bonded model: bond breaks when r - R >= r0 * R; r0 > 0 */
} cdem_contact_material;

typedef struct {
    /* [assembly] */
    double width;               /* assembly width in model units, 10-100 */
    double height;              /* assembly height in model units, 2.5-7.5 */
    double unit_scaling;        /* metres per model unit, 100-1000 */
    int half_radii;             /* 0/1: radii 0.025..0.0625 units instead of 0.05..0.125 */
    double radius_scale;        /* the four radii as a multiple of 0.05..0.125 units (> 0; 1:
                                   cdem's; half_radii is 0.5); cdem_params_radius_scale */
    int wall_height_multiplier; /* lateral wall height = multiplier * assembly height, 1-4 */
    double base_spacing;        /* centre spacing of the base discs in wall radii, 1-2 */
    long seed;                  /* random seed of the packing (and all other randomness), >= 0 */

    /* [time] */
    double runtime;          /* total simulated time in s, >= 100 */
    double equilibration;    /* equilibration time in s, >= 100 and < runtime */
    double display_interval; /* m of boundary displacement between increments (s for repose),
                                0.1-1000 */

    /* [physics] */
    double gravity;                 /* m/s^2, 0.5-25 (ignored, i.e. zero, in the biaxial test) */
    double density;                 /* kg/m^3, 1500-3500 */
    int keep_constants;             /* 0/1: use the 1000 m constants whatever the unit scaling */
    double deformation_damping;     /* multiplier of the damping on deformation steps, 0-1 */
    int calculate_stress;           /* 0/1: store per-element stress in every increment */
    cdem_damping_mode damping_mode; /* absolute (the paper's) or contact */
    double contact_damping;         /* contact: fraction of each contact's critical damping */

    /* [material] */
    cdem_material_model material;   /* granular (frictional-cohesive) or bonded */
    int first_slip;                 /* 0/1: cohesion lost at first slip (1) or at separation (0) */
    cdem_granular_law granular_law; /* how C0 enters the shear strength */
    cdem_cohesive_contacts cohesive_contacts; /* which contacts carry C0 */
    double settling_friction;      /* friction multiplier during equilibration (packing), 0-1 */
    cdem_contact_material element; /* element-element contacts */
    cdem_contact_material wall;    /* element-wall contacts (lateral walls, platens, the base) */
    cdem_contact_material base;    /* element-base contacts; NaN = the wall value (word "wall") */
    cdem_contact_material fault;   /* element-fault contacts */
    /* the laws' own coefficients (their files' part CDEM_PARAM_FIELDS) */
#define CDEM_PARAM_FIELDS
#include "laws/laws.def"
#undef CDEM_PARAM_FIELDS

    /* [heterogeneity] */
    int flexural_slip; /* 0/1: contacts between different pre-growth layers have no strength */
    cdem_flexural_style flexural_slip_style; /* which contacts (layer contacts, weak layers) */
    cdem_weak_interval weak_interval;        /* off, lower or upper interval */
    double weak_thickness_percent;           /* % of assembly height in the interval, 0-100 */
    double weak_strength_percent;  /* % of material strength kept in the interval, 0-100 */
    double weak_density_percent;   /* % of density in the interval, 50-100 */
    int layered_friction;          /* 0/1: layers 5-8, 13-16, 21-24 take layered_friction_value */
    double layered_friction_value; /* friction coefficient of those layers, >= 0 */

    /* [boundary] */
    cdem_mode mode; /* faulting / boundary mode */
    /* the modes' own keys (their files' part CDEM_PARAM_FIELDS, common/modes/) */
#define CDEM_PARAM_FIELDS
#include "modes.def"
#undef CDEM_PARAM_FIELDS
    double window_start; /* m of the run's boundary displacement before the actor moves, >= 0 */
    double window_stop;  /* m of it at which the actor stops; 0: the end of the run */

    /* [boundary.N], N = 2..boundary_actors: the actors after the first, each the lines
     * "key = value" of the [boundary] keys its section sets (cdem_params_actor: the others are
     * [boundary]'s, start and stop their defaults) */
    int boundary_actors; /* actors in all ([boundary] counts): 1 (0 reads as 1) to 8 */
    char actor_keys[CDEM_BOUNDARY_ACTORS - 1][CDEM_ACTOR_TEXT];

    /* [surface] */
    double overburden_pressure;         /* N/m on the top surface; 0 = off */
    int erosion;                        /* 0/1 */
    double erosion_base_level;          /* multiple of assembly height, 1.0-10.0 */
    int sedimentation;                  /* 0/1: syn-tectonic growth strata */
    cdem_sea_level_rise sea_level_rise; /* null, low, mid, high, very-high */
    int growth_sequence1_layers;        /* growth layers in growth sequence 1, >= 1 */

    /* the processes' sections (their files' part CDEM_PARAM_FIELDS, common/processes/) */
#define CDEM_PARAM_FIELDS
#include "processes.def"
#undef CDEM_PARAM_FIELDS

    /* [output] */
    char prefix[64];         /* prefix for per-increment exports (cdem282.txt) */
    double total_strain_max; /* colour-bar maximum for total strain, 0.1-5.0 */
    int series_interval;     /* time steps between time-series samples, >= 1 */
    int checkpoint_interval; /* display increments between checkpoints (resume), 0 = off */
} cdem_params;

typedef enum {
    CDEM_PTYPE_DOUBLE, /* with choices: also accepts choices[0], stored as NaN */
    CDEM_PTYPE_INT,
    CDEM_PTYPE_LONG,
    CDEM_PTYPE_BOOL,   /* stored as int 0/1; accepts true/false, yes/no, on/off, 1/0 */
    CDEM_PTYPE_ENUM,   /* stored as int; the words are in choices, in enum order */
    CDEM_PTYPE_STRING, /* stored as char[size] */
} cdem_param_type;

typedef struct {
    const char *section;        /* INI section, e.g. "assembly" */
    const char *key;            /* key within the section, e.g. "width" */
    cdem_param_type type;       /* how the value is parsed and stored */
    size_t offset;              /* offsetof(cdem_params, field) */
    size_t size;                /* STRING: buffer size; otherwise unused (0) */
    const char *unit;           /* "m", "s", "N/m", "" for none */
    const char *def;            /* default, as it would be written in a file */
    double min, max;            /* inclusive numeric range (DOUBLE/INT/LONG) */
    int min_exclusive;          /* 1: value must be > min */
    int max_exclusive;          /* 1: value must be < max */
    const char *const *choices; /* ENUM: NULL-terminated words */
    const char *help;           /* one line */
    int recorded_when_set;      /* 1: a run file's parameter record holds it only when it
                                   differs from its default (keys added since, so that the
                                   records of runs that leave them alone stay as they were) */
    int fixture;                /* 1: a key of a tests' fixture (a CDEM_TEST_MODE's, ...): it
                                   parses and is recorded when set (as recorded_when_set),
                                   but --print-defaults, docs/parameters.md, the man page
                                   and the completion do not list it */
} cdem_param_def;

/* The table, in file order. */
const cdem_param_def *cdem_params_table(size_t *count);

/* Finds a row by "section.key"; NULL if unknown. */
const cdem_param_def *cdem_params_find(const char *section, const char *key);

/* Fills p with every default. */
void cdem_params_defaults(cdem_params *p);

/* Parses an INI text (already read into memory) over p (start from defaults). path is used
 * only in messages. Reports the first syntax/type/range error of a single value; unknown
 * keys are errors with the closest valid name suggested. */
cdem_status cdem_params_parse_text(cdem_params *p, const char *text, const char *path,
                                   cdem_error *err);

/* Reads and parses a file; also returns its full text in *text_out (malloc'd, caller frees)
 * when text_out is not NULL. */
cdem_status cdem_params_load(cdem_params *p, const char *path, char **text_out, cdem_error *err);

/* Applies one "section.key=value" override (from -s on the command line). */
cdem_status cdem_params_override(cdem_params *p, const char *assignment, cdem_error *err);

/* The violated cross-parameter rules of one validation, one line each of one message. */
typedef struct {
    char *buf;  /* destination (err->msg or a scratch buffer) */
    size_t cap; /* its size */
    size_t len; /* characters written */
    int count;  /* rules violated so far */
} cdem_rule_log;

/* Adds one violated rule (printf format) as a line of the log. */
void cdem_rule_add(cdem_rule_log *log, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* A caller's own rules, added after the table's to the same log. */
typedef void (*cdem_params_rules)(const cdem_params *p, cdem_rule_log *log);

/* Checks every value against its row (CDEM_ERR_RANGE, all such values named at once), then
 * the rules between parameters (equilibration < runtime, the heterogeneity and surface
 * exclusions, ...) and, when more is not NULL, the caller's (cdem-run's: the mode's and the
 * growth strata's, solver/run/validate.c). Every violated rule is reported at once, one per
 * line, in err->msg (CDEM_ERR_CONFLICT). */
cdem_status cdem_params_validate(const cdem_params *p, cdem_params_rules more, cdem_error *err);

/* "a, b or c" from words[0..n) into buf (cut at cap). */
void cdem_words_or(const char *const *words, size_t n, char *buf, size_t cap);

/* The words of an enum parameter (section.key), as cdem_words_or lists them. */
void cdem_params_join_choices(const char *section, const char *key, char *buf, size_t cap);

/* Formats a number so that strtod gives back exactly the same value, as short as possible
 * (whole numbers up to 7 digits without exponent): the values quoted in messages. */
void cdem_params_format_number(double v, char *buf, size_t n);

/* Formats a parameter's current value as it would be written in a file. */
void cdem_params_format_value(const cdem_params *p, const cdem_param_def *def, char *buf, size_t n);

/* Writes a complete, commented parameter file with the values of p. */
void cdem_params_write(const cdem_params *p, FILE *out);
/* As cdem_params_write, for a run file's parameter record: the keys recorded only when set
 * (cdem_param_def.recorded_when_set) are left out at their default. The text reads back to
 * the same values. */
void cdem_params_write_record(const cdem_params *p, FILE *out);
/* 0 when the record leaves the key out (recorded_when_set and at its default), else 1. */
int cdem_params_recorded(const cdem_params *p, const cdem_param_def *d);

/* Sets boundary actor n's keys (2 <= n <= CDEM_BOUNDARY_ACTORS, actors 2..n-1 set first) from
 * their "key = value" lines, as its [boundary.N] section would (a file's record of them);
 * `where` names the source in messages. */
cdem_status cdem_params_set_actor_keys(cdem_params *p, int n, const char *lines, const char *where,
                                       cdem_error *err);

/* The number of boundary actors: 1 + the [boundary.N] sections. */
int cdem_params_actor_count(const cdem_params *p);
/* The parameters boundary actor j (0-based; 0 is [boundary]) runs with: p's, with
 * [boundary.(j+1)]'s keys over [boundary]'s, start and stop from its own section only (their
 * defaults otherwise); out holds one actor. CDEM_ERR_RANGE for a j that is no actor of p. */
cdem_status cdem_params_actor(const cdem_params *p, int j, cdem_params *out, cdem_error *err);

/* Writes the parameter table as a markdown table (section, key, type, default, unit,
 * range/values, help) for docs/parameters.md. Added for `cdem-run --params-markdown`. */
void cdem_params_write_markdown(FILE *out);

/* The registries' tables for docs/solver.md, from their rows' descriptions: the granular
 * laws a parameter file can name (`cdem-run --laws-markdown`) and the boundary modes
 * (`--modes-markdown`); the tests' fixtures are not listed. */
void cdem_params_write_laws_markdown(FILE *out);
void cdem_params_write_modes_markdown(FILE *out);

/* The element-base material in force: material.base_* where set, the wall's value where a
 * base key is the word "wall" (stored as NaN). Returns 1 when any base key has a value of its
 * own, 0 when the base is the wall throughout. */
int cdem_params_base_material(const cdem_params *p, cdem_contact_material *base);

/* A mode's word (a test fixture's too), from its row; "unknown" for a value that is none. */
const char *cdem_mode_name(cdem_mode mode);
/* What an increment of a mode's run is measured by, from its row (a value that is no mode:
 * the displacement). */
cdem_mode_clock cdem_mode_clock_of(cdem_mode mode);
/* A mode's one-line description, from its row; "?" for a value that is no mode. */
const char *cdem_mode_description(cdem_mode mode);

/* A law's word (a test fixture's too) and its one-line description, from its row; "?" for
 * a value that is no law. */
const char *cdem_law_name(cdem_granular_law law);
const char *cdem_law_description(cdem_granular_law law);

/* A file-name prefix of per-increment files (output.prefix, export-sspx and render
 * --prefix): letters, digits, '_', '-' and '.', 1 to 64 of them, not starting with '.' or
 * '-': a name inside the folder the files go to, never a path out of it. 1 when prefix is
 * one; CDEM_PREFIX_RULE says the rule in messages. */
int cdem_params_prefix_ok(const char *prefix);
#define CDEM_PREFIX_RULE                                                                           \
    "must be a file-name prefix: 1 to 64 letters, digits, '_', '-' or '.', not starting with "     \
    "'.' or '-' (e.g. cdem)"

/* The radii's multiple of 0.05..0.125 units that p asks for: radius_scale, halved by
 * half_radii (cdem's option; the two together are refused by cdem_params_validate). */
double cdem_params_radius_scale(const cdem_params *p);

#endif
