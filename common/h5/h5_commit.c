/* h5_commit: the commit record of a run file, /increments/commit (docs/format.md,
 * "/increments/commit: the commit record"), and the recovery of the older record,
 * /increments/index, from a chunk a kill tore.
 *
 * Why a record apart from /increments/index. The index is an extendible chunked dataset: an
 * append rewrites its last chunk in place and grows its extent in its object header. Neither
 * is atomic. A kill inside the chunk's write leaves the new row's bytes beside the old
 * checksum (the kernel copies a write page by page and stops between pages), and HDF5 then
 * refuses the whole chunk: every increment of the file was lost (issue 35, item 1, one kill
 * in 200). A reader can also see the grown extent before the row (item 2, render --follow).
 * The commit record is made so that neither can happen:
 *  - it is contiguous and allocated whole when the file is created (capacity rows, zeros):
 *    no extent, no chunk index, no HDF5 metadata changes when a row is added;
 *  - a row is written once, at its own place, and never rewritten while it is committed;
 *  - each row carries a checksum (FNV-1a 64) of its members and of its position, so a row a
 *    kill or a power cut tore is invalid, and a row copied to another place is too.
 * So the committed increments are the valid rows. A writer writes the rows in order, so in a
 * sound file they are a prefix, everything after them blank (never written), except that the
 * first row after them may be torn in a file whose writer did not close it (a kill stops a
 * write only between two pages, so only a row that crosses a page boundary can be torn, and
 * only into what it was on one side of it: h5i_commit_scan). Any other row is damage: a row
 * that held an increment (the rows /increments/index has, in a closed file) and fails its
 * checksum or is blank costs that increment alone, and a spare row that is not blank costs
 * none; the reader names each in one warning, refuses the damaged rows' increments, and
 * lists every valid row, before and after them (each row's checksum covers its position, so
 * a valid row is the writer's row at its place).
 * --resume drops rows by blanking them from the last to the first, each row its own write,
 * so that at any moment the valid rows still form a prefix (h5_resume.c).
 * The writer still appends every row to /increments/index as well, after this record, for
 * h5py and other HDF5 tools; cdem-c's reader uses that index only in files without a commit
 * record (written before it existed), where a torn last chunk is recovered below. */
#include "h5_internal.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* The row's members in the file's packed little-endian order (the index member table),
 * then its position, as bytes: what the checksum covers. */
static size_t commit_bytes(const index_row *row, uint64_t position, unsigned char *out) {
    size_t at = 0;
    for (size_t i = 0; i < N_INDEX_MEMBERS; i++) {
        const index_member *m = &h5i_index_members[i];
        const char *src = (const char *)row + m->offset;
        uint64_t v = 0;
        size_t len = m->kind == IX_I32 ? 4 : 8;
        if (len == 4) {
            uint32_t v32;
            memcpy(&v32, src, 4);
            v = v32;
        } else {
            memcpy(&v, src, 8); /* int64 and the bits of a double */
        }
        for (size_t b = 0; b < len; b++)
            out[at++] = (unsigned char)(v >> (8 * b));
    }
    for (size_t b = 0; b < 8; b++)
        out[at++] = (unsigned char)(position >> (8 * b));
    return at;
}

/* The inverse of commit_bytes' member part: a row of the index's file type (packed,
 * little-endian, members in table order) into an index_row. */
static void decode_packed_row(const unsigned char *in, index_row *row) {
    memset(row, 0, sizeof *row);
    size_t at = 0;
    for (size_t i = 0; i < N_INDEX_MEMBERS; i++) {
        const index_member *m = &h5i_index_members[i];
        size_t len = m->kind == IX_I32 ? 4 : 8;
        uint64_t v = 0;
        for (size_t b = 0; b < len; b++)
            v |= (uint64_t)in[at++] << (8 * b);
        char *dst = (char *)row + m->offset;
        if (len == 4) {
            uint32_t v32 = (uint32_t)v;
            memcpy(dst, &v32, 4);
        } else {
            memcpy(dst, &v, 8);
        }
    }
}

uint64_t h5i_commit_checksum(const index_row *row, uint64_t position) {
    unsigned char bytes[16 * N_INDEX_MEMBERS];
    return h5i_fnv1a64(bytes, commit_bytes(row, position, bytes));
}

int h5i_commit_row_valid(const commit_row *c, uint64_t position) {
    return c->checksum == h5i_commit_checksum(&c->row, position);
}

int h5i_commit_row_blank(const commit_row *c) {
    static const commit_row zero; /* every member 0: a row never written */
    unsigned char a[16 * N_INDEX_MEMBERS], b[16 * N_INDEX_MEMBERS];
    size_t n = commit_bytes(&c->row, 0, a);
    commit_bytes(&zero.row, 0, b);
    return c->checksum == 0 && memcmp(a, b, n) == 0;
}

hid_t h5i_commit_type(int file) {
    hid_t t = h5i_make_compound(h5i_index_members, N_INDEX_MEMBERS, sizeof(commit_row), file);
    if (t < 0)
        return t;
    const size_t at = file ? H5Tget_size(t) : offsetof(commit_row, checksum);
    if ((file && H5Tset_size(t, at + 8) < 0) ||
        H5Tinsert(t, "checksum", at, file ? H5T_STD_U64LE : H5T_NATIVE_UINT64) < 0) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

hid_t h5i_commit_create(hid_t group, hsize_t capacity) {
    hid_t ft = h5i_commit_type(1);
    hid_t ds = ft >= 0 ? h5i_create_fixed(group, "commit", ft, capacity) : -1;
    hid_t es = h5i_keep_errors(ds < 0);
    if (ft >= 0)
        H5Tclose(ft);
    h5i_restore_errors(es);
    return ds;
}

int h5i_commit_write(hid_t ds, hid_t mtype, hsize_t position, const index_row *row) {
    commit_row c;
    memset(&c, 0, sizeof c);
    c.row = *row;
    c.checksum = h5i_commit_checksum(row, position);
    return h5i_write_rows(ds, mtype, position, 1, &c);
}

int h5i_commit_blank_from(hid_t ds, hid_t mtype, hsize_t keep, const commit_row *rows,
                          hsize_t capacity) {
    commit_row zero;
    memset(&zero, 0, sizeof zero);
    /* last first, one write each (the writer has no sieve buffer to merge them): a kill
     * between two of them leaves the rows still valid before the blank ones */
    for (hsize_t i = capacity; i-- > keep;)
        if (!h5i_commit_row_blank(&rows[i]) && h5i_write_rows(ds, mtype, i, 1, &zero) < 0)
            return -1;
    return 0;
}

/* 1 when row i (of row_bytes bytes, the record's row 0 at file offset base) can be a row a
 * killed writer's write tore: the kernel copies a write into the page cache page by page and
 * a kill stops it only between two pages, so the row must cross a page boundary (a multiple
 * of 4096 bytes, the smallest page: larger pages' boundaries are among them), and one side
 * of that boundary must still hold what was there before: zeros after it (an append of the
 * row stopped there) or zeros before it (--resume's blanking of the row stopped there). A
 * flipped byte in a row that crosses no boundary cannot be a tear. */
static int commit_row_tearable(const commit_row *c, hsize_t i, uint64_t base, size_t row_bytes) {
    unsigned char b[16 * N_INDEX_MEMBERS];
    size_t n = commit_bytes(&c->row, 0, b) - 8; /* the members, without the position */
    for (size_t k = 0; k < 8; k++)
        b[n++] = (unsigned char)(c->checksum >> (8 * k));
    if (n != row_bytes)
        return 1; /* not the documented layout: cannot tell, as before */
    const uint64_t first = base + (uint64_t)i * row_bytes, end = first + row_bytes;
    for (uint64_t page = (first / 4096 + 1) * 4096; page < end; page += 4096) {
        const size_t cut = (size_t)(page - first);
        int zero_after = 1, zero_before = 1;
        for (size_t k = cut; k < n && zero_after; k++)
            zero_after = b[k] == 0;
        for (size_t k = 0; k < cut && zero_before; k++)
            zero_before = b[k] == 0;
        if (zero_after || zero_before)
            return 1;
    }
    return 0;
}

const char *h5i_commit_scan(const commit_row *rows, hsize_t capacity, const commit_scan_in *in,
                            unsigned char *kind, commit_scan_out *out) {
    memset(out, 0, sizeof *out);
    out->first_damaged = capacity;
    hsize_t last_valid = capacity; /* none */
    for (hsize_t i = 0; i < capacity; i++) {
        kind[i] = h5i_commit_row_valid(&rows[i], i) ? COMMIT_VALID
                  : h5i_commit_row_blank(&rows[i])  ? COMMIT_BLANK
                                                    : COMMIT_DAMAGED;
        if (kind[i] == COMMIT_VALID) {
            last_valid = i;
            out->valid++;
        }
    }
    const hsize_t after = last_valid == capacity ? 0 : last_valid + 1;
    const hsize_t index_rows = in->index_rows;
    if (!in->unclosed && index_rows != H5I_ROWS_UNKNOWN) {
        /* closed: the writer wrote its every row to both, so the index's extent is the number
         * of rows written (a damaged last row is still a written one) */
        hsize_t written_rows = 0; /* rows below the index's extent that are not blank */
        for (hsize_t i = 0; i < index_rows && i < capacity; i++)
            written_rows += kind[i] != COMMIT_BLANK;
        out->written = index_rows;
        if (after > index_rows || (index_rows > 0 && written_rows == 0))
            return "its rows and /increments/index disagree"; /* blanked, or a valid row beyond */
    } else {
        out->written = after;
        /* a killed writer wrote its index row after its commit row (--resume blanks commit
         * rows before it shrinks the index): rows below the index's extent that are not blank
         * were written */
        if (index_rows != H5I_ROWS_UNKNOWN)
            for (hsize_t i = after; i < index_rows && i < capacity; i++)
                if (kind[i] != COMMIT_BLANK)
                    out->written = i + 1;
    }
    /* the first row after the valid ones, in a file whose writer did not close it: the row
     * it was writing (or blanking) when it was killed, torn, when only blank rows follow */
    if (in->unclosed && after < capacity && kind[after] == COMMIT_DAMAGED) {
        int rest_blank = 1;
        for (hsize_t i = after + 1; i < capacity && rest_blank; i++)
            rest_blank = kind[i] == COMMIT_BLANK;
        if (rest_blank &&
            (in->live || in->record_at == H5I_ROWS_UNKNOWN ||
             commit_row_tearable(&rows[after], after, in->record_at, in->row_bytes))) {
            kind[after] = COMMIT_TORN;
            out->torn = 1;
            if (out->written == after + 1)
                out->written = after;
        }
    }
    for (hsize_t i = 0; i < capacity; i++) {
        if (kind[i] == COMMIT_BLANK && i < out->written && (!in->unclosed || i < after))
            kind[i] = COMMIT_DAMAGED; /* blank among written rows */
        if (kind[i] == COMMIT_DAMAGED) {
            kind[i] = i < out->written ? COMMIT_DAMAGED : COMMIT_SPARE_DAMAGED;
            if (out->damaged++ == 0)
                out->first_damaged = i;
            if (kind[i] == COMMIT_DAMAGED && out->damaged_written++ == 0)
                out->first_damaged_written = i;
        }
    }
    if (out->damaged_written == 0)
        out->first_damaged_written = capacity;
    return NULL;
}

const char *h5i_commit_damage_text(const commit_row *row, unsigned char kind) {
    if (kind == COMMIT_SPARE_DAMAGED)
        return "a spare row (never written: no increment was there), not blank";
    if (h5i_commit_row_blank(row))
        return "blank (all zero) where its writer wrote an increment";
    return "its checksum does not match its contents";
}

/* ------------------------------------------------------------------ files without it */

/* HDF5's Fletcher-32 (H5checksum.c): 16-bit words, most significant byte first. */
static uint32_t fletcher32(const unsigned char *data, size_t len) {
    uint32_t sum1 = 0, sum2 = 0;
    size_t words = len / 2;
    while (words) {
        size_t t = words > 360 ? 360 : words;
        words -= t;
        do {
            sum1 += (uint32_t)((data[0] << 8) | data[1]);
            data += 2;
            sum2 += sum1;
        } while (--t);
        sum1 = (sum1 & 0xffff) + (sum1 >> 16);
        sum2 = (sum2 & 0xffff) + (sum2 >> 16);
    }
    if (len % 2) {
        sum1 += (uint32_t)(*data << 8);
        sum2 += sum1;
        sum1 = (sum1 & 0xffff) + (sum1 >> 16);
        sum2 = (sum2 & 0xffff) + (sum2 >> 16);
    }
    sum1 = (sum1 & 0xffff) + (sum1 >> 16);
    sum2 = (sum2 & 0xffff) + (sum2 >> 16);
    return (sum2 << 16) | sum1;
}

hsize_t h5i_index_recover_torn_chunk(hid_t index, hsize_t rows, index_row *out) {
    const hsize_t chunk = h5i_chunk_rows_of(index);
    if (chunk == 0 || rows == 0)
        return 0;
    hid_t dcpl = H5Dget_create_plist(index);
    const int only_fletcher =
        dcpl >= 0 && H5Pget_nfilters(dcpl) == 1 &&
        H5Pget_filter2(dcpl, 0, NULL, NULL, NULL, 0, NULL, NULL) == H5Z_FILTER_FLETCHER32;
    if (dcpl >= 0)
        H5Pclose(dcpl);
    hid_t ft = H5Dget_type(index),
          packed = h5i_make_compound(h5i_index_members, N_INDEX_MEMBERS, sizeof(index_row), 1);
    /* only the layout decode_packed_row reads */
    const size_t row_bytes =
        ft >= 0 && packed >= 0 && H5Tequal(ft, packed) > 0 ? H5Tget_size(ft) : 0;
    if (ft >= 0)
        H5Tclose(ft);
    if (packed >= 0)
        H5Tclose(packed);
    const hsize_t first = (rows - 1) / chunk * chunk; /* the last chunk: the one appended to */
    hsize_t raw_size = 0, at = first;
    unsigned char *raw = NULL;
    uint32_t filters = 0;
    hsize_t recovered = 0;
    if (only_fletcher && row_bytes > 0 && H5Dget_chunk_storage_size(index, &at, &raw_size) >= 0 &&
        raw_size == chunk * row_bytes + 4 && (raw = malloc(raw_size)) != NULL &&
        H5Dread_chunk(index, H5P_DEFAULT, &at, &filters, raw) >= 0) {
        const unsigned char *c = raw + raw_size - 4;
        const uint32_t stored =
            (uint32_t)c[0] | (uint32_t)c[1] << 8 | (uint32_t)c[2] << 16 | (uint32_t)c[3] << 24;
        /* A torn rewrite holds the new rows' bytes before the old checksum, which is that of
         * the chunk when it had fewer rows (the rest fill, 0): try the longest such prefix
         * first. Only rows up to the dataset's extent are candidates. */
        for (hsize_t k = rows - first; k > 0 && !recovered; k--) {
            unsigned char *trial = malloc(raw_size - 4);
            if (!trial)
                break;
            memcpy(trial, raw, k * row_bytes);
            memset(trial + k * row_bytes, 0, raw_size - 4 - k * row_bytes);
            if (fletcher32(trial, raw_size - 4) == stored) {
                for (hsize_t i = 0; i < k; i++)
                    decode_packed_row(trial + i * row_bytes, &out[first + i]);
                recovered = first + k;
            }
            free(trial);
        }
    }
    free(raw);
    H5Eclear2(H5E_DEFAULT);
    /* the chunks before the last one are read as usual */
    if (recovered && first > 0) {
        hid_t mt = h5i_make_compound(h5i_index_members, N_INDEX_MEMBERS, sizeof(index_row), 0);
        int ok = mt >= 0 && h5i_read_rows(index, mt, 0, first, out) == 0;
        if (mt >= 0)
            H5Tclose(mt);
        H5Eclear2(H5E_DEFAULT);
        if (!ok)
            recovered = 0;
    }
    return recovered;
}
