/* xdmf: see xdmf.h. The sidecar is text generated from the callback's grids; the only HDF5
 * work here is creating the xy view. */
#include "xdmf.h"

#include "outfile.h"

#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

static void xml_escaped(FILE *f, const char *s) {
    for (; *s; s++) {
        switch (*s) {
        case '&':
            fputs("&amp;", f);
            break;
        case '<':
            fputs("&lt;", f);
            break;
        case '>':
            fputs("&gt;", f);
            break;
        case '"':
            fputs("&quot;", f);
            break;
        default:
            fputc(*s, f);
        }
    }
}

/* XDMF 3: one HDF5 reference with the hyperslab in the text; a 2-D view (xy) when two. */
static void item3(FILE *f, const char *ref, const cdem_xdmf_data *d, long long n, int columns) {
    if (columns == 2)
        fprintf(f, "        <DataItem Dimensions=\"%lld 2\" ", n);
    else
        fprintf(f, "        <DataItem Dimensions=\"%lld\" ", n);
    fprintf(f, "NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">", d->number_type, d->precision);
    xml_escaped(f, ref);
    fprintf(f, ":%s|", d->dataset);
    if (columns == 2)
        fprintf(f, "%lld 0:1 1:%lld 2:%lld 2</DataItem>\n", d->offset, n, d->extent);
    else
        fprintf(f, "%lld:1:%lld:%lld</DataItem>\n", d->offset, n, d->extent);
}

/* XDMF 2: a HyperSlab (start, stride, count) of the whole dataset. */
static void item2(FILE *f, const char *ref, const cdem_xdmf_data *d, long long n) {
    fprintf(f,
            "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"%lld\" Type=\"HyperSlab\">\n"
            "          <DataItem Dimensions=\"3 1\" Format=\"XML\">%lld 1 %lld</DataItem>\n"
            "          <DataItem Dimensions=\"%lld\" NumberType=\"%s\" Precision=\"%d\" "
            "Format=\"HDF\">",
            n, d->offset, n, d->extent, d->number_type, d->precision);
    xml_escaped(f, ref);
    fprintf(f, ":%s</DataItem>\n        </DataItem>\n", d->dataset);
}

int cdem_xdmf_write(FILE *f, const cdem_xdmf_doc *doc) {
    const int v3 = doc->flavour == CDEM_XDMF3;
    fprintf(f,
            "<?xml version=\"1.0\" ?>\n"
            "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
            "<Xdmf Version=\"%s\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
            "  <Domain>\n",
            v3 ? "3.0" : "2.0");
    if (v3) {
        /* the vertex list 0..N-1 (N = the most points of any grid), shared by every grid */
        long long most = 0;
        for (size_t k = 0; k < doc->n_grids; k++) {
            cdem_xdmf_grid g;
            memset(&g, 0, sizeof g);
            if (doc->grid(doc->ctx, k, &g) != 0)
                return -1;
            most = g.n > most ? g.n : most;
        }
        fprintf(f,
                "    <DataItem Name=\"vertices\" Dimensions=\"%lld\" NumberType=\"Int\" "
                "Precision=\"4\" Format=\"XML\">",
                most > 0 ? most : 1);
        for (long long i = 0; i < (most > 0 ? most : 1); i++)
            fprintf(f, i % 20 == 19 ? "%lld\n" : "%lld ", i);
        fputs("</DataItem>\n", f);
    }
    fputs("    <Grid Name=\"increments\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
          f);
    for (size_t k = 0; k < doc->n_grids; k++) {
        cdem_xdmf_grid g;
        memset(&g, 0, sizeof g);
        if (doc->grid(doc->ctx, k, &g) != 0)
            return -1;
        if (g.n <= 0)
            continue; /* an empty grid has no geometry; viewers reject it */
        fprintf(f, "    <Grid Name=\"increment_%06d\" GridType=\"Uniform\">\n", g.number);
        fprintf(f, "      <Time Value=\"%.17g\"/>\n", g.time);
        if (v3) {
            fprintf(f,
                    "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%lld\" "
                    "NodesPerElement=\"1\">\n"
                    "        <DataItem ItemType=\"HyperSlab\" Dimensions=\"%lld\" "
                    "Type=\"HyperSlab\">\n"
                    "          <DataItem Dimensions=\"3 1\" Format=\"XML\">0 1 %lld</DataItem>\n"
                    "          <xi:include xpointer=\"xpointer(/Xdmf/Domain/DataItem[@Name="
                    "&quot;vertices&quot;])\"/>\n"
                    "        </DataItem>\n"
                    "      </Topology>\n",
                    g.n, g.n, g.n);
            fputs("      <Geometry GeometryType=\"XY\">\n", f);
            item3(f, doc->h5_ref, &g.xy, g.n, 2);
        } else {
            fprintf(f,
                    "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%lld\" "
                    "NodesPerElement=\"1\"/>\n",
                    g.n);
            fputs("      <Geometry GeometryType=\"X_Y\">\n", f);
            item2(f, doc->h5_ref, &g.x, g.n);
            item2(f, doc->h5_ref, &g.y, g.n);
        }
        fputs("      </Geometry>\n", f);
        for (size_t a = 0; a < g.n_attributes && a < CDEM_XDMF_MAX_ATTRIBUTES; a++) {
            fputs("      <Attribute Name=\"", f);
            xml_escaped(f, g.attribute_names[a]);
            fputs("\" AttributeType=\"Scalar\" Center=\"Node\">\n", f);
            if (v3)
                item3(f, doc->h5_ref, &g.attributes[a], g.n, 1);
            else
                item2(f, doc->h5_ref, &g.attributes[a], g.n);
            fputs("      </Attribute>\n", f);
        }
        fputs("    </Grid>\n", f);
    }
    fputs("    </Grid>\n  </Domain>\n</Xdmf>\n", f);
    return ferror(f) ? -1 : 0;
}

cdem_status cdem_xdmf_write_file(const char *xmf_path, const cdem_xdmf_doc *doc, cdem_error *err) {
    size_t len = strlen(xmf_path);
    char *tmp = malloc(len + 5);
    if (!tmp)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the sidecar name %s", xmf_path);
    snprintf(tmp, len + 5, "%s.tmp", xmf_path);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        cdem_status st = CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot create the XDMF sidecar: %s", tmp,
                                   strerror(errno));
        free(tmp);
        return st;
    }
    int bad = cdem_xdmf_write(f, doc) != 0;
    if (fclose(f) != 0 || bad) {
        remove(tmp);
        free(tmp);
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot write the XDMF sidecar (disk full?)",
                         xmf_path);
    }
    if (rename(tmp, xmf_path) != 0) {
        int e = errno;
        remove(tmp);
        cdem_status st = CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot rename %s to it: %s", xmf_path,
                                   tmp, strerror(e));
        free(tmp);
        return st;
    }
    free(tmp);
    return CDEM_OK;
}

cdem_status cdem_xdmf_reference(const char *h5_path, const char *xmf_path, char *buf, size_t cap,
                                cdem_error *err) {
    char hdir[PATH_MAX], xdir[PATH_MAX], hreal[PATH_MAX], xreal[PATH_MAX];
    cdem_outfile_folder_of(h5_path, hdir, sizeof hdir);
    cdem_outfile_folder_of(xmf_path, xdir, sizeof xdir);
    const char *slash = strrchr(h5_path, '/');
    const char *base = slash ? slash + 1 : h5_path;
    if (!realpath(hdir, hreal))
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot resolve the folder %s: %s", h5_path, hdir,
                         strerror(errno));
    /* the sidecar's folder may not exist yet: then it is not the same folder */
    int same = realpath(xdir, xreal) && strcmp(hreal, xreal) == 0;
    int n = same ? snprintf(buf, cap, "%s", base)
                 : snprintf(buf, cap, "%s%s%s", hreal, strcmp(hreal, "/") ? "/" : "", base);
    if (n < 0 || (size_t)n >= cap)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: path too long for the XDMF sidecar", h5_path);
    return CDEM_OK;
}

char *cdem_xdmf_path_for(const char *h5_path) {
    size_t len = strlen(h5_path), stem = len;
    const char *exts[] = {".h5", ".hdf5", ".hdf"};
    for (size_t i = 0; i < sizeof exts / sizeof exts[0]; i++) {
        size_t el = strlen(exts[i]);
        if (len > el && strcmp(h5_path + len - el, exts[i]) == 0) {
            stem = len - el;
            break;
        }
    }
    char *p = malloc(stem + 5);
    if (!p)
        return NULL;
    memcpy(p, h5_path, stem);
    memcpy(p + stem, ".xmf", 5);
    return p;
}

const char *cdem_xdmf_open_prefix(const char *xmf_path) {
    return strchr(xmf_path, '/') ? "" : "./";
}

hid_t cdem_xdmf_create_xy_view(hid_t loc, const char *x_name, const char *y_name,
                               const char *xy_name, int unlimited) {
    hsize_t rows = 0;
    if (!unlimited) {
        hid_t ds = H5Dopen2(loc, x_name, H5P_DEFAULT);
        if (ds < 0)
            return -1;
        hid_t sp = H5Dget_space(ds);
        H5Sget_simple_extent_dims(sp, &rows, NULL);
        H5Sclose(sp);
        H5Dclose(ds);
    }
    hsize_t vdims[2] = {rows, 2}, vmax[2] = {unlimited ? H5S_UNLIMITED : rows, 2};
    hsize_t sdims = rows, smax = unlimited ? H5S_UNLIMITED : rows;
    hid_t vspace = H5Screate_simple(2, vdims, vmax);
    hid_t sspace = H5Screate_simple(1, &sdims, &smax);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_obj_track_times(dcpl, 0);
    const double fill = 0.0;
    H5Pset_fill_value(dcpl, H5T_NATIVE_DOUBLE, &fill);
    int ok = vspace >= 0 && sspace >= 0 && dcpl >= 0;
    /* column c of the view <- all of the source: count "unlimited" or the rows */
    const char *names[2] = {x_name, y_name};
    for (int c = 0; c < 2 && ok; c++) {
        hsize_t vstart[2] = {0, (hsize_t)c}, vcount[2] = {unlimited ? H5S_UNLIMITED : rows, 1};
        hsize_t sstart = 0, scount = unlimited ? H5S_UNLIMITED : rows;
        if (unlimited || rows > 0) {
            ok = H5Sselect_hyperslab(vspace, H5S_SELECT_SET, vstart, NULL, vcount, NULL) >= 0 &&
                 H5Sselect_hyperslab(sspace, H5S_SELECT_SET, &sstart, NULL, &scount, NULL) >= 0;
        } else {
            ok = H5Sselect_none(vspace) >= 0 && H5Sselect_none(sspace) >= 0;
        }
        /* "." is this file, so the view survives renaming the file */
        ok = ok && H5Pset_virtual(dcpl, vspace, ".", names[c], sspace) >= 0;
    }
    hid_t xy =
        ok ? H5Dcreate2(loc, xy_name, H5T_IEEE_F64LE, vspace, H5P_DEFAULT, dcpl, H5P_DEFAULT) : -1;
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (sspace >= 0)
        H5Sclose(sspace);
    if (vspace >= 0)
        H5Sclose(vspace);
    return xy;
}
