/* cmd_import_cdem2d: `cdem-strain import-cdem2d`; its help (below) says what it does. */
#include "cmd_options.h"

#include "cdem2d.h"

#include <stdio.h>

static int cmd_import_cdem2d(const cdem_cmd_options *o) {
    if (!o->file)
        return cdem_cmd_usage(o->help, "import-cdem2d needs the cdem2D folder");
    if (!o->out)
        return cdem_cmd_usage(o->help, "import-cdem2d needs -o OUT.h5");
    cdem_error err;
    if (cdem_cdem2d_import_h5(o->file, o->out, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err);
    return CDEM_EXIT_OK;
}

static const char *const import_forms[] = {"DIR -o OUT.h5", NULL};
static const cdem_cli_option import_options[] = {
    {"-o, --output", "OUT.h5", "the cdem file to write (with its .xmf sidecar)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain import-cdem2d",
    .forms = import_forms,
    .about = "Converts a cdem2D simulation folder (modelresults_N.txt, optional "
             "modelforces_N.txt and modelparameters.txt) into a cdem file that every other "
             "command reads (docs/formats-text.md).",
    .options = import_options,
};

CDEM_SIMPLE_COMMAND(import_cdem2d, "import-cdem2d",
                    "convert a cdem2D simulation folder into a cdem file", 1, cmd_import_cdem2d);
