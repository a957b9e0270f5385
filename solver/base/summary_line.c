/* summary_line: see summary_line.h. */
#include "summary_line.h"

#include <stdarg.h>
#include <string.h>

/* Characters from the label's start to the value column. */
#define LABEL_WIDTH 28

void cdem_summary_line(FILE *f, const char *label, const char *fmt, ...) {
    fprintf(f, "  %s:%*s", label,
            (int)(LABEL_WIDTH - strlen(label)) > 1 ? (int)(LABEL_WIDTH - strlen(label)) : 1, "");
    va_list ap;
    va_start(ap, fmt);
    vfprintf(f, fmt, ap);
    va_end(ap);
    fputc('\n', f);
}
