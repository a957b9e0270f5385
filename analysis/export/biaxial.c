/* biaxial: see biaxial.h. */
#include "biaxial.h"

#include "outfile.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

cdem_status cdem_biaxial_write(const char *path, const cdem_series_sample *samples, size_t n,
                               cdem_error *err) {
    cdem_outfile of; /* written to path.tmp, renamed on success */
    FILE *f;
    CDEM_TRY(cdem_outfile_open_text(&of, path, &f, err));
    fprintf(f, "# time_step axial_strain differential_stress_N_per_m\n");
    for (size_t i = 0; i < n; i++)
        fprintf(f, "%lld %.9g %.9g\n", (long long)samples[i].step, samples[i].axial_strain,
                samples[i].differential_stress);
    return cdem_outfile_close_text(&of, f, CDEM_OK, err);
}
