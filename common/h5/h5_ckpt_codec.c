/* h5_ckpt_codec: a checkpoint snapshot (snapshot.h) as bytes and back; no HDF5 here (the
 * slots that hold the bytes are h5_checkpoint.c). A snapshot is one self-describing blob
 * (docs/format.md, "Checkpoints"):
 *   "CDEMSNAP" | u32 version (1) | u32 array count | u64 blob length |
 *   per array: u16 name length | name | u8 type | u64 count | count values |
 *   u64 FNV-1a 64 of every byte before it.
 * All integers and values little-endian; values are copied as they are in memory, so only
 * little-endian hosts write or read checkpoints (h5i_host_little_endian). The decoder trusts
 * nothing: every length is checked against the blob before it is used (fuzz_h5). */
#include "h5_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SNAP_MAGIC      "CDEMSNAP"
#define SNAP_VERSION    1
#define SNAP_MAX_ARRAYS 100000

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
