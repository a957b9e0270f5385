/* biaxial: see biaxial.h. */
#include "biaxial.h"

#include "outfile.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

cdem_status cdem_biaxial_write(const char *path, const cdem_series_sample *samples, size_t n,
                               cdem_error *err) {
    cdem_outfile of; /* written to path.tmp, renamed on success */
    CDEM_TRY(cdem_outfile_begin(&of, path, err));
    FILE *f = fopen(of.tmp, "w");
    if (!f)
        return cdem_outfile_end(
            &of, CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: %s", of.tmp, strerror(errno)), err);
    fprintf(f, "# time_step axial_strain differential_stress_N_per_m\n");
    for (size_t i = 0; i < n; i++)
        fprintf(f, "%lld %.9g %.9g\n", (long long)samples[i].step, samples[i].axial_strain,
                samples[i].differential_stress);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return cdem_outfile_end(&of, CDEM_FAIL(err, CDEM_ERR_IO, "error writing %s", of.tmp), err);
    return cdem_outfile_end(&of, CDEM_OK, err);
}
