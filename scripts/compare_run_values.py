#!/usr/bin/python3
"""Compares two cdem run files (version 2) value by value, whatever their HDF5 layout:
every increment's element rows (bitwise), the index (except the row offsets, which depend on
the chunk size), the series, the parameters, the stop reason, the root attributes except
'created', and the checkpoints' blobs (decoded from any packing: bare, CDEMSNPZ, CDEMSNPT).
For changes of the file layout, where h5diff cannot compare the element datasets (their
shapes differ) and scripts/refactor_guard.sh reports every run file as different.

usage: compare_run_values.py REF.h5 NEW.h5 [REF_ROOT NEW_ROOT]
    REF_ROOT/NEW_ROOT: a folder name that may differ in texts (parameter paths), e.g.
    /work/main /work/wt-x when the guard ran in a worktree. Exit status 1 on a difference."""
import sys, zlib, struct, h5py, numpy as np
def blob(f, s):
    row = f["checkpoint/index"][s]
    b = bytes(f["checkpoint/slot%d" % s][:row["length"]])
    if b[:8] == b"CDEMSNAP": return b, row
    raw = bytearray(zlib.decompress(b[16:]))
    if b[:8] == b"CDEMSNPT":
        at = 24; cnt = struct.unpack("<I", raw[12:16])[0]; sz = {0: 8, 1: 8, 2: 4, 3: 4, 4: 1}
        for _ in range(cnt):
            nl = struct.unpack("<H", raw[at:at+2])[0]; at += 2 + nl
            t = raw[at]; n = struct.unpack("<Q", raw[at+1:at+9])[0]; size = sz[t & 0x7f]
            v = bytes(raw[at+9:at+9+n*size])
            if t & 0x80:
                raw[at] = t & 0x7f
                raw[at+9:at+9+n*size] = np.frombuffer(v, np.uint8).reshape(size, n).T.copy().tobytes()
            at += 9 + n*size
    else: assert b[:8] == b"CDEMSNPZ"
    return bytes(raw), row
a, b = h5py.File(sys.argv[1], "r"), h5py.File(sys.argv[2], "r")
# texts may name another folder (REF_ROOT NEW_ROOT)
ROOTS = [r.encode() for r in sys.argv[3:5]] if len(sys.argv) >= 5 else None
NORM = lambda x: x.replace(ROOTS[1], ROOTS[0]) if ROOTS and isinstance(x, bytes) else x
def arrays(blob):
    at = 24; cnt = struct.unpack("<I", blob[12:16])[0]; out = {}
    for _ in range(cnt):
        nl = struct.unpack("<H", blob[at:at+2])[0]; name = blob[at+2:at+2+nl]; at += 2 + nl
        t = blob[at]; n = struct.unpack("<Q", blob[at+1:at+9])[0]; size = {0: 8, 1: 8, 2: 4, 3: 4, 4: 1}[t]
        out[name] = (t, NORM(bytes(blob[at+9:at+9+n*size]))); at += 9 + n*size
    return out
bad = 0
ia, ib = a["increments/index"][:], b["increments/index"][:]
assert len(ia) == len(ib)
for name in ia.dtype.names:
    if name in ("offset", "stress_offset"): continue
    if not np.array_equal(ia[name], ib[name], equal_nan=name == "sea_level"): print("index", name, "differs"); bad += 1
fields = [k for k in a["increments"].keys() if k not in ("index", "xy")]
rows = 0
for k in range(len(ia)):
    for fld in fields:
        off_a = ia[k]["stress_offset"] if fld.startswith("s") else ia[k]["offset"]
        off_b = ib[k]["stress_offset"] if fld.startswith("s") else ib[k]["offset"]
        if fld.startswith("s") and not ia[k]["has_stress"]: continue
        n = ia[k]["n"]
        va, vb = a["increments/" + fld][off_a:off_a+n], b["increments/" + fld][off_b:off_b+n]
        if va.tobytes() != vb.tobytes(): print("increment", k, fld, "differs"); bad += 1
        rows += n
for grp in ("series",):
    for c in a[grp]:
        if a[grp][c][:].tobytes() != b[grp][c][:].tobytes(): print(grp, c, "differs"); bad += 1
for d in ("parameters", "stop_reason", "stop_detail"):
    va, vb = a[d][()], b[d][()]
    if va.dtype.names: va, vb = [tuple(NORM(x) for x in r) for r in va], [tuple(NORM(x) for x in r) for r in vb]
    else: va, vb = NORM(va.tobytes()), NORM(vb.tobytes())
    if va != vb: print(d, "differs"); bad += 1
for at in a.attrs:
    if at != "created" and NORM(a.attrs[at]) != NORM(b.attrs[at]): print("attr", at, "differs"); bad += 1
for s in (0, 1):
    if a["checkpoint/index"][s]["sequence"] == 0 and b["checkpoint/index"][s]["sequence"] == 0: continue
    (ba, ra), (bb, rb) = blob(a, s), blob(b, s)
    same = ba == bb or arrays(ba) == arrays(bb)
    if not same or ra["sequence"] != rb["sequence"] or ra["increment"] != rb["increment"] or ra["step"] != rb["step"]:
        print("checkpoint slot", s, "differs"); bad += 1
print(f"{len(ia)} increments, {rows} element values, {len(a['series'])} series columns, 2 checkpoint blobs: {bad} differences")
sys.exit(1 if bad else 0)
