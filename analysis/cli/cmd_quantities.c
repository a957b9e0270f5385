/* cmd_quantities: `cdem-strain quantities`; its help (below) says what it does. */
#include "cmd_options.h"

#include "quantity.h"

#include <stdio.h>

static int cmd_quantities(const cdem_cmd_options *o) {
    (void)o;
    size_t n;
    const cdem_quantity *t = cdem_quantity_table(&n);
    for (size_t i = 0; i < n; i++)
        printf("%-18s %-5s %-9s %s%s\n", t[i].name, t[i].unit[0] ? t[i].unit : "-",
               t[i].scale == CDEM_SCALE_SIGNED ? "signed" : "magnitude", t[i].label,
               t[i].needs_stress ? " (needs stress)" : "");
    return CDEM_EXIT_OK;
}

static const char *const quantities_forms[] = {"", NULL};
static const cdem_cli_option quantities_options[] = {{NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain quantities",
    .forms = quantities_forms,
    .about = "Lists every quantity name with its unit, colour scale and label; those marked "
             "\"needs stress\" need a run with physics.calculate_stress = on.",
    .options = quantities_options,
};

CDEM_SIMPLE_COMMAND(quantities, "quantities", "list every quantity name with unit and colour scale",
                    1, cmd_quantities);
