/* stress: see stress.h. One pass over the elements; each walks its CSR slots. */
#include "stress.h"

#include <math.h>

cdem_status cdem_stress_compute(const cdem_neighbour *nb, cdem_state *s, cdem_error *err) {
    CDEM_TRY(cdem_state_enable_stress(s, err));
    if (nb->n != s->n || nb->n_builds == 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "stress: the pair list (%zu elements) does not match the state (%zu "
                         "elements); compute forces first",
                         nb->n, s->n);
    const long n = (long)s->n;
    const double *restrict x = s->x, *restrict y = s->y, *restrict rad = s->radius;
    double *restrict sxx = s->sxx, *restrict syy = s->syy, *restrict sxy = s->sxy;
#pragma omp parallel for schedule(static) if (n > 2048)
    for (long i = 0; i < n; i++) {
        double axx = 0.0, ayy = 0.0, axy = 0.0, ayx = 0.0;
        /* side 0: slots where i is pi (force on i as stored); side 1: where i is pj */
        for (int side = 0; side < 2; side++) {
            const int32_t e0 = side ? nb->jstart[i] : nb->istart[i];
            const int32_t e1 = side ? nb->jstart[i + 1] : nb->istart[i + 1];
            for (int32_t e = e0; e < e1; e++) {
                const int32_t p = side ? nb->jslot[e] : e;
                double fx = nb->pfx[p], fy = nb->pfy[p];
                if (fx == 0.0 && fy == 0.0)
                    continue;
                const int32_t j = side ? nb->pi[p] : nb->pj[p];
                if (side) {
                    fx = -fx;
                    fy = -fy;
                }
                const double dx = x[j] - x[i], dy = y[j] - y[i];
                const double r = sqrt(dx * dx + dy * dy);
                if (!(r > 0.0))
                    continue;
                const double delta = nb->R[p] - r;
                const double len = rad[i] - 0.5 * delta;
                const double bx = dx / r * len, by = dy / r * len;
                axx += bx * fx;
                ayy += by * fy;
                axy += bx * fy;
                ayx += by * fx;
            }
        }
        const double area = M_PI * rad[i] * rad[i];
        sxx[i] = -axx / area;
        syy[i] = -ayy / area;
        sxy[i] = -0.5 * (axy + ayx) / area;
    }
    return CDEM_OK;
}
