/* cmd_render: the `cdem-strain render` subcommand: turns command-line options into a
 * cdem_render_scene/options pair per increment (values, limits, vectors, axes and the
 * label from the analysis context) and writes one picture, one picture per increment, or
 * an animated GIF. Its row of the command table is cdem_command_render (commands.h); this
 * header gives the picture label, which the tests check on their own.
 * Ownership: nothing outlives the call. Thread safety: one call at a time per process. */
#ifndef CDEM_CMD_RENDER_H
#define CDEM_CMD_RENDER_H

#include "analysis.h"

#include <stddef.h>

/* The label drawn above a picture of increment `index`: "Increment K   Net displacement X m"
 * (time for repose runs, axial strain for biaxial tests; the increment number alone for an
 * imported cdem2D run, whose folder gives no displacement). */
void cdem_render_increment_label(const cdem_analysis *an, size_t index, char *buf, size_t n);

#endif
