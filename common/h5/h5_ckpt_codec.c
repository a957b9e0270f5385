/* h5_ckpt_codec: a checkpoint snapshot (snapshot.h) as bytes and back; no HDF5 here (the
 * slots that hold the bytes are h5_checkpoint.c). A snapshot is one self-describing blob
 * (docs/format.md, "Checkpoints"):
 *   "CDEMSNAP" | u32 version (1) | u32 array count | u64 blob length |
 *   per array: u16 name length | name | u8 type | u64 count | count values |
 *   u64 FNV-1a 64 of every byte before it.
 * All integers and values little-endian; values are copied as they are in memory, so only
 * little-endian hosts write or read checkpoints (h5i_host_little_endian). The decoder trusts
 * nothing: every length is checked against the blob before it is used (fuzz_h5).
 * A slot stores the blob packed (h5i_snap_pack): "CDEMSNPZ" | u64 blob length | the blob as
 * one zlib stream (deflate level DEFLATE_LEVEL, as the element data). The blob's bytes, and so
 * the restored run, are the same; the default run's two slots shrink from 2 x 473 KB to
 * 2 x 269 KB. Compressing here, not with an HDF5 filter: a filtered chunk that is rewritten
 * with another compressed size moves, and in SWMR mode HDF5 never frees the old place, so
 * every checkpoint would leave its predecessor behind in the file (28 per default run); the
 * unfiltered slot is rewritten in place. Files written before hold the bare "CDEMSNAP" blob,
 * which h5i_snap_unpack still accepts. */
#include "h5_internal.h"

#include <zlib.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SNAP_MAGIC      "CDEMSNAP"
#define SNAP_VERSION    1
#define SNAP_MAX_ARRAYS 100000
#define PACK_MAGIC      "CDEMSNPZ"
#define PACK_HEADER     16 /* magic and the u64 blob length */

int h5i_host_little_endian(void) {
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static void put_le(unsigned char *p, uint64_t v, int bytes) {
    for (int i = 0; i < bytes; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t get_le(const unsigned char *p, int bytes) {
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

/* FNV-1a, 64 bit: detects torn or corrupted checkpoint blobs. */
uint64_t h5i_fnv1a64(const unsigned char *p, size_t n) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

/* Declared in h5_internal.h (what it does is said there). */
cdem_status h5i_snap_encode(const cdem_snapshot *snap, unsigned char **buf, size_t *cap,
                            size_t *len, const char *path, cdem_error *err) {
    size_t total = SNAP_HEADER + 8, count = cdem_snapshot_count(snap);
    for (size_t i = 0; i < count; i++) {
        const cdem_snapshot_array *a = cdem_snapshot_at(snap, i);
        size_t bytes = a->count * cdem_snapshot_type_size(a->type);
        total += 2 + strlen(a->name) + 1 + 8 + bytes;
    }
    if (total > *cap) {
        unsigned char *b = realloc(*buf, total);
        if (!b)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory for a checkpoint of %zu bytes",
                             path, total);
        *buf = b;
        *cap = total;
    }
    unsigned char *p = *buf;
    memcpy(p, SNAP_MAGIC, 8);
    put_le(p + 8, SNAP_VERSION, 4);
    put_le(p + 12, count, 4);
    put_le(p + 16, total, 8);
    size_t at = SNAP_HEADER;
    for (size_t i = 0; i < count; i++) {
        const cdem_snapshot_array *a = cdem_snapshot_at(snap, i);
        size_t nl = strlen(a->name), bytes = a->count * cdem_snapshot_type_size(a->type);
        put_le(p + at, nl, 2);
        memcpy(p + at + 2, a->name, nl);
        at += 2 + nl;
        p[at++] = (unsigned char)a->type;
        put_le(p + at, a->count, 8);
        at += 8;
        if (bytes)
            memcpy(p + at, a->data, bytes); /* little-endian host (checked by the caller) */
        at += bytes;
    }
    put_le(p + at, h5i_fnv1a64(p, at), 8);
    *len = at + 8;
    return CDEM_OK;
}

/* Declared in h5_internal.h (what it does is said there). */
cdem_status h5i_snap_decode(const unsigned char *p, size_t len, cdem_snapshot *snap,
                            const char *what, cdem_error *err) {
    cdem_snapshot_clear(snap);
    if (len < SNAP_HEADER + 8 || memcmp(p, SNAP_MAGIC, 8) != 0)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: not a checkpoint blob (no %s header)", what,
                         SNAP_MAGIC);
    uint64_t version = get_le(p + 8, 4), count = get_le(p + 12, 4), total = get_le(p + 16, 8);
    if (version != SNAP_VERSION)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "%s: checkpoint blob version %llu; this program reads version %d", what,
                         (unsigned long long)version, SNAP_VERSION);
    if (total != len)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: checkpoint blob says %llu bytes but has %zu",
                         what, (unsigned long long)total, len);
    if (get_le(p + len - 8, 8) != h5i_fnv1a64(p, len - 8))
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: checkpoint blob checksum mismatch (torn?)",
                         what);
    if (count > SNAP_MAX_ARRAYS)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: checkpoint blob claims %llu arrays", what,
                         (unsigned long long)count);
    size_t at = SNAP_HEADER, end = len - 8;
    for (uint64_t i = 0; i < count; i++) {
        char name[CDEM_SNAPSHOT_NAME_MAX];
        if (end - at < 2)
            goto short_blob;
        size_t nl = (size_t)get_le(p + at, 2);
        at += 2;
        if (nl == 0 || nl >= sizeof name || end - at < nl + 9)
            goto short_blob;
        memcpy(name, p + at, nl);
        name[nl] = '\0';
        at += nl;
        int type = p[at++];
        uint64_t n = get_le(p + at, 8);
        at += 8;
        size_t size = cdem_snapshot_type_size((cdem_snapshot_type)type);
        if (size == 0)
            return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: array \"%s\" has unknown type %d", what,
                             name, type);
        if (n > (end - at) / size)
            goto short_blob;
        cdem_status st = cdem_snapshot_put(snap, name, (cdem_snapshot_type)type, (size_t)n,
                                           n ? p + at : NULL, err);
        if (st != CDEM_OK) {
            cdem_snapshot_clear(snap);
            cdem_error_prefix(err, "%s", what);
            return st == CDEM_ERR_INVALID ? CDEM_ERR_FORMAT : st;
        }
        at += (size_t)n * size;
    }
    if (at != end)
        goto short_blob;
    return CDEM_OK;
short_blob:
    cdem_snapshot_clear(snap);
    return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                     "%s: checkpoint blob is inconsistent at byte %zu of %zu (array list does not "
                     "fit its length)",
                     what, at, len);
}

/* Declared in h5_internal.h (what it does is said there). */
cdem_status h5i_snap_pack(const unsigned char *raw, size_t raw_len, unsigned char **buf,
                          size_t *cap, size_t *len, const char *path, cdem_error *err) {
    const uLong bound = compressBound((uLong)raw_len);
    const size_t need = PACK_HEADER + (size_t)bound;
    if (need > *cap) {
        unsigned char *b = realloc(*buf, need);
        if (!b)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                             "%s: out of memory compressing a checkpoint of %zu bytes", path,
                             raw_len);
        *buf = b;
        *cap = need;
    }
    uLongf packed = bound;
    int zr = compress2(*buf + PACK_HEADER, &packed, raw, (uLong)raw_len, DEFLATE_LEVEL);
    if (zr != Z_OK)
        return CDEM_FAIL(err, zr == Z_MEM_ERROR ? CDEM_ERR_NOMEM : CDEM_ERR_IO,
                         "%s: cannot compress a checkpoint of %zu bytes (zlib error %d)", path,
                         raw_len, zr);
    memcpy(*buf, PACK_MAGIC, 8);
    put_le(*buf + 8, raw_len, 8);
    *len = PACK_HEADER + (size_t)packed;
    return CDEM_OK;
}

/* Declared in h5_internal.h (what it does is said there). */
cdem_status h5i_snap_unpack(const unsigned char *p, size_t len, const unsigned char **raw,
                            size_t *raw_len, int *owned, const char *what, cdem_error *err) {
    *raw = NULL;
    *raw_len = 0;
    *owned = 0;
    if (len >= 8 && memcmp(p, SNAP_MAGIC, 8) == 0) { /* written before compression */
        *raw = p;
        *raw_len = len;
        return CDEM_OK;
    }
    if (len < PACK_HEADER || memcmp(p, PACK_MAGIC, 8) != 0)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: not a checkpoint (no %s or %s header)", what,
                         SNAP_MAGIC, PACK_MAGIC);
    const uint64_t n = get_le(p + 8, 8);
    if (n < SNAP_HEADER + 8 || n > SNAP_MAX_BYTES || n > (uint64_t)(uLong)-1)
        return CDEM_FAIL(
            err, CDEM_ERR_FORMAT, "%s: compressed checkpoint claims %llu bytes (allowed %d..%llu)",
            what, (unsigned long long)n, SNAP_HEADER + 8, (unsigned long long)SNAP_MAX_BYTES);
    unsigned char *out = malloc((size_t)n);
    if (!out)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory for a checkpoint of %llu bytes",
                         what, (unsigned long long)n);
    uLongf got = (uLongf)n;
    uLong used = (uLong)(len - PACK_HEADER);
    int zr = uncompress2(out, &got, p + PACK_HEADER, &used);
    if (zr != Z_OK || got != n || used != len - PACK_HEADER) {
        free(out);
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "%s: compressed checkpoint does not inflate to its %llu bytes (zlib "
                         "error %d, %lu bytes out of %lu in)",
                         what, (unsigned long long)n, zr, (unsigned long)got, (unsigned long)used);
    }
    *raw = out;
    *raw_len = (size_t)n;
    *owned = 1;
    return CDEM_OK;
}
