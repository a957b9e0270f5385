"""The comparisons of tests/validate/kill_campaign.sh (docs/reliability.md, "Round four
(issue 46)", "Audit re-run"), with h5py and numpy only:

  kill_campaign.py committed KILLED STRAIGHT INFO_JSON
      The committed increments of a killed run's file: the rows of /increments/commit whose
      FNV-1a 64 checksum (of the 84 bytes of members and the row number, docs/format.md,
      "/increments/commit") matches, read from the file's bytes; their number must equal
      `cdem-strain info --json`'s increment_count (INFO_JSON, its output), and each must
      read back identical to the straight run's increment of the same number: every member
      of its row but offset and stress_offset (where the rows sit may differ: a completed
      run's file is compacted) and every element dataset's rows, bit for bit. The series
      must be a prefix of the straight run's. Prints "committed C identical I series S" and,
      for each difference, a line naming it; exit 0 when C == I, the count agrees and the
      series is a prefix, 1 otherwise.

  kill_campaign.py same A B [--ignore-checkpoint]
      A and B are the same run file: the same objects, every attribute (the root attribute
      `created` left out) and every dataset (type, shape, bytes) equal. With
      --ignore-checkpoint, /checkpoint is left out (a file whose writer was killed while it
      compacted the completed run keeps its checkpoints, docs/format.md "Completed runs").
      Prints "same" or the differences; exit 0 when the same, 1 otherwise.
"""
import json
import struct
import sys

import h5py
import numpy as np

ROW = 92
FNV_OFFSET, FNV_PRIME, MASK = 0xCBF29CE484222325, 0x100000001B3, (1 << 64) - 1
ROW_FMT = "<iqdiddddqqiq"  # number step time phase net axial diff sea offset n has_stress soff
NAMES = ("number", "step", "time", "phase", "net_displacement", "axial_strain",
         "differential_stress", "sea_level", "offset", "n", "has_stress", "stress_offset")
STRESS = ("sxx", "syy", "sxy")


def fnv1a64(data):
    h = FNV_OFFSET
    for b in data:
        h = ((h ^ b) * FNV_PRIME) & MASK
    return h


def open_run(path):
    """A closed file as it is; a killed writer's file with SWMR read (docs/format.md)."""
    try:
        return h5py.File(path, "r")
    except OSError:
        return h5py.File(path, "r", swmr=True)


def commit_rows(path):
    """The valid rows of the commit record, in order, read from the file's own bytes (the
    dataset is contiguous), and the number of rows that are neither valid nor all zeros."""
    with open_run(path) as f:
        ds = f["increments/commit"]
        at, rows = ds.id.get_offset(), ds.shape[0]
    with open(path, "rb") as raw:
        raw.seek(at)
        data = raw.read(rows * ROW)
    valid, other = [], 0
    for r in range(rows):
        b = data[r * ROW:(r + 1) * ROW]
        if len(b) < ROW:
            other += 1
            continue
        (check,) = struct.unpack_from("<Q", b, 84)
        if fnv1a64(b[:84] + struct.pack("<q", r)) == check:
            valid.append(dict(zip(NAMES, struct.unpack_from(ROW_FMT, b, 0))))
        elif any(b):
            other += 1
    return valid, other


def element_names(f):
    g = f["increments"]
    return sorted(k for k in g if k not in ("commit", "index") and isinstance(g[k], h5py.Dataset))


def increment_data(f, row, name):
    off = row["stress_offset"] if name in STRESS else row["offset"]
    if name in STRESS and not row["has_stress"]:
        return None
    return np.asarray(f["increments"][name][off:off + row["n"]])


def committed(killed, straight, info_json):
    problems = []
    rows, other = commit_rows(killed)
    ref_rows, _ = commit_rows(straight)
    ref = {r["number"]: r for r in ref_rows}
    info = json.load(open(info_json))
    if info.get("increment_count") != len(rows):
        problems.append("cdem-strain info lists %s increments, the commit record has %d valid "
                        "rows" % (info.get("increment_count"), len(rows)))
    if other > 1:  # a killed writer may leave one torn row after the valid ones
        problems.append("%d commit rows are neither valid nor blank" % other)
    if info.get("damage"):
        problems.append("damage reported: %s" % info["damage"])
    same = 0
    with open_run(killed) as f, open_run(straight) as g:
        names = element_names(g)
        if element_names(f) != names:
            problems.append("element datasets %s, straight run %s" % (element_names(f), names))
        for k, row in enumerate(rows):
            r = ref.get(row["number"])
            what = []
            if row["number"] != k:
                what.append("row %d holds increment %d" % (k, row["number"]))
            if r is None:
                what.append("the straight run has no increment %d" % row["number"])
            else:
                for m in NAMES:
                    if m in ("offset", "stress_offset"):
                        continue
                    if isinstance(row[m], float):  # bit for bit (NaN sea level included)
                        differs = struct.pack("<d", row[m]) != struct.pack("<d", r[m])
                    else:
                        differs = row[m] != r[m]
                    if differs:
                        what.append("%s %r, straight %r" % (m, row[m], r[m]))
                for name in names:
                    a, b = increment_data(f, row, name), increment_data(g, r, name)
                    if (a is None) != (b is None) or (a is not None and (
                            a.dtype != b.dtype or a.shape != b.shape or a.tobytes() != b.tobytes())):
                        what.append("dataset %s differs" % name)
            if what:
                problems.append("increment %d: %s" % (row["number"], "; ".join(what)))
            else:
                same += 1
        sa, sb = f["series"], g["series"]
        prefix = "yes"
        if sorted(sa) != sorted(sb):
            prefix = "no"
            problems.append("series columns differ")
        else:
            for c in sa:
                a, b = np.asarray(sa[c][:]), np.asarray(sb[c][:])
                if len(a) > len(b) or a.tobytes() != b[:len(a)].tobytes():
                    prefix = "no"
                    problems.append("series/%s (%d samples) is not a prefix of the straight "
                                    "run's (%d)" % (c, len(a), len(b)))
                    break
        samples = len(sa["step"]) if "step" in sa else 0
    print("committed %d identical %d series %s (%d samples)" % (len(rows), same, prefix, samples))
    for p in problems:
        print("  " + p)
    return 0 if not problems else 1


def attrs_differ(a, b, where, skip=()):
    out = []
    ka, kb = set(a.keys()) - set(skip), set(b.keys()) - set(skip)
    if ka != kb:
        out.append("%s: attributes only in the first %s, only in the second %s"
                   % (where, sorted(ka - kb), sorted(kb - ka)))
    for k in sorted(ka & kb):
        va, vb = a[k], b[k]
        if isinstance(va, np.ndarray) or isinstance(vb, np.ndarray):
            va, vb = np.asarray(va), np.asarray(vb)
            eq = va.dtype == vb.dtype and va.shape == vb.shape and va.tobytes() == vb.tobytes()
        else:
            eq = type(va) == type(vb) and (va == vb or (va != va and vb != vb))
            if isinstance(va, (np.floating, float)):
                eq = np.float64(va).tobytes() == np.float64(vb).tobytes()
        if not eq:
            out.append("%s: attribute %s differs" % (where, k))
    return out


def same(pa, pb, ignore_checkpoint):
    problems = []
    with open_run(pa) as a, open_run(pb) as b:
        problems += attrs_differ(a.attrs, b.attrs, "/", skip=("created",))
        objs = []
        a.visit(objs.append)
        other = []
        b.visit(other.append)
        if ignore_checkpoint:
            objs = [o for o in objs if not o.startswith("checkpoint")]
            other = [o for o in other if not o.startswith("checkpoint")]
        if sorted(objs) != sorted(other):
            problems.append("objects differ: %s" % sorted(set(objs) ^ set(other)))
        for name in sorted(set(objs) & set(other)):
            oa, ob = a[name], b[name]
            if type(oa) != type(ob):
                problems.append("/%s: a %s and a %s" % (name, type(oa).__name__, type(ob).__name__))
                continue
            problems += attrs_differ(oa.attrs, ob.attrs, "/" + name)
            if isinstance(oa, h5py.Dataset):
                if oa.dtype != ob.dtype or oa.shape != ob.shape:
                    problems.append("/%s: type or shape differs (%s %s, %s %s)"
                                    % (name, oa.dtype, oa.shape, ob.dtype, ob.shape))
                    continue
                va, vb = oa[()], ob[()]
                if isinstance(va, np.ndarray):
                    eq = va.tobytes() == vb.tobytes() if va.dtype.kind != "O" \
                        else list(va.ravel()) == list(vb.ravel())
                else:
                    eq = va == vb
                if not eq:
                    problems.append("/%s: data differs" % name)
    print("same" if not problems else "different")
    for p in problems:
        print("  " + p)
    return 0 if not problems else 1


def main(argv):
    if len(argv) == 5 and argv[1] == "committed":
        return committed(argv[2], argv[3], argv[4])
    if len(argv) in (4, 5) and argv[1] == "same" and argv[4:] in ([], ["--ignore-checkpoint"]):
        return same(argv[2], argv[3], len(argv) == 5)
    sys.stderr.write(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
