/* cmd_element: `cdem-strain element`; its help (below) says what it does. */
#include "cmd_options.h"

#include "analysis.h"
#include "quantity.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

static int cmd_element(const cdem_cmd_options *o) {
    if (!o->increment || !o->element)
        return cdem_cmd_usage(o->help, "element needs --increment K and --element ID");
    char *end;
    long id = strtol(o->element, &end, 10);
    if (*end || end == o->element)
        return cdem_cmd_usage(o->help, "--element must be an element id (a whole number)");
    cdem_analysis *a;
    int rc = cdem_cmd_open_run(o, &a);
    if (rc)
        return rc;
    cdem_error err;
    size_t k;
    const cdem_state *s;
    if (cdem_analysis_find(a, o->increment, &k, &err) != CDEM_OK ||
        cdem_analysis_state(a, k, &s, &err) != CDEM_OK) {
        cdem_analysis_close(a);
        return cdem_cmd_fail(NULL, NULL, &err);
    }
    size_t idx = SIZE_MAX;
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == id)
            idx = i;
    const cdem_increment_info *in = cdem_analysis_info(a, k);
    if (idx == SIZE_MAX) {
        CDEM_FAIL(&err, CDEM_ERR_NOTFOUND, "element %ld is not in increment %d (%zu elements)", id,
                  (int)in->number, s->n);
        cdem_analysis_close(a);
        return cdem_cmd_fail(NULL, NULL, &err);
    }
    printf("element %ld at increment %d\n", id, (int)in->number);
    printf("  %-18s %.3f m\n  %-18s %.3f m\n  %-18s %.3f m\n  %-18s %d\n  %-18s %d\n", "x",
           s->x[idx], "y", s->y[idx], "radius", s->radius[idx], "layer", (int)s->layer[idx],
           "born (increment)", (int)s->born[idx]);
    printf("  %-18s%s%s%s\n", "kind", (s->flags[idx] & CDEM_FLAGS_BOUNDARY) ? " wall" : " free",
           (s->flags[idx] & CDEM_FLAG_GROWTH) ? " growth" : "",
           (s->flags[idx] & CDEM_FLAG_WEAK) ? " weak" : "");
    size_t nq;
    const cdem_quantity *t = cdem_quantity_table(&nq);
    const int has_stress = in->has_stress;
    for (size_t j = 0; j < nq; j++) {
        if (t[j].needs_stress && !has_stress)
            continue;
        if (cdem_analysis_from_equil(&t[j]) && !cdem_analysis_equil_known(a)) {
            printf("  %-18s not defined yet (measured from the end of equilibration, not "
                   "reached)\n",
                   t[j].name);
            continue;
        }
        double *v;
        if (cdem_analysis_values(a, k, &t[j], &s, &v, &err) != CDEM_OK) {
            cdem_analysis_close(a);
            return cdem_cmd_fail(NULL, NULL, &err);
        }
        /* the state pointer was refreshed: find the element again */
        for (size_t i = 0; i < s->n; i++)
            if (s->id[i] == id)
                idx = i;
        if (isfinite(v[idx]))
            printf("  %-18s %.6g %s\n", t[j].name, v[idx], t[j].unit);
        else
            printf("  %-18s undefined\n", t[j].name);
        free(v);
    }
    cdem_analysis_close(a);
    return CDEM_EXIT_OK;
}

static const char *const element_forms[] = {"RUN.h5 --increment K --element ID", NULL};
static const cdem_cli_option element_options[] = {
    {"--increment", "K|last|equil|first", "the increment"},
    {"--element", "ID", "the element's id (stable for the whole run)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain element",
    .forms = element_forms,
    .about = "Coordinates, radius, layer, birth increment and every applicable quantity of one "
             "element (the original program's option-click).",
    .options = element_options,
};

CDEM_SIMPLE_COMMAND(element, "element", "coordinates and every applicable value of one element", 1,
                    cmd_element);
