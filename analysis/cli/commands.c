/* commands: see commands.h. The general help's command list is built from the table at
 * print time, so a row added to the table is listed without another edit. */
#include "commands.h"

#include "cmd_basic.h"
#include "cmd_faults.h"
#include "cmd_plot.h"
#include "cmd_render.h"
#include "cmd_wedge.h"

#include <string.h>

static int cmd_help(int argc, char **argv);

static const char *const help_forms[] = {"[COMMAND]", NULL};
static const cdem_cli_option help_options[] = {{NULL, NULL, NULL}};
static const cdem_cli_help help_help = {
    .program = "cdem-strain help",
    .forms = help_forms,
    .about = "Without COMMAND the general help of cdem-strain; with COMMAND the usage, "
             "description and options of that command (the same as 'cdem-strain COMMAND "
             "--help').",
    .options = help_options,
};

static const cdem_command table[] = {
    {"info", cdem_cmd_info, &cdem_cmd_info_help, "summary, stop reason and the list of increments"},
    {"compute", cdem_cmd_compute, &cdem_cmd_compute_help,
     "per-element values of a quantity (CSV id,x,y,value, or HDF5)"},
    {"element", cdem_cmd_element, &cdem_cmd_element_help,
     "coordinates and every applicable value of one element"},
    {"limits", cdem_cmd_limits, &cdem_cmd_limits_help,
     "colour-bar limits of a quantity at an increment"},
    {"render", cdem_cmd_render, &cdem_cmd_render_help,
     "pictures of increments (PNG, PDF, SVG), albums and animated GIFs"},
    {"series", cdem_cmd_series, &cdem_cmd_series_help, "the time series as CSV"},
    {"plot-series", cdem_cmd_plot_series, &cdem_cmd_plot_series_help,
     "line plot of time-series columns"},
    {"mohr", cdem_cmd_plot_mohr, &cdem_cmd_mohr_help, "Mohr-Coulomb fit of biaxial tests"},
    {"repose", cdem_cmd_plot_repose, &cdem_cmd_repose_help, "angle of repose of the free surface"},
    {"voids", cdem_cmd_plot_voids, &cdem_cmd_voids_help,
     "steepest surface slope, voids and open fissures (cliffs, chasms, cavities)"},
    {"faults", cdem_cmd_faults, &cdem_cmd_faults_help,
     "fault zones from a strain field: position, dip and dip direction"},
    {"wedge", cdem_cmd_wedge, &cdem_cmd_wedge_help,
     "accretionary-wedge height, length, taper, area, forces"},
    {"plot-csv", cdem_cmd_plot_csv, &cdem_cmd_plot_csv_help,
     "curves of CSV columns, several files per panel"},
    {"export-sspx", cdem_cmd_export_sspx, &cdem_cmd_export_sspx_help,
     "one SSPX text file per increment"},
    {"export-biaxial", cdem_cmd_export_biaxial, &cdem_cmd_export_biaxial_help,
     "biaxial test series: time step, axial strain, differential stress"},
    {"import-cdem2d", cdem_cmd_import_cdem2d, &cdem_cmd_import_cdem2d_help,
     "convert a cdem2D simulation folder into a cdem file"},
    {"xdmf", cdem_cmd_xdmf, &cdem_cmd_xdmf_help,
     "(re)write the XDMF sidecar of a run or compute file for ParaView"},
    {"quantities", cdem_cmd_quantities, &cdem_cmd_quantities_help,
     "list every quantity name with unit and colour scale"},
    {"help", cmd_help, &help_help, "the general help, or the help of one command"},
};

const cdem_command *cdem_commands(size_t *n) {
    *n = sizeof table / sizeof table[0];
    return table;
}

const cdem_command *cdem_command_find(const char *name) {
    for (size_t k = 0; k < sizeof table / sizeof table[0]; k++)
        if (!strcmp(table[k].name, name))
            return &table[k];
    return NULL;
}

static const char *const strain_forms[] = {"COMMAND [ARGS]...",
                                           "RUN.h5 --increment K --quantity NAME [...]",
                                           "help [COMMAND]", "-V|--version | -h|--help", NULL};
static const cdem_cli_option strain_options[] = {
    {"-V, --version", NULL, "print the version and exit"}, {NULL, NULL, NULL}};

const cdem_cli_help cdem_strain_help = {
    .program = "cdem-strain",
    .forms = strain_forms,
    .about = "Analyses cdem-run results (and imported cdem2D simulations): displacement, "
             "incremental, total and cumulative strain, stress, principal axes and colour "
             "limits; pictures, plots and text exports. A run file as the first argument "
             "means compute. 'cdem-strain help COMMAND' or "
             "'cdem-strain COMMAND --help' shows a command's usage and options.",
    .rows_heading = "Commands",
    .options = strain_options,
    .notes = "Quantities, formulas and rules: docs/analysis.md; pictures: docs/rendering.md; "
             "text formats: docs/formats-text.md; the user guide: docs/guide.md.",
};

void cdem_commands_print_help(FILE *f) {
    cdem_cli_row rows[sizeof table / sizeof table[0] + 1];
    for (size_t k = 0; k < sizeof table / sizeof table[0]; k++)
        rows[k] = (cdem_cli_row){table[k].name, table[k].summary};
    rows[sizeof table / sizeof table[0]] = (cdem_cli_row){NULL, NULL};
    cdem_cli_help h = cdem_strain_help;
    h.rows = rows;
    cdem_cli_help_print(f, &h);
}

static int cmd_help(int argc, char **argv) {
    if (argc < 2) {
        cdem_commands_print_help(stdout);
        return 0;
    }
    const cdem_command *c = cdem_command_find(argv[1]);
    if (!c || argc > 2) {
        char msg[200];
        snprintf(msg, sizeof msg, c ? "one command at a time" : "unknown command '%.100s'",
                 argv[1]);
        cdem_cli_usage_print(stderr, &help_help, msg);
        return 2;
    }
    cdem_cli_help_print(stdout, c->help);
    return 0;
}
