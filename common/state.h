/* state: the element state shared by cdem-run, cdem-strain and the file format.
 *
 * A struct of arrays (one array per property, index = element slot), so hot loops stream
 * through memory and each array maps one-to-one onto an HDF5 dataset. An element keeps its
 * id for life; added elements get new ids (next_id); removed elements are compacted away.
 * Stress arrays (sxx, syy, sxy) exist only when has_stress is set. The solver may keep its
 * own extra per-element arrays, indexed the same way, in its own context.
 * Ownership: cdem_state owns its arrays; cdem_state_free releases them. Growth is geometric
 * (reserve), never inside a time step. Thread safety: none; one owner at a time.
 * Units: m, m/s, N, kg per metre of thickness, N/m for stress (compression positive). */
#ifndef CDEM_STATE_H
#define CDEM_STATE_H

#include "cdem_error.h"

#include <stddef.h>
#include <stdint.h>

/* Element flags (bit field, stored as uint32 in every increment). */
enum {
    CDEM_FLAG_WALL = 1u << 0,   /* fixed or moving wall element (base, lateral wall, platen) */
    CDEM_FLAG_FAULT = 1u << 1,  /* element of a fault face */
    CDEM_FLAG_MOVING = 1u << 2, /* boundary element whose motion is prescribed by the mode */
    CDEM_FLAG_GROWTH = 1u << 3, /* deposited during the run (syn-tectonic sedimentation) */
    CDEM_FLAG_WEAK = 1u << 4,   /* inside the weak and/or light interval */
    CDEM_FLAG_BIAXIAL_EDGE = 1u << 5, /* biaxial free-edge element carrying confining pressure */
    CDEM_FLAG_FOOTWALL = 1u << 6,     /* removed footwall element kept fixed for display only */
    CDEM_FLAG_MYLAR = 1u << 7,        /* CD "mylar sheet" element dragging the hanging wall */
    CDEM_FLAG_SURFACE = 1u << 8,      /* top-surface element (overburden acts on it) */
    CDEM_FLAG_BASE = 1u << 9,         /* wall element of the base row (material.base_*) */
    CDEM_FLAG_SALT = 1u << 10,        /* a viscous salt element (salt.layer; solver/salt/) */
    /* bits 16..22: the element moves with boundary actor 2..8 ([boundary.N]; the first actor's
     * elements carry CDEM_FLAG_MOVING), as CDEM_FLAG_ACTOR_MOVING(N) */
    CDEM_FLAG_ACTORS_MOVING = 0x7Fu << 16,
};

/* The flag of the elements boundary actor n (2..8) moves. */
#define CDEM_FLAG_ACTOR_MOVING(n) (1u << (14 + (n)))

/* The elements of a process (solver/process/process.h, its flag): the process evaluates their
 * pairs, never the pair list (cdem_contact_class); the analysis colours and filters by them. */
#define CDEM_FLAGS_PROCESS (CDEM_FLAG_SALT)

/* Elements that are integrated by Newton's law: neither wall, fault nor footwall display. */
#define CDEM_FLAGS_BOUNDARY                                                                        \
    (CDEM_FLAG_WALL | CDEM_FLAG_FAULT | CDEM_FLAG_FOOTWALL | CDEM_FLAG_MYLAR)

/* Element types of the per-element arrays, as stored in files. */
typedef enum {
    CDEM_FIELD_I32, /* int32_t */
    CDEM_FIELD_U32, /* uint32_t */
    CDEM_FIELD_F64, /* double */
} cdem_field_type;

/* The per-element arrays: the one list that declares them (cdem_state below), allocates,
 * grows, frees, copies and compacts them (state.c), stores them in every increment of the
 * run file (common/h5/h5_layout.c) and in checkpoints (solver/base/checkpoint.c). Adding a field is
 * one row here (plus, for an in_increments field, its line in docs/format.md and a thought
 * about older files, which lack the dataset). The order is the order of the checkpoint blob
 * and of the run file's datasets: append new rows, do not reorder. Columns:
 *   X(name, C type, file type, in_increments, stress)
 *   in_increments  1: a dataset /increments/<name> of the run file; 0: checkpoints only
 *   stress         1: allocated only when has_stress (the three stress components)
 * area_ratio (J) is 1 for every element but a viscous process's elements, whose material area
 * J pi r^2 / phi it scales (solver/process/process.h). It is in checkpoints, not in
 * increments: J stays within 1 % of 1 (the process's bulk modulus), its pressure K (1/J - 1)
 * is in the stress datasets and its area in the process's series columns, and every file of a
 * run without such a process stays as it was. */
#define CDEM_STATE_FIELDS(X)                                                                       \
    X(id, int32_t, CDEM_FIELD_I32, 1, 0)     /* stable element id, unique within a run */          \
    X(x, double, CDEM_FIELD_F64, 1, 0)       /* centre position, m */                              \
    X(y, double, CDEM_FIELD_F64, 1, 0)       /* centre position, m */                              \
    X(vx, double, CDEM_FIELD_F64, 0, 0)      /* velocity, m/s */                                   \
    X(vy, double, CDEM_FIELD_F64, 0, 0)      /* velocity, m/s */                                   \
    X(fx, double, CDEM_FIELD_F64, 0, 0)      /* total force of the current step, N */              \
    X(fy, double, CDEM_FIELD_F64, 0, 0)      /* total force of the current step, N */              \
    X(radius, double, CDEM_FIELD_F64, 1, 0)  /* m */                                               \
    X(mass, double, CDEM_FIELD_F64, 0, 0)    /* kg per metre */                                    \
    X(layer, int32_t, CDEM_FIELD_I32, 1, 0)  /* 1..24 pre-growth; 25.. growth; 0 = wall */         \
    X(flags, uint32_t, CDEM_FIELD_U32, 1, 0) /* CDEM_FLAG_* bits */                                \
    X(born, int32_t, CDEM_FIELD_I32, 1, 0)   /* increment that created it (0 = initial) */         \
    X(sxx, double, CDEM_FIELD_F64, 1, 1)     /* stress, N/m, compression positive */               \
    X(syy, double, CDEM_FIELD_F64, 1, 1)     /* NULL unless has_stress */                          \
    X(sxy, double, CDEM_FIELD_F64, 1, 1)                                                           \
    X(area_ratio, double, CDEM_FIELD_F64, 0, 0) /* a viscous process's elements: material          \
                                                   area / area at placement (J) */

typedef struct {
    size_t n;        /* number of elements in use */
    size_t capacity; /* allocated length of every array */
    int has_stress;  /* 1: sxx, syy, sxy are allocated */
    int32_t next_id; /* id for the next added element */
    /* one array per row of CDEM_STATE_FIELDS (meaning and units there): id, x, y, vx, vy,
     * fx, fy, radius, mass, layer, flags, born, sxx, syy, sxy, area_ratio */
#define CDEM_STATE_MEMBER(name, ctype, ftype, in_increments, stress) ctype *name;
    CDEM_STATE_FIELDS(CDEM_STATE_MEMBER)
#undef CDEM_STATE_MEMBER
} cdem_state;

/* A row of CDEM_STATE_FIELDS as data, for code that loops over the fields at run time. */
typedef struct {
    const char *name;     /* member name, dataset name and checkpoint array name */
    cdem_field_type type; /* element type */
    size_t offset;        /* offset of the array pointer in cdem_state */
    int in_increments;    /* 1: stored in every increment of the run file */
    int stress;           /* 1: exists only when has_stress */
} cdem_state_field;

/* The rows of CDEM_STATE_FIELDS, in order; cdem_state_field_count of them. */
extern const cdem_state_field cdem_state_fields[];
extern const size_t cdem_state_field_count;

/* The array of field f in s (NULL when not allocated). */
void *cdem_state_field_array(const cdem_state *s, const cdem_state_field *f);

/* Bytes of one element of type t. */
size_t cdem_field_type_size(cdem_field_type t);

/* Initialises an empty state with room for capacity elements. */
cdem_status cdem_state_init(cdem_state *s, size_t capacity, int with_stress, cdem_error *err);

/* Releases every array; s may be NULL. Leaves s empty. */
void cdem_state_free(cdem_state *s);

/* The lowest and highest centre heights of the free elements (neither wall, fault, footwall
 * display nor mylar: CDEM_FLAGS_BOUNDARY); lo = +inf and hi = -inf when there are none. The
 * layers, the weak interval, the erosion level and a process's band are measured on it. */
void cdem_state_free_y_range(const cdem_state *s, double *lo, double *hi);

/* Grows every array to hold at least capacity elements (geometric growth). */
cdem_status cdem_state_reserve(cdem_state *s, size_t capacity, cdem_error *err);

/* Allocates the stress arrays (zeroed) if they are missing. */
cdem_status cdem_state_enable_stress(cdem_state *s, cdem_error *err);

/* Appends one element with zero velocity and force; returns its index in *index.
 * id < 0 means "assign next_id". */
cdem_status cdem_state_append(cdem_state *s, int32_t id, double x, double y, double radius,
                              double mass, int32_t layer, uint32_t flags, int32_t born,
                              size_t *index, cdem_error *err);

/* Removes the elements whose keep[i] is 0, preserving the order of the rest. keep_out
 * (optional, length n before the call) receives for each old index its new index or
 * SIZE_MAX. */
void cdem_state_compact(cdem_state *s, const unsigned char *keep, size_t *new_index_out);

/* Copies src into dst. dst is an output, like cdem_state_init's: its previous contents are
 * neither read nor freed, so it may be an uninitialised variable. (A destination that was
 * freed on entry crashed on garbage pointers; a misused destination now only leaks, which
 * LeakSanitizer reports under make asan.) To copy into a state that owns arrays, use
 * cdem_state_assign. Copying a state onto itself does nothing. On failure dst is empty. */
cdem_status cdem_state_copy(cdem_state *dst, const cdem_state *src, cdem_error *err);

/* Replaces the contents of dst, which must be initialised or zeroed ({0}), by a copy of src:
 * dst's arrays are released first. For reusing one destination in a loop. */
cdem_status cdem_state_assign(cdem_state *dst, const cdem_state *src, cdem_error *err);

/* Map from element id to index, for matching elements across increments. */
typedef struct {
    int32_t min_id, max_id; /* range of ids present */
    size_t *index;          /* index[id - min_id] = slot, or SIZE_MAX when absent */
} cdem_id_map;

cdem_status cdem_id_map_build(cdem_id_map *map, const cdem_state *s, cdem_error *err);
/* Slot of id, or SIZE_MAX when the id is not in the state. */
size_t cdem_id_map_find(const cdem_id_map *map, int32_t id);
void cdem_id_map_free(cdem_id_map *map);

#endif
