/* run_validate: every rule the parameters of a cdem-run run obey, checked before anything is
 * built: the table's ranges and rules (common/params.c) and, in the same message, the
 * solver's own: the boundary mode's (its validate hook and excludes, and whether it inverts:
 * modes/bc_registry.c), the growth strata's (packing/sediment.c) and the processes' (their
 * rules hooks: process/process.h). And the one limit on the size of a model that is not a rule of
 * its parameters: the memory of the machine it runs on (cdem_run_check_memory). */
#include "run.h"
#include "run_ctx.h"

#include "bc.h"
#include "model.h"
#include "process.h"
#include "sediment.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* Where the model's elements can be, against a run file's bound on positions
 * (file_bounds.h; the box alone and the radius are the table's rules, common/params.c): the
 * base from -beyond_left W to (1 + beyond_right) W (the mode's derive: repose's runs on past
 * its walls), the walls up to H x wall_height_multiplier, the boundaries' displacement over
 * the run (a wall moving out, a fault's ramps below the base) and twice the largest radius
 * either way. The advice scales what moves: the runtime after equilibration, or the model
 * (everything grows with unit_scaling). */
static void extent_rule(const cdem_params *p, cdem_rule_log *log) {
    cdem_model m;
    cdem_error err;
    if (cdem_bc_derive_model(p, &m, &err) != CDEM_OK)
        return; /* the mode's rules, or cdem-run's derivation, say what is wrong */
    const double W = m.width_m, H = m.height_m * p->wall_height_multiplier;
    const double D = m.total_displacement, r2 = 2.0 * m.max_radius;
    const double box =
        fmax(fmax(m.mode.base_beyond_left * W, (1.0 + m.mode.base_beyond_right) * W), H);
    const double extent = box + D + r2;
    if (extent <= CDEM_FILE_MAX_LENGTH)
        return;
    char v1[64], v2[64], v3[64], v4[64], v5[64];
    cdem_params_format_number(p->runtime, v1, sizeof v1);
    cdem_params_format_number(p->unit_scaling, v2, sizeof v2);
    cdem_params_format_number(CDEM_FILE_MAX_LENGTH, v3, sizeof v3);
    char advice[256];
    const double room = CDEM_FILE_MAX_LENGTH - box - r2; /* what the displacement may take */
    if (room > 0.0 && D > 0.0) {
        /* the displacement grows with the steps after equilibration; a step for rounding */
        const double runtime_max = p->equilibration + (p->runtime - p->equilibration) * room / D;
        cdem_params_format_number(floor(runtime_max - m.dt), v4, sizeof v4);
        cdem_params_format_number(floor(p->unit_scaling * CDEM_FILE_MAX_LENGTH / extent), v5,
                                  sizeof v5);
        snprintf(advice, sizeof advice,
                 "set [time] runtime <= %s s, or a smaller [assembly] unit_scaling (<= %s m)", v4,
                 v5);
    } else {
        cdem_params_format_number(floor(0.9 * p->unit_scaling * CDEM_FILE_MAX_LENGTH / extent), v5,
                                  sizeof v5);
        snprintf(advice, sizeof advice,
                 "set [assembly] unit_scaling <= %s m, or a smaller assembly", v5);
    }
    cdem_rule_add(log,
                  "runtime = %s s at unit_scaling = %s m: the model's elements would reach %.4g m "
                  "from its origin (the box and base %.4g m, the boundaries' displacement %.4g m "
                  "at %.4g m/s, two radii), beyond the %s m a run file holds for positions "
                  "(docs/format.md, \"Physical bounds\"): %s",
                  v1, v2, extent, box, D, m.boundary_speed, v3, advice);
}

/* The rules of the solver's modules, after the table's. */
static void solver_rules(const cdem_params *p, cdem_rule_log *log) {
    cdem_bc_rules(p, log);
    cdem_sediment_rules(p, log);
    cdem_processes_rules(p, log);
    extent_rule(p, log);
}

cdem_status cdem_run_validate(const cdem_params *p, cdem_error *err) {
    return cdem_params_validate(p, solver_rules, err);
}

/* Memory available to a new process (bytes): MemAvailable of /proc/meminfo, else the free
 * physical pages; 0 when neither can be read. */
static double memory_available(void) {
    FILE *f = fopen("/proc/meminfo", "r");
    if (f) {
        char line[256];
        unsigned long long kb = 0;
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "MemAvailable: %llu kB", &kb) == 1)
                break;
        fclose(f);
        if (kb > 0)
            return (double)kb * 1024.0;
    }
    const long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : 0.0;
}

/* The bytes a run of about n elements needs. */
static double memory_for(long n) {
    return CDEM_RUN_MEMORY_FIXED + (double)n * CDEM_RUN_MEMORY_PER_ELEMENT;
}

double cdem_run_memory_estimate(const cdem_params *p) {
    return memory_for(cdem_model_estimate_elements(p));
}

/* The memory check of a model of about n elements against `have` bytes. */
static cdem_status check_memory_of(long n, double have, cdem_error *err) {
    const double need = memory_for(n);
    /* the memory first (the limit a user meets), then the 32-bit indices */
    if (have <= 0.0 || need <= have) {
        if (n > CDEM_RUN_MAX_ELEMENTS)
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "the model would hold about %ld elements: more than the %ld a run can "
                             "number (its neighbour list numbers the contact pairs, up to 4 per "
                             "element, with 32-bit integers): use larger elements ([assembly] "
                             "radius_scale) or a smaller assembly",
                             n, CDEM_RUN_MAX_ELEMENTS);
        return CDEM_OK;
    }
    return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                     "the model would hold about %ld elements and need about %.3g GB of memory "
                     "(%.0f bytes per element, measured), but this machine has %.3g GB "
                     "available: use larger elements ([assembly] radius_scale), a smaller "
                     "assembly, or a machine with more memory",
                     n, need / 1e9, CDEM_RUN_MEMORY_PER_ELEMENT, have / 1e9);
}

cdem_status cdem_run_check_memory(const cdem_params *p, cdem_error *err) {
    return cdem_run_check_memory_in(p, memory_available(), err);
}

cdem_status cdem_run_check_memory_in(const cdem_params *p, double have, cdem_error *err) {
    return check_memory_of(cdem_model_estimate_elements(p), have, err);
}

cdem_status run_check_model_memory(const cdem_model *m, cdem_error *err) {
    return check_memory_of(m->elements_estimated, memory_available(), err);
}
