/* biaxial: see biaxial.h. */
#include "biaxial.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

cdem_status cdem_biaxial_write(const char *path, const cdem_series_sample *samples, size_t n,
                               cdem_error *err) {
    FILE *f = fopen(path, "w");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot create %s: %s", path, strerror(errno));
    fprintf(f, "# time_step axial_strain differential_stress_N_per_m\n");
    for (size_t i = 0; i < n; i++)
        fprintf(f, "%lld %.9g %.9g\n", (long long)samples[i].step, samples[i].axial_strain,
                samples[i].differential_stress);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return CDEM_FAIL(err, CDEM_ERR_IO, "error writing %s", path);
    return CDEM_OK;
}
