/* salt: the parameters of the viscous salt process ([salt]; solver/salt/, docs/solver.md
 * section 9), read as processes.def says: its section's name, the enums of its keys, its
 * fields of cdem_params, their words and its rows of the parameter table; its own elements
 * (their density, which the model's time step must know) and its columns of the time
 * series. */
/* clang-format off */
#ifdef CDEM_PARAM_SECTIONS
"salt",
#endif

#ifdef CDEM_PARAM_TYPES
/* Where the viscous salt is (salt.layer). */
typedef enum {
    CDEM_SALT_OFF = 0,
    CDEM_SALT_BASAL = 1,    /* the lowest salt.thickness_percent of the assembly */
    CDEM_SALT_INTERVAL = 2, /* between salt.interval_bottom_percent and _top_percent */
} cdem_salt_layer_choice;
/* How the salt meets a neighbour that is not salt (salt.*_contact). */
typedef enum {
    CDEM_SALT_NO_SLIP = 0,   /* the neighbour joins the salt's grid: the salt sticks to it */
    CDEM_SALT_FREE_SLIP = 1, /* only the pair law (repulsion and a normal dashpot) */
} cdem_salt_contact;
#endif

#ifdef CDEM_PARAM_FIELDS
cdem_salt_layer_choice salt_layer; /* off, basal or interval */
double salt_thickness_percent;     /* basal: % of the span of element centres, (0, 100) */
double salt_interval_bottom_percent, salt_interval_top_percent; /* interval: % of the span */
double salt_viscosity;        /* Pa s, geological (Newtonian) */
double salt_density;          /* kg/m^3 */
double salt_rate;             /* mm/yr: the geological speed of the model's boundary speed */
double salt_time_scale;       /* S, geological s per model s; NaN = from salt_rate ("rate") */
double salt_bulk_modulus;     /* Pa: p = K (1/J - 1) */
double salt_grid_spacing;     /* node spacing of the salt's grid, in mean radii */
double salt_reach;            /* the pair dashpots reach reach x (r_i + r_j) */
double salt_dashpot_fraction; /* the pair dashpots' coefficient, x beta x viscosity */
cdem_salt_contact salt_cover_contact, salt_base_contact, salt_wall_contact;
#endif

#ifdef CDEM_PARAM_WORDS
static const char *const salt_layer_words[] = {"off", "basal", "interval", NULL};
static const char *const salt_contact_words[] = {"no-slip", "free-slip", NULL};
/* salt.time_scale's word: the time scale follows from salt.rate */
static const char *const from_rate_words[] = {"rate", NULL};
#endif

#ifdef CDEM_PARAM_ROWS
    {"salt", "layer", CDEM_PTYPE_ENUM, P_OFF(salt_layer), 0, "", "off", 0, 0, 0, 0, salt_layer_words,
     "viscous salt: none (off), the lowest part of the assembly (basal) or an interval of the pre-growth layers (interval), fixed at assembly", 0, 0},
    {"salt", "thickness_percent", CDEM_PTYPE_DOUBLE, P_OFF(salt_thickness_percent), 0, "%", "25", 0, 100, 1, 1, NULL,
     "basal: the salt's thickness, % of the span of element centres (it must leave a cover)", 0, 0},
    {"salt", "interval_bottom_percent", CDEM_PTYPE_DOUBLE, P_OFF(salt_interval_bottom_percent), 0, "%", "20", 0, 100, 0, 0, NULL,
     "interval: the salt's base, % of the span of element centres above the lowest", 0, 0},
    {"salt", "interval_top_percent", CDEM_PTYPE_DOUBLE, P_OFF(salt_interval_top_percent), 0, "%", "40", 0, 100, 0, 0, NULL,
     "interval: the salt's top, % of the span of element centres above the lowest", 0, 0},
    {"salt", "viscosity", CDEM_PTYPE_DOUBLE, P_OFF(salt_viscosity), 0, "Pa s", "1e18", 1e15, 1e21, 0, 0, NULL,
     "the salt's geological (Newtonian) viscosity; the model's is viscosity / time_scale", 0, 0},
    {"salt", "salt_density", CDEM_PTYPE_DOUBLE, P_OFF(salt_density), 0, "kg/m^3", "2200", 1000, 3500, 0, 0, NULL,
     "the salt's density (halite 2160)", 0, 0},
    {"salt", "rate", CDEM_PTYPE_DOUBLE, P_OFF(salt_rate), 0, "mm/yr", "1", 0.01, 100, 0, 0, NULL,
     "the geological speed the boundary speed stands for: time_scale = boundary speed / rate", 0, 0},
    {"salt", "time_scale", CDEM_PTYPE_DOUBLE, P_OFF(salt_time_scale), 0, "", "rate", 1, 1e16, 0, 0, from_rate_words,
     "geological seconds per model second (modes without a moving boundary); rate = from salt.rate", 0, 0},
    {"salt", "bulk_modulus", CDEM_PTYPE_DOUBLE, P_OFF(salt_bulk_modulus), 0, "Pa", "2.5e10", 1e8, 1e12, 0, 0, NULL,
     "the salt's bulk modulus K: pressure K (1/J - 1) for an area ratio J; halite's, about 25 GPa, "
     "by default (the salt's area changes by p / K: 0.4 % under 4 km of cover)", 0, 0},
    {"salt", "grid_spacing", CDEM_PTYPE_DOUBLE, P_OFF(salt_grid_spacing), 0, "mean radii", "4.5", 3, 8, 0, 0, NULL,
     "node spacing of the grid that carries the salt's stress", 0, 0},
    {"salt", "reach", CDEM_PTYPE_DOUBLE, P_OFF(salt_reach), 0, "", "1.5", 1, 2, 0, 0, NULL,
     "the salt's pair dashpots act up to reach x (r_i + r_j)", 0, 0},
    {"salt", "dashpot_fraction", CDEM_PTYPE_DOUBLE, P_OFF(salt_dashpot_fraction), 0, "", "0.1", 0, 1, 0, 0, NULL,
     "the salt's pair dashpots (which damp the element motions the grid cannot see), as a fraction of a dashpot network of the salt's viscosity", 0, 0},
    {"salt", "cover_contact", CDEM_PTYPE_ENUM, P_OFF(salt_cover_contact), 0, "", "no-slip", 0, 0, 0, 0, salt_contact_words,
     "no-slip: cover elements next to the salt join its grid (the salt sticks to them); free-slip: only the pair law", 0, 0},
    {"salt", "base_contact", CDEM_PTYPE_ENUM, P_OFF(salt_base_contact), 0, "", "no-slip", 0, 0, 0, 0, salt_contact_words,
     "the same for the base and the fault elements", 0, 0},
    {"salt", "wall_contact", CDEM_PTYPE_ENUM, P_OFF(salt_wall_contact), 0, "", "no-slip", 0, 0, 0, 0, salt_contact_words,
     "the same for the lateral walls", 0, 0},
#endif

#ifdef CDEM_PROCESS_ELEMENTS
/* the salt elements: their density, when salt.layer is on */
CDEM_PROCESS_ELEMENTS("salt", "salt.salt_density", p->salt_layer != CDEM_SALT_OFF, p->salt_density)
#endif

#ifdef CDEM_PROCESS_SERIES
/* m^2, the salt's material area (sum of J pi r^2 / phi over the salt elements): conserved to
 * within its elastic compression */
CDEM_PROCESS_SERIES(salt_area, "m^2", 0, 1e14, "Salt area (m^2)")
/* m, the highest salt element's top (a diapir's crest); within the coordinate bound */
CDEM_PROCESS_SERIES(salt_top, "m", -1e7, 1e7, "Salt top (m)")
#endif
    /* clang-format on */
