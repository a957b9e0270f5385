#!/usr/bin/python3
"""The script a user would otherwise write: strain from neighbour least-squares fits with
numpy + scipy cKDTree + batched normal equations (no Python loop over elements).
Same states as bench/bench_strain_states.h; prints seconds and the same checksum as bench_strain.
"""
import sys
import time

import numpy as np
from scipy.spatial import cKDTree

def packing(ncol, nrow):
    c, r = np.meshgrid(np.arange(ncol), np.arange(nrow))
    c = c.ravel().astype(float)
    r = r.ravel().astype(float)
    d = 180.0
    dy = d * np.sqrt(3.0) / 2.0
    x = (c + 0.25 + 0.5 * (r % 2)) * d + 25.0 * np.sin(12.9898 * c + 78.233 * r)
    y = (r + 0.5) * dy + 25.0 * np.cos(39.3468 * c + 11.135 * r)
    radii = np.array([50.0, 75.0, 100.0, 125.0])[((c * 7 + r * 3) % 4).astype(int)]
    return x, y, radii

def deform(x, y, k):
    return (x + k * 1e-3 * (0.5 * y + 200.0 * np.sin(x / 1500.0)),
            y + k * 1e-3 * (100.0 * np.cos(y / 900.0) - 0.2 * x))

def strain(x0, y0, x1, y1, rmax):
    h = 2.0 * rmax
    tree = cKDTree(np.column_stack([x0, y0]))
    nb = tree.query_ball_point(np.column_stack([x0, y0]), h)
    lens = np.array([len(l) for l in nb])
    m = lens.max()
    idx = np.zeros((len(nb), m), dtype=int)
    mask = np.zeros((len(nb), m), dtype=bool)
    for i, l in enumerate(nb):
        idx[i, :len(l)] = l
        mask[i, :len(l)] = True
    X = (x0[idx] - x0[:, None]) * mask
    Y = (y0[idx] - y0[:, None]) * mask
    U = (x1 - x0)[idx] * mask
    V = (y1 - y0)[idx] * mask
    A = np.stack([mask.astype(float), X, Y], axis=-1)
    N = np.einsum('nki,nkj->nij', A, A)
    bu = np.einsum('nki,nk->ni', A, U)
    bv = np.einsum('nki,nk->ni', A, V)
    ok = (lens >= 3) & (np.abs(np.linalg.det(N)) > 0)
    N[~ok] = np.eye(3)
    su = np.linalg.solve(N, bu[..., None])[..., 0]
    sv = np.linalg.solve(N, bv[..., None])[..., 0]
    gxx, gxy, gyx, gyy = su[:, 1], su[:, 2], sv[:, 1], sv[:, 2]
    F = np.empty((len(x0), 2, 2))
    F[:, 0, 0] = 1 + gxx; F[:, 0, 1] = gxy; F[:, 1, 0] = gyx; F[:, 1, 1] = 1 + gyy
    C = np.einsum('nki,nkj->nij', F, F)
    lam = np.linalg.eigvalsh(C)
    l3, l1 = lam[:, 0], lam[:, 1]
    shear = (l1 - l3) / (2 * np.sqrt(l1 * l3))
    e1 = np.sqrt(l1) - 1
    e3 = 1 - np.sqrt(l3)
    dil = np.sqrt(l1 * l3) - 1
    rot = 0.5 * (gxy - gyx)
    shear[~ok] = np.nan
    return e1, e3, shear, dil, rot

def main():
    x0, y0, r = packing(250, 200)
    x1, y1 = deform(x0, y0, 50.0)
    best = 1e30
    for _ in range(3):
        t0 = time.perf_counter()
        res = strain(x0, y0, x1, y1, r.max())
        best = min(best, time.perf_counter() - t0)
    print("single %d elements seconds %.4f checksum %.10e" % (len(x0), best, np.nansum(res[2])))
    x0, y0, r = packing(100, 100)
    best = 1e30
    for _ in range(1):
        t = 0.0
        cum = np.zeros(len(x0))
        for k in range(1, 301):
            xa, ya = deform(x0, y0, k - 1)
            xb, yb = deform(x0, y0, k)
            t0 = time.perf_counter()
            res = strain(xa, ya, xb, yb, r.max())
            cum += np.nan_to_num(res[2])
            t += time.perf_counter() - t0
        best = min(best, t)
    print("cumulative %d elements 300 increments seconds %.4f checksum %.10e"
          % (len(x0), best, cum.sum()))

if __name__ == "__main__":
    sys.exit(main())
