/* xdmf: the XDMF sidecars that let ParaView and VisIt read cdem HDF5 files (run.xmf, the
 * .xmf of a compute --format h5 file). XDMF 3 (default; ParaView's Xdmf3 readers): every data
 * item is an HDF5 reference with its hyperslab in the text ("f.h5:/ds|start:stride:count:
 * dataspace") and the dataset's NumberType/Precision, because VTK's Xdmf3 reader types an
 * array before reading it and HyperSlab/Function items (XDMF 2's way, and X_Y geometry) have
 * no type then: ParaView 5.11 skipped them and crashed. The geometry is XY from an n x 2 HDF5
 * virtual dataset over x and y (cdem_xdmf_create_xy_view, no storage); the Polyvertex
 * topology is a HyperSlab of one shared inline list 0..N-1 (XInclude; topology is read before
 * its type is asked). XDMF 2 (--xdmf2; VisIt, ParaView's legacy reader): HyperSlabs of the
 * ragged datasets, X_Y geometry. References are relative to the sidecar's folder, else
 * absolute. docs/format.md, "XDMF sidecar", is the authority. Library code: never prints.
 * Ownership: the caller owns everything passed in. Thread safety: no state. */
#ifndef CDEM_XDMF_H
#define CDEM_XDMF_H

#include "cdem_error.h"

#include <hdf5.h>
#include <stdio.h>

typedef enum {
    CDEM_XDMF3 = 3, /* ParaView's default readers */
    CDEM_XDMF2 = 2, /* legacy readers (ParaView "XDMF Reader", VisIt) */
} cdem_xdmf_flavour;

/* Rows offset .. offset+n-1 of a 1-D dataset of `extent` rows (or of an extent x 2 one). */
typedef struct {
    const char *dataset;     /* path in the HDF5 file, e.g. "/increments/radius" */
    long long offset;        /* first row */
    long long extent;        /* rows of the dataset when written (>= offset + n) */
    const char *number_type; /* "Float", "Int", "UInt" */
    int precision;           /* bytes per value: 4 or 8 */
} cdem_xdmf_data;

#define CDEM_XDMF_MAX_ATTRIBUTES 16

/* One time step: n points with coordinates and point attributes. */
typedef struct {
    int number;        /* increment number (the grid is named increment_NNNNNN) */
    double time;       /* the time value of the step */
    long long n;       /* points; a grid with none is left out (an empty grid is invalid) */
    cdem_xdmf_data x;  /* XDMF 2: the x coordinates */
    cdem_xdmf_data y;  /* XDMF 2: the y coordinates */
    cdem_xdmf_data xy; /* XDMF 3: the n x 2 coordinates (x, y) */
    size_t n_attributes;
    const char *attribute_names[CDEM_XDMF_MAX_ATTRIBUTES];
    cdem_xdmf_data attributes[CDEM_XDMF_MAX_ATTRIBUTES];
} cdem_xdmf_grid;

/* A sidecar: h5_ref is how the sidecar names the HDF5 file (cdem_xdmf_reference); grid(ctx,
 * k, g) fills step k (0 <= k < n_grids; g is zeroed first) and returns 0, or -1 to fail. */
typedef struct {
    const char *h5_ref;
    cdem_xdmf_flavour flavour;
    size_t n_grids;
    int (*grid)(void *ctx, size_t k, cdem_xdmf_grid *g);
    void *ctx;
} cdem_xdmf_doc;

/* Writes the sidecar to xmf_path through xmf_path.tmp, renamed over it, so a reader never
 * sees half a sidecar. CDEM_ERR_IO naming the file when it cannot be written. */
cdem_status cdem_xdmf_write_file(const char *xmf_path, const cdem_xdmf_doc *doc, cdem_error *err);

/* The same to an open stream (no rename); -1 on a write error or a failed grid callback. */
int cdem_xdmf_write(FILE *f, const cdem_xdmf_doc *doc);

/* How a sidecar at xmf_path refers to the HDF5 file h5_path: its base name when both are in
 * the same folder, else its absolute path (realpath). Into buf; CDEM_ERR_* naming the file
 * when h5_path cannot be resolved. */
cdem_status cdem_xdmf_reference(const char *h5_path, const char *xmf_path, char *buf, size_t cap,
                                cdem_error *err);

/* "dir/run.h5" -> "dir/run.xmf" (".h5"/".hdf5"/".hdf" replaced, otherwise ".xmf" appended),
 * malloc'd; NULL when out of memory. */
char *cdem_xdmf_path_for(const char *h5_path);

/* What to put before a sidecar's path when showing it to a user who will open it in
 * ParaView: "./" for a bare name ("run.xmf"), "" for a path with a folder part. ParaView
 * 5.11's Xdmf3 reader resolves the heavy-data reference of a bare name as "run.xmfrun.h5"
 * and aborts (pvpython's OpenDataFile("run.xmf")); "./run.xmf" and absolute paths work
 * (tests/validate/check_paraview.py checks both forms). */
const char *cdem_xdmf_open_prefix(const char *xmf_path);

/* Creates the virtual dataset loc/xy_name of rows x 2 doubles whose columns are the 1-D
 * datasets x_name and y_name (absolute paths) of the same file (HDF5 VDS, no storage). unlimited:
 * the view follows the sources as they grow (the run file's extendible x and y); otherwise it has
 * their current length. Object time stamps off (deterministic bytes). Returns the dataset
 * (close it) or a negative id. */
hid_t cdem_xdmf_create_xy_view(hid_t loc, const char *x_name, const char *y_name,
                               const char *xy_name, int unlimited);

#endif
