/* run_validate: every rule the parameters of a cdem-run run obey, checked before anything is
 * built: the table's ranges and rules (common/params.c) and, in the same message, the
 * solver's own: the boundary mode's (its validate hook and excludes, and whether it inverts:
 * modes/bc_registry.c), the growth strata's (packing/sediment.c) and the salt's
 * (step/salt_rules.c). */
#include "run.h"

#include "bc.h"
#include "salt.h"
#include "sediment.h"

/* The rules of the solver's modules, after the table's. */
static void solver_rules(const cdem_params *p, cdem_rule_log *log) {
    cdem_bc_rules(p, log);
    cdem_sediment_rules(p, log);
    cdem_salt_rules(p, log);
}

cdem_status cdem_run_validate(const cdem_params *p, cdem_error *err) {
    return cdem_params_validate(p, solver_rules, err);
}
