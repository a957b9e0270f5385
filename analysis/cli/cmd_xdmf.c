/* cmd_xdmf: `cdem-strain xdmf`; its help (below) says what it does. */
#include "cmd_options.h"

#include "qexport.h"
#include "xdmf.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>

/* 1 when path is a compute --format h5 file (root attribute "quantity"), 0 otherwise. */
static int is_quantity_file(const char *path) {
    int yes = 0;
    H5E_BEGIN_TRY {
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        if (f >= 0) {
            yes = H5Aexists(f, "quantity") > 0;
            H5Fclose(f);
        }
    }
    H5E_END_TRY;
    return yes;
}

static int cmd_xdmf(const cdem_cmd_options *o) {
    if (!o->file)
        return cdem_cmd_usage(o->help,
                              "xdmf needs the HDF5 file (RUN.h5, or a compute --format h5 file)");
    cdem_error err;
    char *own = o->out ? NULL : cdem_xdmf_path_for(o->file);
    const char *out = o->out ? o->out : own;
    const int want = o->xdmf2 ? CDEM_XDMF2 : CDEM_XDMF3;
    int written = 0;
    cdem_status st = !out ? CDEM_FAIL(&err, CDEM_ERR_NOMEM, "out of memory")
                     : is_quantity_file(o->file)
                         ? cdem_qexport_write_xdmf(o->file, out, want, &written, &err)
                         : cdem_h5_write_xdmf(o->file, out, want, &written, &err);
    if (st == CDEM_OK) {
        /* ./run.xmf, not run.xmf: the name as ParaView can open it (cdem_xdmf_open_prefix) */
        printf("%s%s\n", cdem_xdmf_open_prefix(out), out);
        if (written != want)
            fprintf(stderr,
                    "cdem-strain xdmf: note: %s has no xy view (written by an older version) "
                    "or a name with ':' or '|': wrote an XDMF 2 sidecar; ParaView opens it with "
                    "its legacy \"XDMF Reader\"\n",
                    o->file);
    }
    free(own);
    return st == CDEM_OK ? CDEM_EXIT_OK : cdem_cmd_fail(NULL, NULL, &err);
}

static const char *const xdmf_forms[] = {"FILE.h5 [-o OUT.xmf] [--xdmf2]", NULL};
static const cdem_cli_option xdmf_options[] = {
    {"-o, --output", "OUT.xmf",
     "the sidecar (default: next to FILE.h5, run.h5 -> run.xmf); it names FILE.h5 by its name "
     "when both are in one folder, else by its absolute path"},
    {"--xdmf2", NULL, "XDMF 2 instead of 3, for VisIt and ParaView's legacy \"XDMF Reader\""},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain xdmf",
    .forms = xdmf_forms,
    .about = "Writes the XDMF sidecar that lets ParaView (and VisIt, with --xdmf2) open a run "
             "file or a compute --format h5 file: after renaming or moving the file, or for "
             "the other flavour. cdem-run and compute write one themselves (docs/format.md, "
             "\"XDMF sidecar\"). Prints the sidecar's name as ParaView opens it: ./run.xmf, "
             "not run.xmf (ParaView 5.11's Xdmf3 reader aborts on a bare name).",
    .options = xdmf_options,
};

CDEM_SIMPLE_COMMAND(xdmf, "xdmf",
                    "(re)write the XDMF sidecar of a run or compute file for ParaView", 1,
                    cmd_xdmf);
