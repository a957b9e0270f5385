"""Reads the increments of a cdem-c run file of format version 1 or 2 (docs/format.md) with
h5py, in a form the validation scripts share:

    import cdemfile
    incs = cdemfile.increments(f)      # sorted by number
    incs[-1].attrs["net_displacement"], incs[-1]["x"]    # numpy arrays
    cdemfile.stop_reason(f)            # str
"""
import numpy as np


class Increment:
    """One increment: .attrs (number, step, time, phase, net_displacement, axial_strain,
    differential_stress, sea_level, n) and element arrays by name (id, x, y, ...)."""

    def __init__(self, f, attrs, group=None, offset=0, stress_offset=-1):
        self._f, self.attrs, self._g = f, attrs, group
        self._off, self._soff = offset, stress_offset

    def __getitem__(self, name):
        if self._g is not None:
            return np.asarray(self._g[name][:])
        n = int(self.attrs["n"])
        off = self._soff if name in ("sxx", "syy", "sxy") else self._off
        if off < 0:
            raise KeyError("increment %d has no %s" % (self.attrs["number"], name))
        return np.asarray(self._f["increments"][name][off:off + n])


def increments(f):
    if int(f.attrs["format_version"]) == 1:
        out = [Increment(f, dict(g.attrs), group=g) for g in f["increments"].values()]
    else:
        out = []
        for row in f["increments"]["index"][:]:
            attrs = {k: row[k].item() for k in row.dtype.names}
            out.append(Increment(f, attrs, offset=int(row["offset"]),
                                 stress_offset=int(row["stress_offset"]) if row["has_stress"] else -1))
    return sorted(out, key=lambda i: int(i.attrs["number"]))


def stop_reason(f):
    v = f.attrs["stop_reason"] if "stop_reason" in f.attrs else f["stop_reason"][()]
    return v.decode() if isinstance(v, bytes) else str(v)
