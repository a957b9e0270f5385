/* params: the parameter table, the INI parser, overrides, validation and the writers.
 *
 * One static const table (param_table) describes every field of cdem_params; everything
 * else in this file is a loop over it. Defaults are stored as the text a user would write
 * and are parsed by the same code as a file, so a default can never escape its own range
 * check. The INI parser is hand-written (not libinih) because every message must carry the
 * exact line number and the offending text, and because overrides (-s section.key=value)
 * must go through the same assignment code as file lines.
 * Key names are the field names of cdem_params; nested contact materials are flattened
 * with an underscore (element.friction -> [material] element_friction).
 * Nothing here allocates except cdem_params_load (the file text).
 * The laws' and the modes' words come from their registries (laws/laws.def, modes.def); a
 * mode's rules are the mode's (solver/modes/), this file keeps the rules of no mode.
 * Why one file of ~1100 lines: the table, its choice lists and the cross-field validation
 * rules are most of it, and the parser, the overrides and the writers are loops over the
 * table that must see its private layout (offsets, text defaults); splitting them would
 * export the table to every caller instead of keeping "one table, one owner". */
#include "params.h"

#include "file_bounds.h"
#include "suggest.h"

#include <assert.h>
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#define P_OFF(field) offsetof(cdem_params, field)

/* Upper bound used for "no upper limit" rows; printed as "no upper limit". */
#define NOMAX HUGE_VAL

static const char *const material_words[] = {"granular", "bonded", NULL};
/* The laws' words, in enum order (the users' laws: a fixture of the tests has no word a
 * file could use), and every law's row text. */
static const char *const law_words[] = {
#define CDEM_LAW(ID, word, description, scalar, lanes) word,
#include "laws/laws.def"
#undef CDEM_LAW
    NULL};
_Static_assert(sizeof law_words / sizeof law_words[0] == CDEM_LAW_WORDS + 1,
               "one word per law of parameter files (laws.def)");
static const struct {
    const char *word, *description;
} law_rows[CDEM_LAW_COUNT] = {
#define CDEM_LAW(ID, word, description, scalar, lanes) [CDEM_LAW_##ID] = {word, description},
#define CDEM_TEST_LAW                                  CDEM_LAW
#include "laws/laws.def"
#undef CDEM_LAW
#undef CDEM_TEST_LAW
};
static const char *const cohesive_words[] = {"equilibrated", "formed", "initial", NULL};
/* A real parameter whose row has choices accepts its one word instead of a number, stored as
 * NaN: "take the value of another parameter" (the base takes the lateral walls' values). */
static const char *const as_wall_words[] = {"wall", NULL};
/* The modes' words, in enum order (the users' modes), and every mode's word. */
static const char *const mode_words[] = {
#define CDEM_MODE(ID, id, word, clock, description) word,
#include "modes.def"
#undef CDEM_MODE
    NULL};
_Static_assert(sizeof mode_words / sizeof mode_words[0] == CDEM_MODE_WORDS + 1,
               "one word per mode of parameter files (modes.def)");
static const struct {
    const char *word, *description;
    cdem_mode_clock clock;
} mode_rows[CDEM_MODE_COUNT] = {
#define CDEM_MODE(ID, id, word, clock, description) [CDEM_MODE_##ID] = {word, description, clock},
#define CDEM_TEST_MODE                              CDEM_MODE
#include "modes.def"
#undef CDEM_MODE
#undef CDEM_TEST_MODE
};
static const char *const walls_words[] = {"right", "both", NULL};
static const char *const weak_words[] = {"off", "lower", "upper", NULL};
static const char *const flex_words[] = {"layer-contacts", "weak-layers", NULL};
static const char *const sea_words[] = {"null", "low", "mid", "high", "very-high", NULL};
static const char *const damping_words[] = {"absolute", "contact", NULL};
/* The words of the laws', the modes' and the processes' own enum keys (params.h). */
#define CDEM_PARAM_WORDS
#include "laws/laws.def"
#include "modes.def"
#include "processes.def"
#undef CDEM_PARAM_WORDS

/* Boolean spellings: bool_true_words[i] and bool_false_words[i] are a pair. */
static const char *const bool_true_words[] = {"true", "yes", "on", "1", NULL};
static const char *const bool_false_words[] = {"false", "no", "off", "0", NULL};

/* Sections in file order. */
/* Sections in file order: a process's own section comes before [output]. */
static const char *const section_names[] = {"assembly",      "time",     "physics", "material",
                                            "heterogeneity", "boundary", "surface",
#define CDEM_PARAM_SECTIONS
#include "processes.def"
#undef CDEM_PARAM_SECTIONS
                                            "output",        NULL};

/* clang-format off */
static const cdem_param_def param_table[] = {
    /* section, key, type, offset, size, unit, default, min, max, min_excl, max_excl, choices, help,
       recorded_when_set, fixture */
    {"assembly", "width", CDEM_PTYPE_DOUBLE, P_OFF(width), 0, "units", "10", 0, 1e6, 1, 0, NULL,
     "assembly width in model units (cdem's box: 10 to 100; beyond it, bounded by the memory the run needs, at least 8 largest diameters)", 0, 0},
    {"assembly", "height", CDEM_PTYPE_DOUBLE, P_OFF(height), 0, "units", "5", 0, 1e6, 1, 0, NULL,
     "assembly height in model units (cdem's box: 2.5 to 7.5; beyond it, bounded by the memory the run needs, at least 8 largest diameters)", 0, 0},
    {"assembly", "unit_scaling", CDEM_PTYPE_DOUBLE, P_OFF(unit_scaling), 0, "m", "1000", 1, 1e6, 0, 0, NULL,
     "length of one model unit (cdem: 100 to 1000; the contact constants scale with the radius below 1000 m, docs/solver.md)", 0, 0},
    {"assembly", "half_radii", CDEM_PTYPE_BOOL, P_OFF(half_radii), 0, "", "off", 0, 1, 0, 0, NULL,
     "use radii 0.025-0.0625 units instead of 0.05-0.125 (4x the elements, half the time step); radius_scale = 0.5 is the same", 0, 0},
    {"assembly", "radius_scale", CDEM_PTYPE_DOUBLE, P_OFF(radius_scale), 0, "", "1", 0.001, 1000, 0, 0, NULL,
     "the four element radii 0.05, 0.075, 0.1, 0.125 units times this (the paper's distribution kept): 0.5 is cdem's half radii, 0.1 cdem2D's finer assemblies; elements per area grow as 1/radius_scale^2, the time step shrinks with radius_scale", 0, 0},
    {"assembly", "wall_height_multiplier", CDEM_PTYPE_INT, P_OFF(wall_height_multiplier), 0, "", "1", 1, 4, 0, 0, NULL,
     "lateral wall height as a multiple of the assembly height", 0, 0},
    {"assembly", "base_spacing", CDEM_PTYPE_DOUBLE, P_OFF(base_spacing), 0, "wall radii", "2", 1, 2, 0, 0, NULL,
     "centre spacing of the base wall's discs in wall radii: 2 touching (a rough base, which resists sliding even without friction), 1 overlapping (a nearly smooth base); the biaxial test's platens are always smooth (1)", 0, 0},
    {"assembly", "seed", CDEM_PTYPE_LONG, P_OFF(seed), 0, "", "1", 0, 2147483647.0, 0, 0, NULL,
     "random seed of the packing and of all other randomness", 0, 0},

    {"time", "runtime", CDEM_PTYPE_DOUBLE, P_OFF(runtime), 0, "s", "2000", 100, 1e6, 0, 0, NULL,
     "total simulated time (simulation time, not geological time)", 0, 0},
    {"time", "equilibration", CDEM_PTYPE_DOUBLE, P_OFF(equilibration), 0, "s", "400", 100, 1e6, 0, 0, NULL,
     "equilibration time before any boundary moves; must be shorter than runtime", 0, 0},
    {"time", "display_interval", CDEM_PTYPE_DOUBLE, P_OFF(display_interval), 0, "m", "5", 0.1, 1000, 0, 0, NULL,
     "boundary displacement between display increments (seconds for mode = repose)", 0, 0},

    {"physics", "gravity", CDEM_PTYPE_DOUBLE, P_OFF(gravity), 0, "m/s^2", "9.81", 0.5, 25, 0, 0, NULL,
     "gravitational acceleration (not applied in the biaxial test)", 0, 0},
    {"physics", "density", CDEM_PTYPE_DOUBLE, P_OFF(density), 0, "kg/m^3", "2500", 1500, 3500, 0, 0, NULL,
     "element density", 0, 0},
    {"physics", "keep_constants", CDEM_PTYPE_BOOL, P_OFF(keep_constants), 0, "", "off", 0, 1, 0, 0, NULL,
     "keep the 1000 m spring and damping constants whatever the unit scaling", 0, 0},
    {"physics", "deformation_damping", CDEM_PTYPE_DOUBLE, P_OFF(deformation_damping), 0, "", "1", 0, 1, 0, 0, NULL,
     "multiplier of the viscous damping on deformation steps (1 = the paper's; equilibration and sediment settling keep it whole)", 0, 0},
    {"physics", "calculate_stress", CDEM_PTYPE_BOOL, P_OFF(calculate_stress), 0, "", "off", 0, 1, 0, 0, NULL,
     "store per-element stress in every increment", 0, 0},
    {"physics", "damping_mode", CDEM_PTYPE_ENUM, P_OFF(damping_mode), 0, "", "absolute", 0, 0, 0, 0, damping_words,
     "absolute: the paper's drag on each free element's velocity (the calibration of Figs. 4-6); contact: a normal dashpot on each contact instead, which damps relative motion only (required by a viscous substrate process)", 0, 0},
    {"physics", "contact_damping", CDEM_PTYPE_DOUBLE, P_OFF(contact_damping), 0, "", "0.2", 0, 1, 0, 0, NULL,
     "damping_mode = contact: each contact's dashpot as a fraction of its critical damping 2 sqrt(Kn m_i m_j / (m_i + m_j))", 0, 0},

    {"material", "material", CDEM_PTYPE_ENUM, P_OFF(material), 0, "", "granular", 0, 0, 0, 0, material_words,
     "granular (frictional-cohesive) or bonded (elastic bonds with a breaking strain)", 0, 0},
    {"material", "first_slip", CDEM_PTYPE_BOOL, P_OFF(first_slip), 0, "", "on", 0, 1, 0, 0, NULL,
     "granular: cohesion lost at the first slip (on) or when the pair separates (off)", 0, 0},
    {"material", "granular_law", CDEM_PTYPE_ENUM, P_OFF(granular_law), 0, "", "normal-cohesion", 0, 0, 0, 0, law_words,
     "granular: how the cohesion C0 enters a contact's shear strength"
#define CDEM_LAW(ID, word, description, scalar, lanes) "; " word ": " description
#include "laws/laws.def"
#undef CDEM_LAW
     , 0, 0},
    {"material", "cohesive_contacts", CDEM_PTYPE_ENUM, P_OFF(cohesive_contacts), 0, "", "initial", 0, 0, 0, 0, cohesive_words,
     "granular: C0 on the contacts of the end of equilibration (equilibrated), also on every contact formed later (formed), or only on those that were contacts of the built assembly and never separated (initial)", 0, 0},
    {"material", "settling_friction", CDEM_PTYPE_DOUBLE, P_OFF(settling_friction), 0, "", "0", 0, 1, 0, 0, NULL,
     "granular: friction multiplier during equilibration (0: a dense, frictionless settling); the full friction acts from deformation on", 0, 0},
    {"material", "element_friction", CDEM_PTYPE_DOUBLE, P_OFF(element.friction), 0, "", "0.25", 0, 10, 0, 0, NULL,
     "element-element friction coefficient", 0, 0},
    {"material", "element_cohesion", CDEM_PTYPE_DOUBLE, P_OFF(element.cohesion), 0, "N", "5e9", 0, 1e15, 0, 0, NULL,
     "element-element cohesion force", 0, 0},
    {"material", "element_breaking_strain", CDEM_PTYPE_DOUBLE, P_OFF(element.breaking_strain), 0, "", "0.02", 0, 1, 1, 0, NULL,
     "bonded: element-element bond breaks when r - R >= breaking_strain * R", 0, 0},
    {"material", "wall_friction", CDEM_PTYPE_DOUBLE, P_OFF(wall.friction), 0, "", "0.25", 0, 10, 0, 0, NULL,
     "element-wall friction coefficient (lateral walls, biaxial platens; the base too unless base_friction is set)", 0, 0},
    {"material", "wall_cohesion", CDEM_PTYPE_DOUBLE, P_OFF(wall.cohesion), 0, "N", "5e9", 0, 1e15, 0, 0, NULL,
     "element-wall cohesion force", 0, 0},
    {"material", "wall_breaking_strain", CDEM_PTYPE_DOUBLE, P_OFF(wall.breaking_strain), 0, "", "0.02", 0, 1, 1, 0, NULL,
     "bonded: element-wall breaking strain", 0, 0},
    {"material", "base_friction", CDEM_PTYPE_DOUBLE, P_OFF(base.friction), 0, "", "wall", 0, 10, 0, 0, as_wall_words,
     "element-base friction coefficient (the base row; biaxial: the bottom platen); wall = wall_friction", 0, 0},
    {"material", "base_cohesion", CDEM_PTYPE_DOUBLE, P_OFF(base.cohesion), 0, "N", "wall", 0, 1e15, 0, 0, as_wall_words,
     "element-base cohesion force; wall = wall_cohesion", 0, 0},
    {"material", "base_breaking_strain", CDEM_PTYPE_DOUBLE, P_OFF(base.breaking_strain), 0, "", "wall", 0, 1, 1, 0, as_wall_words,
     "bonded: element-base breaking strain; wall = wall_breaking_strain", 0, 0},
    {"material", "fault_friction", CDEM_PTYPE_DOUBLE, P_OFF(fault.friction), 0, "", "0.25", 0, 10, 0, 0, NULL,
     "element-fault friction coefficient (set 0 for CH kinematics)", 0, 0},
    {"material", "fault_cohesion", CDEM_PTYPE_DOUBLE, P_OFF(fault.cohesion), 0, "N", "5e9", 0, 1e15, 0, 0, NULL,
     "element-fault cohesion force (set 0 for CH kinematics)", 0, 0},
    {"material", "fault_breaking_strain", CDEM_PTYPE_DOUBLE, P_OFF(fault.breaking_strain), 0, "", "0.02", 0, 1, 1, 0, NULL,
     "bonded: element-fault breaking strain", 0, 0},
    /* the laws' own coefficients, in laws.def's order */
#define CDEM_PARAM_ROWS
#include "laws/laws.def"
#undef CDEM_PARAM_ROWS

    {"heterogeneity", "flexural_slip", CDEM_PTYPE_BOOL, P_OFF(flexural_slip), 0, "", "off", 0, 1, 0, 0, NULL,
     "contacts between different pre-growth layers have no friction/cohesion (or no bond)", 0, 0},
    {"heterogeneity", "flexural_slip_style", CDEM_PTYPE_ENUM, P_OFF(flexural_slip_style), 0, "", "layer-contacts", 0, 0, 0, 0, flex_words,
     "which contacts flexural slip makes strengthless: every contact between two different pre-growth layers (layer-contacts, the manual's and the paper's), or every contact of an element of layers 4, 8, 12, 16 and 20 (weak-layers, the original's versions 4.1-4.2)", 0, 0},
    {"heterogeneity", "weak_interval", CDEM_PTYPE_ENUM, P_OFF(weak_interval), 0, "", "off", 0, 0, 0, 0, weak_words,
     "weak and/or light interval at the bottom (lower) or top (upper) of the assembly", 0, 0},
    {"heterogeneity", "weak_thickness_percent", CDEM_PTYPE_DOUBLE, P_OFF(weak_thickness_percent), 0, "%", "50", 0, 100, 0, 0, NULL,
     "thickness of the weak interval, % of the assembly height", 0, 0},
    {"heterogeneity", "weak_strength_percent", CDEM_PTYPE_DOUBLE, P_OFF(weak_strength_percent), 0, "%", "0", 0, 100, 0, 0, NULL,
     "strength kept in the weak interval, % of the material values (0 = frictionless/unbonded)", 0, 0},
    {"heterogeneity", "weak_density_percent", CDEM_PTYPE_DOUBLE, P_OFF(weak_density_percent), 0, "%", "100", 50, 100, 0, 0, NULL,
     "density of the weak interval, % of the density", 0, 0},
    {"heterogeneity", "layered_friction", CDEM_PTYPE_BOOL, P_OFF(layered_friction), 0, "", "off", 0, 1, 0, 0, NULL,
     "layers 5-8, 13-16 and 21-24 take layered_friction_value (granular only)", 0, 0},
    {"heterogeneity", "layered_friction_value", CDEM_PTYPE_DOUBLE, P_OFF(layered_friction_value), 0, "", "0.1", 0, 10, 0, 0, NULL,
     "friction coefficient of layers 5-8, 13-16 and 21-24", 0, 0},

    {"boundary", "mode", CDEM_PTYPE_ENUM, P_OFF(mode), 0, "", "planar-fault", 0, 0, 0, 0, mode_words,
     "boundary / faulting mode", 0, 0},
    /* the modes' own keys, in modes.def's order */
#define CDEM_PARAM_ROWS
#include "modes.def"
#undef CDEM_PARAM_ROWS
    {"boundary", "start", CDEM_PTYPE_DOUBLE, P_OFF(window_start), 0, "m", "0", 0, 1e9, 0, 0, NULL,
     "the run's boundary displacement (the display interval's clock) before this boundary moves", 1, 0},
    {"boundary", "stop", CDEM_PTYPE_DOUBLE, P_OFF(window_stop), 0, "m", "0", 0, 1e9, 0, 0, NULL,
     "the run's boundary displacement at which this boundary stops (0 = the end of the run)", 1, 0},

    {"surface", "overburden_pressure", CDEM_PTYPE_DOUBLE, P_OFF(overburden_pressure), 0, "N/m", "0", 0, 1e9, 0, 0, NULL,
     "vertical pressure on the top surface (0 = off)", 0, 0},
    {"surface", "erosion", CDEM_PTYPE_BOOL, P_OFF(erosion), 0, "", "off", 0, 1, 0, 0, NULL,
     "remove elements above the erosion base level", 0, 0},
    {"surface", "erosion_base_level", CDEM_PTYPE_DOUBLE, P_OFF(erosion_base_level), 0, "", "1", 1, 10, 0, 0, NULL,
     "erosion base level, multiple of the assembly height", 0, 0},
    {"surface", "sedimentation", CDEM_PTYPE_BOOL, P_OFF(sedimentation), 0, "", "off", 0, 1, 0, 0, NULL,
     "syn-tectonic sedimentation below sea level (growth strata)", 0, 0},
    {"surface", "sea_level_rise", CDEM_PTYPE_ENUM, P_OFF(sea_level_rise), 0, "", "null", 0, 0, 0, 0, sea_words,
     "sea-level rise per boundary displacement: factor 0, 0.25, 0.5, 0.75, 1.0", 0, 0},
    {"surface", "growth_sequence1_layers", CDEM_PTYPE_INT, P_OFF(growth_sequence1_layers), 0, "", "10", 1, 1000, 0, 0, NULL,
     "growth layers coloured as growth sequence 1 (the rest are sequence 2)", 0, 0},

    /* the processes' own sections, in processes.def's order */
#define CDEM_PARAM_ROWS
#include "processes.def"
#undef CDEM_PARAM_ROWS

    {"output", "prefix", CDEM_PTYPE_STRING, P_OFF(prefix), sizeof(((cdem_params *)0)->prefix), "", "cdem", 0, 0, 0, 0, NULL,
     "prefix of per-increment export files (cdem282.txt)", 0, 0},
    {"output", "total_strain_max", CDEM_PTYPE_DOUBLE, P_OFF(total_strain_max), 0, "", "2", 0.1, 5, 0, 0, NULL,
     "colour-bar maximum for total strain", 0, 0},
    {"output", "series_interval", CDEM_PTYPE_INT, P_OFF(series_interval), 0, "steps", "100", 1, 1000000, 0, 0, NULL,
     "time steps between time-series samples", 0, 0},
    {"output", "checkpoint_interval", CDEM_PTYPE_INT, P_OFF(checkpoint_interval), 0, "increments", "10", 0, 1000000, 0, 0, NULL,
     "display increments between checkpoints that cdem-run --resume continues from (0 = none)", 0, 0},
};
/* clang-format on */

#define N_PARAMS (sizeof param_table / sizeof param_table[0])

const cdem_param_def *cdem_params_table(size_t *count) {
    if (count)
        *count = N_PARAMS;
    return param_table;
}

const cdem_param_def *cdem_params_find(const char *section, const char *key) {
    if (!section || !key)
        return NULL;
    for (size_t i = 0; i < N_PARAMS; i++)
        if (strcmp(param_table[i].section, section) == 0 && strcmp(param_table[i].key, key) == 0)
            return &param_table[i];
    return NULL;
}

const char *cdem_law_name(cdem_granular_law law) {
    return (int)law >= 0 && law < CDEM_LAW_COUNT ? law_rows[law].word : "?";
}

const char *cdem_law_description(cdem_granular_law law) {
    return (int)law >= 0 && law < CDEM_LAW_COUNT ? law_rows[law].description : "?";
}

const char *cdem_mode_name(cdem_mode mode) {
    return (int)mode >= 0 && mode < CDEM_MODE_COUNT ? mode_rows[mode].word : "unknown";
}

cdem_mode_clock cdem_mode_clock_of(cdem_mode mode) {
    return (int)mode >= 0 && mode < CDEM_MODE_COUNT ? mode_rows[mode].clock
                                                    : CDEM_CLOCK_DISPLACEMENT;
}

const char *cdem_mode_description(cdem_mode mode) {
    return (int)mode >= 0 && mode < CDEM_MODE_COUNT ? mode_rows[mode].description : "?";
}

int cdem_params_base_material(const cdem_params *p, cdem_contact_material *base) {
    *base = p->base;
    const int own =
        !(isnan(base->friction) && isnan(base->cohesion) && isnan(base->breaking_strain));
    if (isnan(base->friction))
        base->friction = p->wall.friction;
    if (isnan(base->cohesion))
        base->cohesion = p->wall.cohesion;
    if (isnan(base->breaking_strain))
        base->breaking_strain = p->wall.breaking_strain;
    return own;
}

/* ---------- small text helpers ---------- */

static int is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Copies text[0..len) into buf (cut to n-1), trimming surrounding whitespace. */
static void copy_trimmed(char *buf, size_t n, const char *text, size_t len) {
    while (len > 0 && is_blank(*text)) {
        text++;
        len--;
    }
    while (len > 0 && is_blank(text[len - 1]))
        len--;
    if (len >= n)
        len = n - 1;
    memcpy(buf, text, len);
    buf[len] = '\0';
}

/* Appends "w1, w2, w3" to buf. */
static void join_words(const char *const *words, char *buf, size_t n) {
    size_t pos = 0;
    buf[0] = '\0';
    for (size_t i = 0; words[i] && pos < n; i++) {
        int w = snprintf(buf + pos, n - pos, "%s%s", i ? ", " : "", words[i]);
        if (w < 0)
            break;
        pos += (size_t)w;
    }
}

void cdem_words_or(const char *const *words, size_t n, char *buf, size_t cap) {
    size_t pos = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < n && pos < cap; i++) {
        const char *sep = i == 0 ? "" : i + 1 == n ? " or " : ", ";
        const int w = snprintf(buf + pos, cap - pos, "%s%s", sep, words[i]);
        if (w < 0)
            break;
        pos += (size_t)w;
    }
}

void cdem_params_join_choices(const char *section, const char *key, char *buf, size_t cap) {
    const cdem_param_def *d = cdem_params_find(section, key);
    size_t n = 0;
    while (d && d->choices && d->choices[n])
        n++;
    cdem_words_or(d ? d->choices : NULL, n, buf, cap);
}

void cdem_params_format_number(double v, char *buf, size_t n) {
    if (v == floor(v) && fabs(v) < 1e7) { /* whole numbers up to 7 digits: "2000", not "2e+03" */
        snprintf(buf, n, "%.0f", v);
        return;
    }
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(buf, n, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            return;
    }
}

/* Describes the allowed range: "between 0.5 and 25 m/s^2", "> 0 and <= 90 degrees",
 * ">= 100 s". */
static void describe_range(const cdem_param_def *d, char *buf, size_t n) {
    if (d->type == CDEM_PTYPE_DOUBLE && d->choices) {
        cdem_param_def plain = *d;
        plain.choices = NULL;
        char num[128];
        describe_range(&plain, num, sizeof num);
        snprintf(buf, n, "%s, or %s", num, d->choices[0]);
        return;
    }
    char lo[32], hi[32];
    cdem_params_format_number(d->min, lo, sizeof lo);
    cdem_params_format_number(d->max, hi, sizeof hi);
    const char *sp = d->unit[0] ? " " : "";
    if (d->max == NOMAX)
        snprintf(buf, n, "%s %s%s%s", d->min_exclusive ? ">" : ">=", lo, sp, d->unit);
    else if (!d->min_exclusive && !d->max_exclusive)
        snprintf(buf, n, "between %s and %s%s%s", lo, hi, sp, d->unit);
    else
        snprintf(buf, n, "%s %s and %s %s%s%s", d->min_exclusive ? ">" : ">=", lo,
                 d->max_exclusive ? "<" : "<=", hi, sp, d->unit);
}

/* Short "allowed values" text for comments and the markdown table. */
static void describe_allowed(const cdem_param_def *d, char *buf, size_t n) {
    if (d->type == CDEM_PTYPE_DOUBLE && d->choices) {
        cdem_param_def plain = *d;
        plain.choices = NULL;
        char num[128];
        describe_allowed(&plain, num, sizeof num);
        snprintf(buf, n, "%s, or %s", num, d->choices[0]);
        return;
    }
    switch (d->type) {
    case CDEM_PTYPE_BOOL:
        snprintf(buf, n, "on/off");
        break;
    case CDEM_PTYPE_ENUM:
        join_words(d->choices, buf, n);
        break;
    case CDEM_PTYPE_STRING:
        snprintf(buf, n, "text, at most %zu characters", d->size - 1);
        break;
    default: {
        char lo[32], hi[32];
        cdem_params_format_number(d->min, lo, sizeof lo);
        cdem_params_format_number(d->max, hi, sizeof hi);
        if (d->max == NOMAX)
            snprintf(buf, n, "%s %s", d->min_exclusive ? ">" : ">=", lo);
        else if (!d->min_exclusive && !d->max_exclusive)
            snprintf(buf, n, "%s to %s", lo, hi);
        else
            snprintf(buf, n, "%s %s and %s %s", d->min_exclusive ? ">" : ">=", lo,
                     d->max_exclusive ? "<" : "<=", hi);
    }
    }
}

static int in_range(const cdem_param_def *d, double v) {
    if (!isfinite(v))
        return 0;
    if (d->min_exclusive ? !(v > d->min) : !(v >= d->min))
        return 0;
    if (d->max != NOMAX && (d->max_exclusive ? !(v < d->max) : !(v <= d->max)))
        return 0;
    return 1;
}

static const char *type_noun(cdem_param_type t) {
    switch (t) {
    case CDEM_PTYPE_INT:
    case CDEM_PTYPE_LONG:
        return "a whole number";
    default:
        return "a number";
    }
}

/* ---------- assignment: the one path for file lines, defaults and overrides ---------- */

/* 1 when v is a plain decimal number ([+-]digits[.digits][e[+-]digits]). strtod also reads
 * hexadecimal ("0x10" is 16), "infinity" and "nan", which a parameter file never means: a
 * hex value would be taken silently for another number. */
static int decimal_text(const char *v) {
    const char *p = v;
    if (*p == '+' || *p == '-')
        p++;
    int digits = 0;
    while (isdigit((unsigned char)*p))
        p++, digits++;
    if (*p == '.')
        for (p++; isdigit((unsigned char)*p); p++)
            digits++;
    if (digits == 0)
        return 0;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!isdigit((unsigned char)*p))
            return 0;
        while (isdigit((unsigned char)*p))
            p++;
    }
    return *p == '\0';
}

/* Sets one parameter from its value text. where = "model.ini:12" or "-s a.b=c"; the message
 * reads "<where>: <key> = <value>: <problem>". */
static cdem_status assign_value(cdem_params *p, const cdem_param_def *d, const char *value,
                                const char *where, cdem_error *err) {
    char *field = (char *)p + d->offset;
    switch (d->type) {
    case CDEM_PTYPE_DOUBLE:
    case CDEM_PTYPE_INT:
    case CDEM_PTYPE_LONG: {
        char range[160];
        describe_range(d, range, sizeof range);
        if (value[0] == '\0')
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: %s = : missing value; expected %s %s", where,
                             d->key, type_noun(d->type), range);
        if (d->type == CDEM_PTYPE_DOUBLE && d->choices && strcasecmp(value, d->choices[0]) == 0) {
            const double inherit = NAN;
            memcpy(field, &inherit, sizeof inherit);
            return CDEM_OK;
        }
        char *end = NULL;
        errno = 0;
        double v = 0.0;
        if (d->type == CDEM_PTYPE_DOUBLE) {
            v = strtod(value, &end);
            if (!decimal_text(value))
                end = (char *)value; /* refused below as "not a number" */
        } else {
            long long iv = strtoll(value, &end, 10);
            v = (double)iv;
        }
        if (end == value || *end != '\0' || (d->type == CDEM_PTYPE_DOUBLE && !isfinite(v)))
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: %s = %s: not %s; expected %s %s", where,
                             d->key, value, type_noun(d->type), type_noun(d->type), range);
        if (errno == ERANGE || !in_range(d, v))
            return CDEM_FAIL(err, CDEM_ERR_RANGE, "%s: %s = %s: must be %s", where, d->key, value,
                             range);
        if (d->type == CDEM_PTYPE_DOUBLE)
            memcpy(field, &v, sizeof v);
        else if (d->type == CDEM_PTYPE_INT) {
            int iv = (int)v;
            memcpy(field, &iv, sizeof iv);
        } else {
            long lv = (long)v;
            memcpy(field, &lv, sizeof lv);
        }
        return CDEM_OK;
    }
    case CDEM_PTYPE_BOOL: {
        int b = -1;
        for (size_t i = 0; bool_true_words[i]; i++) {
            if (strcasecmp(value, bool_true_words[i]) == 0)
                b = 1;
            if (strcasecmp(value, bool_false_words[i]) == 0)
                b = 0;
        }
        if (b < 0)
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "%s: %s = %s: must be one of true, false, yes, no, on, off, 1, 0",
                             where, d->key, value);
        memcpy(field, &b, sizeof b);
        return CDEM_OK;
    }
    case CDEM_PTYPE_ENUM: {
        for (int i = 0; d->choices[i]; i++) {
            if (strcasecmp(value, d->choices[i]) == 0) {
                memcpy(field, &i, sizeof i);
                return CDEM_OK;
            }
        }
        char words[256];
        join_words(d->choices, words, sizeof words);
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "%s: %s = %s: must be one of %s", where, d->key,
                         value, words);
    }
    case CDEM_PTYPE_STRING: {
        size_t len = strlen(value);
        if (len >= d->size)
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "%s: %s = %.40s...: too long (%zu characters; at most %zu)", where,
                             d->key, value, len, d->size - 1);
        /* A '"' inside the value or a control character could not be written back into a
         * parameter file (cdem_params_write) and read the same (found by fuzzing). */
        for (size_t i = 0; i < len; i++) {
            unsigned char c = (unsigned char)value[i];
            if (c == '"' || (c < 0x20 && c != '\t') || c == 0x7f)
                return CDEM_FAIL(err, CDEM_ERR_RANGE,
                                 "%s: %s: character %zu of the value is %s (byte 0x%02x): quotes "
                                 "inside a value and control characters are not allowed (quote "
                                 "the whole value to keep '#', ';' or spaces at its ends)",
                                 where, d->key, i + 1, c == '"' ? "a quote" : "a control character",
                                 (unsigned)c);
        }
        memcpy(field, value, len + 1);
        return CDEM_OK;
    }
    }
    return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: %s: unknown parameter type", where, d->key);
}

void cdem_params_defaults(cdem_params *p) {
    memset(p, 0, sizeof *p);
    for (size_t i = 0; i < N_PARAMS; i++) {
        cdem_status st = assign_value(p, &param_table[i], param_table[i].def, "defaults", NULL);
        assert(st == CDEM_OK && "a default in param_table violates its own range");
        (void)st;
    }
}

/* Reports an unknown key with the closest known name (or the section it belongs to). */
static cdem_status fail_unknown_key(const char *where, const char *section, const char *key,
                                    cdem_error *err) {
    for (size_t i = 0; i < N_PARAMS; i++)
        if (strcmp(param_table[i].key, key) == 0)
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: [%s] %s: unknown key; it belongs in [%s]",
                             where, section, key, param_table[i].section);
    const cdem_param_def *best = NULL;
    size_t best_d = (size_t)-1;
    /* Prefer keys of the same section on ties, so the suggestion stays local. */
    for (int pass = 0; pass < 2; pass++)
        for (size_t i = 0; i < N_PARAMS; i++) {
            int same = strcmp(param_table[i].section, section) == 0;
            if (same != (pass == 0))
                continue;
            size_t dist = cdem_edit_distance(key, param_table[i].key);
            if (dist < best_d) {
                best_d = dist;
                best = &param_table[i];
            }
        }
    if (best && cdem_suggest_close(best_d, key)) {
        if (strcmp(best->section, section) == 0)
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: [%s] %s: unknown key; did you mean '%s'?",
                             where, section, key, best->key);
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "%s: [%s] %s: unknown key; did you mean '%s' (it belongs in [%s])?", where,
                         section, key, best->key, best->section);
    }
    return CDEM_FAIL(err, CDEM_ERR_PARSE,
                     "%s: [%s] %s: unknown key; `cdem-run --print-defaults` lists every key", where,
                     section, key);
}

/* N of a section named [boundary.N] (a boundary actor's), 0 for another name, -1 for
 * "boundary." followed by anything but a number. */
static int actor_section(const char *name) {
    if (strncmp(name, "boundary.", 9) != 0)
        return 0;
    const char *d = name + 9;
    char *end = NULL;
    const long n = isdigit((unsigned char)*d) ? strtol(d, &end, 10) : -1;
    return (n < 0 || !end || *end) ? -1 : (n > 1000 ? 1000 : (int)n);
}

static int known_section(const char *name) {
    for (size_t i = 0; section_names[i]; i++)
        if (strcmp(section_names[i], name) == 0)
            return 1;
    return 0;
}

static cdem_status fail_unknown_section(const char *where, const char *name, cdem_error *err) {
    const size_t n = sizeof section_names / sizeof section_names[0] - 1;
    const char *best = cdem_suggest(name, section_names, n);
    if (best)
        return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: unknown section [%s]; did you mean [%s]?", where,
                         name, best);
    char words[256];
    join_words(section_names, words, sizeof words);
    return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: unknown section [%s]; sections are %s", where, name,
                     words);
}

/* Splits a value at an inline comment ('#' or ';' after whitespace) and handles a quoted
 * value ("..." may contain '#' and ';'). Writes the cleaned value into buf. Returns 0 when
 * a quote is not closed or text follows the closing quote. */
static int clean_value(const char *text, size_t len, char *buf, size_t n) {
    while (len > 0 && is_blank(*text)) {
        text++;
        len--;
    }
    if (len > 0 && text[0] == '"') {
        const char *close = memchr(text + 1, '"', len - 1);
        if (!close)
            return 0;
        size_t rest = len - (size_t)(close + 1 - text);
        const char *r = close + 1;
        while (rest > 0 && is_blank(*r)) {
            r++;
            rest--;
        }
        if (rest > 0 && *r != '#' && *r != ';')
            return 0;
        size_t vlen = (size_t)(close - text - 1);
        if (vlen >= n)
            vlen = n - 1;
        memcpy(buf, text + 1, vlen);
        buf[vlen] = '\0';
        return 1;
    }
    size_t cut = len;
    for (size_t i = 0; i < len; i++)
        if ((text[i] == '#' || text[i] == ';') && (i == 0 || is_blank(text[i - 1]))) {
            cut = i;
            break;
        }
    copy_trimmed(buf, n, text, cut);
    return 1;
}

/* Value buffer: long enough for a path plus slack so "too long" can be reported. */
#define VALUE_MAX (CDEM_PATH_MAX + 64)

/* [boundary.N]: N must be 2..CDEM_BOUNDARY_ACTORS ([boundary] is the first actor). */
static cdem_status check_actor_section(const char *section, const char *where, cdem_error *err) {
    const int n = actor_section(section);
    if (n == 0)
        return CDEM_OK;
    if (n < 2 || n > CDEM_BOUNDARY_ACTORS)
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "%s: section [%s]: a boundary actor's section is [boundary.2] to "
                         "[boundary.%d] ([boundary] is the first)",
                         where, section, CDEM_BOUNDARY_ACTORS);
    return CDEM_OK;
}

/* The line of `key` in an actor's text ("key = value\n" lines), or NULL. */
static char *actor_line(char *text, const char *key) {
    const size_t kl = strlen(key);
    for (char *line = text; line && *line;) {
        if (strncmp(line, key, kl) == 0 && line[kl] == ' ')
            return line;
        char *eol = strchr(line, '\n');
        line = eol ? eol + 1 : NULL;
    }
    return NULL;
}

/* Sets key = value for boundary actor n (2..): the value checked as the actor's own
 * parameters take it, and kept in its lines in the written form. A first key of
 * [boundary.(count + 1)] adds the actor; a later section is refused. replace: an override
 * (-s) replaces the key's line; a file's second line for a key is refused. */
static cdem_status assign_actor(cdem_params *work, int n, const char *key, const char *value,
                                int replace, const char *where, cdem_error *err) {
    CDEM_TRY(check_actor_section(n >= 2 && n <= CDEM_BOUNDARY_ACTORS ? "boundary.2" : "boundary.0",
                                 where, err));
    const cdem_param_def *d = cdem_params_find("boundary", key);
    if (!d) {
        char section[32];
        snprintf(section, sizeof section, "boundary.%d", n);
        return fail_unknown_key(where, section, key, err);
    }
    const int count = cdem_params_actor_count(work);
    if (n > count + 1)
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "%s: [boundary.%d] %s: set a key of [boundary.%d] (at least its mode) "
                         "first: the actors are numbered in order",
                         where, n, key, count + 1);
    char *text = work->actor_keys[n - 2];
    if (n == count + 1)
        text[0] = '\0';
    char *old = actor_line(text, key);
    if (old && !replace) {
        return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: [boundary.%d] %s: duplicate key; keep one",
                         where, n, key);
    }
    if (old) { /* drop the old line */
        char *eol = strchr(old, '\n');
        memmove(old, eol ? eol + 1 : old + strlen(old), strlen(eol ? eol + 1 : "") + 1);
    }
    cdem_params saved = *work;
    if (n == count + 1)
        work->boundary_actors = n;
    cdem_params actor;
    cdem_status st = cdem_params_actor(work, n - 1, &actor, err);
    if (st == CDEM_OK)
        st = assign_value(&actor, d, value, where, err);
    char formatted[VALUE_MAX];
    if (st == CDEM_OK) {
        cdem_params_format_value(&actor, d, formatted, sizeof formatted);
        const size_t used = strlen(text), add = strlen(key) + strlen(formatted) + 4;
        if (used + add >= CDEM_ACTOR_TEXT)
            st = CDEM_FAIL(err, CDEM_ERR_PARSE,
                           "%s: [boundary.%d] %s: the section's keys exceed %d characters", where,
                           n, key, CDEM_ACTOR_TEXT);
        else
            snprintf(text + used, CDEM_ACTOR_TEXT - used, "%s = %s\n", key, formatted);
    }
    if (st != CDEM_OK)
        *work = saved;
    return st;
}

cdem_status cdem_params_parse_text(cdem_params *p, const char *text, const char *path,
                                   cdem_error *err) {
    if (!p || !text)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_params_parse_text: NULL argument");
    if (!path)
        path = "<text>";
    cdem_params work = *p;     /* commit only on success */
    int set_on_line[N_PARAMS]; /* line where each key was set; 0 = not yet */
    memset(set_on_line, 0, sizeof set_on_line);
    char section[64] = "";
    int have_section = 0;
    const char *s = text;
    if ((unsigned char)s[0] == 0xEF && (unsigned char)s[1] == 0xBB && (unsigned char)s[2] == 0xBF)
        s += 3; /* UTF-8 byte-order mark */
    for (int line_no = 1; *s; line_no++) {
        const char *eol = strchr(s, '\n');
        size_t len = eol ? (size_t)(eol - s) : strlen(s);
        const char *next = eol ? eol + 1 : s + len;
        char line[VALUE_MAX + 128];
        char where[CDEM_PATH_MAX + 32];
        snprintf(where, sizeof where, "%s:%d", path, line_no);
        if (len >= sizeof line)
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: line longer than %zu characters: %.40s...",
                             where, sizeof line - 1, s);
        copy_trimmed(line, sizeof line, s, len);
        s = next;
        if (line[0] == '\0' || line[0] == '#' || line[0] == ';')
            continue;
        if (line[0] == '[') {
            char *close = strchr(line, ']');
            char rest[16];
            if (!close || !clean_value(close + 1, strlen(close + 1), rest, sizeof rest) ||
                rest[0] != '\0')
                return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                 "%s: line is not 'key = value' or '[section]': %s", where, line);
            copy_trimmed(section, sizeof section, line + 1, (size_t)(close - line - 1));
            if (!known_section(section) && actor_section(section) == 0)
                return fail_unknown_section(where, section, err);
            CDEM_TRY(check_actor_section(section, where, err));
            have_section = 1;
            continue;
        }
        char *eq = strchr(line, '=');
        char key[64];
        if (eq)
            copy_trimmed(key, sizeof key, line, (size_t)(eq - line));
        if (!eq || key[0] == '\0' || strpbrk(key, " \t"))
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "%s: line is not 'key = value' or '[section]': %s", where, line);
        char value[VALUE_MAX];
        if (!clean_value(eq + 1, strlen(eq + 1), value, sizeof value))
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "%s: %s: unterminated quote or text after the closing quote: %s",
                             where, key, line);
        if (!have_section) {
            const cdem_param_def *any = NULL;
            for (size_t i = 0; i < N_PARAMS && !any; i++)
                if (strcmp(param_table[i].key, key) == 0)
                    any = &param_table[i];
            if (any)
                return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                 "%s: %s: key before any [section]; put it under [%s]", where, key,
                                 any->section);
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "%s: %s: key before any [section]; start the file with a section "
                             "such as [assembly]",
                             where, key);
        }
        const int actor = actor_section(section);
        if (actor > 0) { /* [boundary.N]: a key of the actor's own (assign_actor) */
            CDEM_TRY(assign_actor(&work, actor, key, value, 0, where, err));
            continue;
        }
        const cdem_param_def *d = cdem_params_find(section, key);
        if (!d)
            return fail_unknown_key(where, section, key, err);
        size_t idx = (size_t)(d - param_table);
        if (set_on_line[idx])
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "%s: [%s] %s: duplicate key (already set on line %d); keep one", where,
                             section, key, set_on_line[idx]);
        set_on_line[idx] = line_no;
        CDEM_TRY(assign_value(&work, d, value, where, err));
    }
    *p = work;
    return CDEM_OK;
}

cdem_status cdem_params_load(cdem_params *p, const char *path, char **text_out, cdem_error *err) {
    if (text_out)
        *text_out = NULL;
    if (!p || !path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_params_load: NULL argument");
    FILE *f = fopen(path, "rb");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot open parameter file: %s", path,
                         strerror(errno));
    struct stat sb; /* a folder opens, and then every read fails with a bare "read error" */
    if (fstat(fileno(f), &sb) == 0 && !S_ISREG(sb.st_mode)) {
        fclose(f);
        return CDEM_FAIL(err, CDEM_ERR_IO,
                         "%s: is %s, not a parameter file (a text file of "
                         "[section] and key = value lines)",
                         path, S_ISDIR(sb.st_mode) ? "a folder" : "not a regular file");
    }
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    if (!buf) {
        fclose(f);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory reading the file", path);
    }
    for (;;) {
        if (len + 1 >= cap) {
            if (cap > ((size_t)64 << 20)) {
                free(buf);
                fclose(f);
                return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                 "%s: file larger than 64 MiB; not a parameter file", path);
            }
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                fclose(f);
                return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory reading the file", path);
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - 1 - len, f);
        len += got;
        if (got == 0)
            break;
    }
    int read_error = ferror(f);
    fclose(f);
    buf[len] = '\0';
    if (read_error) {
        free(buf);
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: read error", path);
    }
    if (memchr(buf, '\0', len)) {
        free(buf);
        return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: contains NUL bytes; not a text parameter file",
                         path);
    }
    cdem_status st = cdem_params_parse_text(p, buf, path, err);
    if (st != CDEM_OK || !text_out)
        free(buf);
    else
        *text_out = buf;
    return st;
}

cdem_status cdem_params_override(cdem_params *p, const char *assignment, cdem_error *err) {
    if (!p || !assignment)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_params_override: NULL argument");
    char where[VALUE_MAX + 16];
    snprintf(where, sizeof where, "-s %s", assignment);
    const char *eq = strchr(assignment, '=');
    char name[128];
    copy_trimmed(name, sizeof name, assignment,
                 eq ? (size_t)(eq - assignment) : strlen(assignment));
    const char *dot = strchr(name, '.');
    if (!eq || !dot || dot == name || dot[1] == '\0') {
        /* Help the user: find the section of a bare key. */
        const char *bare = dot ? dot + 1 : name;
        for (size_t i = 0; i < N_PARAMS; i++)
            if (strcmp(param_table[i].key, bare) == 0)
                return CDEM_FAIL(
                    err, CDEM_ERR_PARSE, "%s: expected section.key=value, e.g. %s.%s=%s", where,
                    param_table[i].section, param_table[i].key, eq ? eq + 1 : param_table[i].def);
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "%s: expected section.key=value, e.g. physics.gravity=9.81", where);
    }
    char section[64], key[64];
    copy_trimmed(section, sizeof section, name, (size_t)(dot - name));
    copy_trimmed(key, sizeof key, dot + 1, strlen(dot + 1));
    if (strcmp(section, "boundary") == 0 && isdigit((unsigned char)key[0]) && strchr(key, '.')) {
        /* boundary.N.key: a key of boundary actor N ([boundary.N]) */
        const char *kdot = strchr(key, '.');
        char actor_name[64], actor_key[64];
        snprintf(actor_name, sizeof actor_name, "boundary.%.*s", (int)(kdot - key), key);
        copy_trimmed(actor_key, sizeof actor_key, kdot + 1, strlen(kdot + 1));
        const int n = actor_section(actor_name);
        if (n < 0)
            return fail_unknown_section(where, actor_name, err);
        CDEM_TRY(check_actor_section(actor_name, where, err));
        char value[VALUE_MAX];
        copy_trimmed(value, sizeof value, eq + 1, strlen(eq + 1));
        size_t vl = strlen(value);
        if (vl >= 2 && value[0] == '"' && value[vl - 1] == '"') {
            memmove(value, value + 1, vl - 2);
            value[vl - 2] = '\0';
        }
        return assign_actor(p, n, actor_key, value, 1, where, err);
    }
    if (!known_section(section))
        return fail_unknown_section(where, section, err);
    const cdem_param_def *d = cdem_params_find(section, key);
    if (!d)
        return fail_unknown_key(where, section, key, err);
    char value[VALUE_MAX];
    copy_trimmed(value, sizeof value, eq + 1, strlen(eq + 1));
    /* Quotes are optional on the command line; strip one matching pair. */
    size_t vl = strlen(value);
    if (vl >= 2 && value[0] == '"' && value[vl - 1] == '"') {
        memmove(value, value + 1, vl - 2);
        value[vl - 2] = '\0';
    }
    cdem_params work = *p;
    CDEM_TRY(assign_value(&work, d, value, where, err));
    *p = work;
    return CDEM_OK;
}

/* ---------- formatting and writing ---------- */

void cdem_params_format_value(const cdem_params *p, const cdem_param_def *def, char *buf,
                              size_t n) {
    if (!buf || n == 0)
        return;
    buf[0] = '\0';
    if (!p || !def)
        return;
    const char *field = (const char *)p + def->offset;
    switch (def->type) {
    case CDEM_PTYPE_DOUBLE: {
        double v;
        memcpy(&v, field, sizeof v);
        if (isnan(v) && def->choices)
            snprintf(buf, n, "%s", def->choices[0]);
        else
            cdem_params_format_number(v, buf, n);
        break;
    }
    case CDEM_PTYPE_INT: {
        int v;
        memcpy(&v, field, sizeof v);
        snprintf(buf, n, "%d", v);
        break;
    }
    case CDEM_PTYPE_LONG: {
        long v;
        memcpy(&v, field, sizeof v);
        snprintf(buf, n, "%ld", v);
        break;
    }
    case CDEM_PTYPE_BOOL: {
        int v;
        memcpy(&v, field, sizeof v);
        snprintf(buf, n, "%s", v ? "on" : "off");
        break;
    }
    case CDEM_PTYPE_ENUM: {
        int v;
        memcpy(&v, field, sizeof v);
        int count = 0;
        while (def->choices[count])
            count++;
        snprintf(buf, n, "%s", v >= 0 && v < count ? def->choices[v] : "?");
        break;
    }
    case CDEM_PTYPE_STRING: {
        size_t len = strnlen(field, def->size);
        /* Quote when the plain text would not read back the same. */
        int quote = len == 0 || is_blank(field[0]) || is_blank(field[len - 1]) ||
                    memchr(field, '#', len) || memchr(field, ';', len);
        snprintf(buf, n, quote ? "\"%.*s\"" : "%.*s", (int)len, field);
        break;
    }
    }
}

int cdem_params_recorded(const cdem_params *p, const cdem_param_def *d) {
    if (!d->recorded_when_set && !d->fixture)
        return 1;
    cdem_params def;
    memset(&def, 0, sizeof def);
    if (assign_value(&def, d, d->def, "defaults", NULL) != CDEM_OK)
        return 1;
    char a[VALUE_MAX + 4], b[VALUE_MAX + 4];
    cdem_params_format_value(p, d, a, sizeof a);
    cdem_params_format_value(&def, d, b, sizeof b);
    return strcmp(a, b) != 0;
}

/* The sections [boundary.2] ... of p's actors after the first. */
static void write_actors(const cdem_params *p, FILE *out) {
    for (int j = 1; j < cdem_params_actor_count(p); j++)
        fprintf(out,
                "\n[boundary.%d]\n# boundary actor %d: these keys over [boundary]'s (start and "
                "stop its own)\n%s",
                j + 1, j + 1, p->actor_keys[j - 1]);
}

/* 1 when a record leaves section out: every key of it is recorded only when set (a section
 * added since, such as a process's [tilt]) and p sets none of them, so that the records of
 * runs that leave it alone stay as they were. */
static int record_leaves_out(const cdem_params *p, const char *section) {
    for (size_t i = 0; i < N_PARAMS; i++) {
        const cdem_param_def *d = &param_table[i];
        if (strcmp(d->section, section) != 0)
            continue;
        if (!(d->recorded_when_set || d->fixture) || cdem_params_recorded(p, d))
            return 0;
    }
    return 1;
}

/* cdem_params_write (every key) or, with record, cdem_params_write_record. */
static void write_params(const cdem_params *p, FILE *out, int record) {
    if (!p || !out)
        return;
    fprintf(out, "# cdem-c model parameters (complete; see docs/parameters.md)\n"
                 "# INI format: [section], key = value; '#' or ';' start a comment.\n"
                 "# Every key is listed; delete a line to use its default.\n");
    const char *cur = "";
    for (size_t i = 0; i < N_PARAMS; i++) {
        const cdem_param_def *d = &param_table[i];
        if (d->fixture && !(record && cdem_params_recorded(p, d)))
            continue; /* a fixture's key: in a record when set, else nowhere */
        if (strcmp(d->section, cur) != 0) {
            if (strcmp(cur, "boundary") == 0)
                write_actors(p, out);
            if (!(record && record_leaves_out(p, d->section)))
                fprintf(out, "\n[%s]\n", d->section);
            cur = d->section;
        }
        if (record && !cdem_params_recorded(p, d))
            continue;
        char allowed[256], value[VALUE_MAX + 4];
        describe_allowed(d, allowed, sizeof allowed);
        cdem_params_format_value(p, d, value, sizeof value);
        fprintf(out, "# %s (%s%s%s; default %s)\n%s = %s\n", d->help, d->unit,
                d->unit[0] ? "; " : "", allowed, d->def[0] ? d->def : "empty", d->key, value);
    }
    if (strcmp(cur, "boundary") == 0)
        write_actors(p, out);
}

void cdem_params_write(const cdem_params *p, FILE *out) {
    write_params(p, out, 0);
}

void cdem_params_write_record(const cdem_params *p, FILE *out) {
    write_params(p, out, 1);
}

cdem_status cdem_params_set_actor_keys(cdem_params *p, int n, const char *lines, const char *where,
                                       cdem_error *err) {
    cdem_params work = *p;
    for (const char *line = lines; *line;) {
        const char *eol = strchr(line, '\n');
        const size_t len = eol ? (size_t)(eol - line) : strlen(line);
        const char *eq = memchr(line, '=', len);
        if (len > 0) {
            char key[64], value[VALUE_MAX];
            if (!eq)
                return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: [boundary.%d]: not 'key = value': %.*s",
                                 where, n, (int)len, line);
            copy_trimmed(key, sizeof key, line, (size_t)(eq - line));
            if (!clean_value(eq + 1, len - (size_t)(eq + 1 - line), value, sizeof value))
                return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: [boundary.%d] %s: unterminated quote",
                                 where, n, key);
            CDEM_TRY(assign_actor(&work, n, key, value, 0, where, err));
        }
        line = eol ? eol + 1 : line + len;
    }
    *p = work;
    return CDEM_OK;
}

int cdem_params_actor_count(const cdem_params *p) {
    return p->boundary_actors < 1                      ? 1
           : p->boundary_actors > CDEM_BOUNDARY_ACTORS ? CDEM_BOUNDARY_ACTORS
                                                       : p->boundary_actors;
}

cdem_status cdem_params_actor(const cdem_params *p, int j, cdem_params *out, cdem_error *err) {
    const int count = cdem_params_actor_count(p);
    if (j < 0 || j >= count)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "boundary actor %d: the parameters have %d", j + 1,
                         count);
    if (out != p)
        *out = *p;
    out->boundary_actors = 1;
    memset(out->actor_keys, 0, sizeof out->actor_keys);
    if (j == 0)
        return CDEM_OK;
    /* the window is the actor's own: start and stop from its section, else their defaults */
    for (size_t i = 0; i < N_PARAMS; i++)
        if (param_table[i].offset == P_OFF(window_start) ||
            param_table[i].offset == P_OFF(window_stop))
            CDEM_TRY(assign_value(out, &param_table[i], param_table[i].def, "defaults", err));
    char where[32];
    snprintf(where, sizeof where, "[boundary.%d]", j + 1);
    for (const char *line = p->actor_keys[j - 1]; *line;) {
        const char *eol = strchr(line, '\n');
        const size_t len = eol ? (size_t)(eol - line) : strlen(line);
        const char *eq = memchr(line, '=', len);
        if (!eq)
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: a line is not 'key = value': %.*s", where,
                             (int)len, line);
        char key[64], value[VALUE_MAX];
        copy_trimmed(key, sizeof key, line, (size_t)(eq - line));
        if (!clean_value(eq + 1, len - (size_t)(eq + 1 - line), value, sizeof value))
            return CDEM_FAIL(err, CDEM_ERR_PARSE, "%s: %s: unterminated quote", where, key);
        const cdem_param_def *d = cdem_params_find("boundary", key);
        if (!d)
            return fail_unknown_key(where, "boundary", key, err);
        CDEM_TRY(assign_value(out, d, value, where, err));
        line = eol ? eol + 1 : line + len;
    }
    return CDEM_OK;
}

/* Escapes '|' for a markdown table cell. */
static void md_cell(FILE *out, const char *text) {
    for (const char *c = text; *c; c++) {
        if (*c == '|')
            fputc('\\', out);
        fputc(*c, out);
    }
}

static const char *type_name(cdem_param_type t) {
    switch (t) {
    case CDEM_PTYPE_DOUBLE:
        return "real";
    case CDEM_PTYPE_INT:
    case CDEM_PTYPE_LONG:
        return "integer";
    case CDEM_PTYPE_BOOL:
        return "boolean";
    case CDEM_PTYPE_ENUM:
        return "choice";
    case CDEM_PTYPE_STRING:
        return "text";
    }
    return "?";
}

void cdem_params_write_markdown(FILE *out) {
    if (!out)
        return;
    fprintf(out, "| section | key | type | default | unit | range / values | meaning |\n"
                 "|---|---|---|---|---|---|---|\n");
    for (size_t i = 0; i < N_PARAMS; i++) {
        const cdem_param_def *d = &param_table[i];
        if (d->fixture)
            continue; /* no user's key */
        char allowed[256];
        describe_allowed(d, allowed, sizeof allowed);
        fprintf(out, "| %s | `%s` | %s | ", d->section, d->key, type_name(d->type));
        if (d->def[0]) {
            fputc('`', out);
            md_cell(out, d->def);
            fputc('`', out);
        } else {
            fputs("(empty)", out);
        }
        fputs(" | ", out);
        md_cell(out, d->unit);
        fputs(" | ", out);
        md_cell(out, allowed);
        fputs(" | ", out);
        md_cell(out, d->help);
        fputs(" |\n", out);
    }
}

void cdem_params_write_laws_markdown(FILE *out) {
    if (!out)
        return;
    fprintf(out, "| `material.granular_law` | what it does |\n|---|---|\n");
    for (int law = 0; law < CDEM_LAW_WORDS; law++) {
        fprintf(out, "| `%s` | ", law_rows[law].word);
        md_cell(out, law_rows[law].description);
        fputs(" |\n", out);
    }
}

void cdem_params_write_modes_markdown(FILE *out) {
    if (!out)
        return;
    fprintf(out, "| `boundary.mode` | what it does |\n|---|---|\n");
    for (int mode = 0; mode < CDEM_MODE_WORDS; mode++) {
        fprintf(out, "| `%s` | ", mode_rows[mode].word);
        md_cell(out, mode_rows[mode].description);
        fputs(" |\n", out);
    }
}

/* ---------- validation of combinations ---------- */

void cdem_rule_add(cdem_rule_log *log, const char *fmt, ...) {
    log->count++;
    if (log->len + 2 >= log->cap)
        return;
    if (log->len > 0)
        log->buf[log->len++] = '\n';
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(log->buf + log->len, log->cap - log->len, fmt, ap);
    va_end(ap);
    if (w > 0)
        log->len += (size_t)w < log->cap - log->len ? (size_t)w : log->cap - log->len - 1;
}

double cdem_params_radius_scale(const cdem_params *p) {
    return p->radius_scale * (p->half_radii ? 0.5 : 1.0);
}

int cdem_params_prefix_ok(const char *prefix) {
    if (!prefix || !prefix[0] || prefix[0] == '.' || prefix[0] == '-' || strlen(prefix) > 64)
        return 0;
    for (const char *c = prefix; *c; c++)
        if (!isalnum((unsigned char)*c) && *c != '_' && *c != '-' && *c != '.')
            return 0;
    return 1;
}

/* The limits of a model's size the file bounds set (file_bounds.h): its largest radius
 * (0.125 units x the radius scale x unit_scaling), m, and its size, m: width, and height x
 * wall_height_multiplier, times unit_scaling. */
static double largest_radius(const cdem_params *p) {
    return CDEM_LARGEST_RADIUS_UNITS * cdem_params_radius_scale(p) * p->unit_scaling;
}
static double model_size_units(const cdem_params *p) {
    return fmax(p->width, p->height * p->wall_height_multiplier);
}

/* An assembly at least 8 of its largest elements wide and high (issue 33: no longer cdem's
 * box of 10 to 100 by 2.5 to 7.5 units; the memory a run needs is checked before it starts,
 * with the machine's own memory, by cdem-run). The advice is one that works (issue 46, item
 * 2): to enlarge the assembly only when the enlarged one and its elements fit the file
 * bounds, else to make the elements smaller. */
static void size_rule(const cdem_params *p, cdem_rule_log *log) {
    const double scale = cdem_params_radius_scale(p);
    const double least = 8.0 * 2.0 * CDEM_LARGEST_RADIUS_UNITS * scale;
    if (!(p->width < least || p->height < least))
        return;
    char v1[64], v2[64], v3[64], advice[400];
    cdem_params_format_number(least, v2, sizeof v2);
    cdem_params_format_number(p->width < least ? p->width : p->height, v1, sizeof v1);
    const double enlarged =
        fmax(fmax(p->width, least), fmax(p->height, least) * p->wall_height_multiplier);
    const int enlarge_ok = largest_radius(p) <= CDEM_FILE_MAX_RADIUS &&
                           enlarged * p->unit_scaling <= CDEM_MODEL_MAX_SIZE;
    /* the radius scale whose assembly of this width and height is 8 largest elements */
    const double rs_max = fmin(p->width, p->height) / (8.0 * 2.0 * CDEM_LARGEST_RADIUS_UNITS);
    const cdem_param_def *rs = cdem_params_find("assembly", "radius_scale");
    if (enlarge_ok) {
        snprintf(advice, sizeof advice,
                 "enlarge it or make the elements smaller ([assembly] radius_scale)");
    } else if (rs && rs_max >= rs->min) {
        cdem_params_format_number(rs_max, v3, sizeof v3);
        snprintf(advice, sizeof advice,
                 "make the elements smaller: [assembly] radius_scale <= %s%s (an assembly "
                 "enlarged to %s units would not fit a run file, below)",
                 v3, p->half_radii ? " with half_radii = off" : "", v2);
    } else {
        snprintf(advice, sizeof advice,
                 "no assembly of this unit_scaling fits both this and a run file's bounds "
                 "(below): lower [assembly] unit_scaling and enlarge it");
    }
    cdem_rule_add(log,
                  "%s = %s units: an assembly must be at least 8 of its largest elements "
                  "(diameter %.6g units) wide and high, i.e. >= %s units: %s",
                  p->width < least ? "width" : "height", v1,
                  2.0 * CDEM_LARGEST_RADIUS_UNITS * scale, v2, advice);
}

/* The bounds of a run file (file_bounds.h; docs/format.md, "Physical bounds") that the
 * assembly's parameters decide (issue 46, item 2: unit_scaling = 1e6 passed the checks and
 * the writer refused increment 0): its largest radius and its size. The boundaries'
 * displacement is cdem-run's rule (solver/run/run_validate.c): it needs the time step. */
static void file_bound_rules(const cdem_params *p, cdem_rule_log *log) {
    char us[64], rs[64], v1[64], v2[64], v3[64], v4[64];
    cdem_params_format_number(p->unit_scaling, us, sizeof us);
    cdem_params_format_number(p->radius_scale, rs, sizeof rs);
    const double rmax = largest_radius(p);
    if (!(rmax <= CDEM_FILE_MAX_RADIUS)) {
        const double scale = cdem_params_radius_scale(p);
        cdem_params_format_number(rmax, v1, sizeof v1);
        cdem_params_format_number(CDEM_FILE_MAX_RADIUS, v2, sizeof v2);
        cdem_params_format_number(CDEM_FILE_MAX_RADIUS / (CDEM_LARGEST_RADIUS_UNITS * scale), v3,
                                  sizeof v3);
        cdem_params_format_number(
            CDEM_FILE_MAX_RADIUS / (CDEM_LARGEST_RADIUS_UNITS * p->unit_scaling), v4, sizeof v4);
        if (p->half_radii)
            cdem_rule_add(log,
                          "unit_scaling = %s m with half_radii = on: the largest element radius "
                          "would be %s m (0.0625 units x unit_scaling), above the %s m a run "
                          "file holds (docs/format.md, \"Physical bounds\"): set [assembly] "
                          "unit_scaling <= %s m",
                          us, v1, v2, v3);
        else
            cdem_rule_add(log,
                          "unit_scaling = %s m and radius_scale = %s: the largest element "
                          "radius would be %s m (0.125 units x radius_scale x unit_scaling), "
                          "above the %s m a run file holds (docs/format.md, \"Physical "
                          "bounds\"): set [assembly] unit_scaling <= %s m at this radius_scale, "
                          "or radius_scale <= %s at this unit_scaling",
                          us, rs, v1, v2, v3, v4);
    }
    const double size = model_size_units(p) * p->unit_scaling;
    if (!(size <= CDEM_MODEL_MAX_SIZE)) {
        const int wide = p->width >= p->height * p->wall_height_multiplier;
        char what[160];
        cdem_params_format_number(wide ? p->width : p->height, v1, sizeof v1);
        if (wide)
            snprintf(what, sizeof what, "width = %s units", v1);
        else
            snprintf(what, sizeof what, "height = %s units x wall_height_multiplier = %d", v1,
                     p->wall_height_multiplier);
        cdem_params_format_number(size, v1, sizeof v1);
        cdem_params_format_number(CDEM_MODEL_MAX_SIZE, v2, sizeof v2);
        cdem_params_format_number(0.9 * CDEM_MODEL_MAX_SIZE / model_size_units(p), v4, sizeof v4);
        cdem_rule_add(log,
                      "%s at unit_scaling = %s m: the model would be %s m across, more than "
                      "the %s m a run file holds for positions (docs/format.md, \"Physical "
                      "bounds\"): set [assembly] unit_scaling <= %s m at this size (room for "
                      "the boundaries' displacement), or make the assembly smaller",
                      what, us, v1, v2, v4);
    }
}

cdem_status cdem_params_validate(const cdem_params *p, cdem_params_rules more, cdem_error *err) {
    if (!p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_params_validate: NULL parameters");
    char msg[CDEM_ERROR_MSG_MAX];
    cdem_rule_log log = {msg, sizeof msg, 0, 0};
    msg[0] = '\0';
    char v1[64], v2[64];

    /* Values set by code rather than parsed still obey the table. */
    for (size_t i = 0; i < N_PARAMS; i++) {
        const cdem_param_def *d = &param_table[i];
        const char *field = (const char *)p + d->offset;
        double v = 0.0;
        int iv = 0, count = 0;
        long lv = 0;
        switch (d->type) {
        case CDEM_PTYPE_DOUBLE:
            memcpy(&v, field, sizeof v);
            if (isnan(v) && d->choices)
                continue; /* the row's word */
            break;
        case CDEM_PTYPE_INT:
            memcpy(&iv, field, sizeof iv);
            v = iv;
            break;
        case CDEM_PTYPE_LONG:
            memcpy(&lv, field, sizeof lv);
            v = (double)lv;
            break;
        case CDEM_PTYPE_BOOL:
            memcpy(&iv, field, sizeof iv);
            if (iv != 0 && iv != 1)
                cdem_rule_add(&log, "[%s] %s = %d: must be 0 or 1 (off/on)", d->section, d->key,
                              iv);
            continue;
        case CDEM_PTYPE_ENUM:
            memcpy(&iv, field, sizeof iv);
            while (d->choices[count])
                count++;
            if (iv < 0 || iv >= count)
                cdem_rule_add(&log, "[%s] %s = %d: not a valid choice", d->section, d->key, iv);
            continue;
        case CDEM_PTYPE_STRING:
            if (!memchr(field, '\0', d->size))
                cdem_rule_add(&log, "[%s] %s: text not terminated within %zu characters",
                              d->section, d->key, d->size);
            continue;
        }
        if (!in_range(d, v)) {
            char range[160];
            describe_range(d, range, sizeof range);
            cdem_params_format_number(v, v1, sizeof v1);
            cdem_rule_add(&log, "[%s] %s = %s: must be %s", d->section, d->key, v1, range);
        }
    }
    if (log.count > 0) /* ranges first: the cross rules below assume sane values */
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "%s", msg);

    /* the size of the assembly against its elements, and both against a run file's bounds */
    if (p->half_radii && p->radius_scale != 1.0) {
        cdem_params_format_number(p->radius_scale, v1, sizeof v1);
        cdem_rule_add(&log,
                      "half_radii = on and radius_scale = %s: choose one (half_radii is "
                      "radius_scale = 0.5)",
                      v1);
    } else {
        size_rule(p, &log);
        file_bound_rules(p, &log);
    }
    /* a file-name prefix, not a path (issue 35, item 8: "../../etc/x" was accepted) */
    if (!cdem_params_prefix_ok(p->prefix))
        cdem_rule_add(&log, "[output] prefix = \"%.60s\": %s", p->prefix, CDEM_PREFIX_RULE);
    if (!(p->equilibration < p->runtime)) {
        cdem_params_format_number(p->equilibration, v1, sizeof v1);
        cdem_params_format_number(p->runtime, v2, sizeof v2);
        cdem_rule_add(&log,
                      "equilibration = %s s must be shorter than runtime = %s s: increase [time] "
                      "runtime or reduce [time] equilibration",
                      v1, v2);
    }
    if (p->weak_interval != CDEM_WEAK_OFF && p->layered_friction)
        cdem_rule_add(&log,
                      "weak_interval = %s excludes layered_friction = on: set [heterogeneity] "
                      "weak_interval = off or layered_friction = off",
                      weak_words[p->weak_interval]);
    if (p->layered_friction && p->material != CDEM_MATERIAL_GRANULAR)
        cdem_rule_add(&log,
                      "layered_friction = on requires material = granular (got material = %s): set "
                      "[heterogeneity] layered_friction = off or [material] material = granular",
                      material_words[p->material]);
    if (p->overburden_pressure > 0) {
        cdem_params_format_number(p->overburden_pressure, v1, sizeof v1);
        if (p->erosion)
            cdem_rule_add(&log,
                          "overburden_pressure = %s N/m excludes erosion = on: set [surface] "
                          "overburden_pressure = 0 or erosion = off",
                          v1);
        if (p->sedimentation)
            cdem_rule_add(&log,
                          "overburden_pressure = %s N/m excludes sedimentation = on: set [surface] "
                          "overburden_pressure = 0 or sedimentation = off",
                          v1);
    }
    if (more)
        more(p, &log);
    if (log.count > 0)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT, "%s", msg);
    return CDEM_OK;
}
