/* summary_line: the layout of one line of the model summary (solver/run/summary.h),
 * "  label:" padded to a fixed column, then the value, so that every section reads alike,
 * the boundary modes' own lines (their describe hook, solver/modes/bc.h) too. Every number
 * carries its unit; nothing depends on the clock or the machine. Thread safety: writes only
 * to the given stream. */
#ifndef CDEM_SUMMARY_LINE_H
#define CDEM_SUMMARY_LINE_H

#include <stdio.h>

/* Writes "  label:" padded to the value column, the printf-formatted value and a newline. */
void cdem_summary_line(FILE *f, const char *label, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#endif
