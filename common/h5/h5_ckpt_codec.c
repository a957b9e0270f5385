/* h5_ckpt_codec: a checkpoint snapshot (snapshot.h) as bytes and back; no HDF5 here (the
 * slots that hold the bytes are h5_checkpoint.c). A snapshot is one self-describing blob
 * (docs/format.md, "Checkpoints"):
 *   "CDEMSNAP" | u32 version (1) | u32 array count | u64 blob length |
 *   per array: u16 name length | name | u8 type | u64 count | count values |
 *   u64 FNV-1a 64 of every byte before it.
 * All integers and values little-endian; values are copied as they are in memory, so only
 * little-endian hosts write or read checkpoints (h5i_host_little_endian). The decoder trusts
 * nothing: every length is checked against the blob before it is used (fuzz_h5).
 * A slot stores the blob packed (h5i_snap_pack): "CDEMSNPT" | u64 blob length | one zlib
 * stream of the blob with the values of some arrays byte-transposed (byte 0 of every value,
 * then byte 1, ...: HDF5's shuffle filter; the high bit of such an array's type byte says so).
 * The low bytes of a double are noise, its high bytes repeat: transposed, deflate finds the
 * repeats (the default run's slots: 267 KB at level 4 untransposed, 245 KB now). An array is
 * transposed when a level-1 trial on its first SHUFFLE_PROBE bytes says it compresses better
 * so (masses, flags and the pairs' shear displacements and forces compress better as they
 * are). Unpacking undoes the transposition, so the blob's bytes, and so the restored run, are
 * the same (its checksum is checked after). Compressing here, not with an HDF5 filter: a filtered
 * chunk that is rewritten with another compressed size moves, and in SWMR mode HDF5 never frees the
 * old place, so every checkpoint would leave its predecessor behind in the file (28 per
 * default run); the unfiltered slot is rewritten in place. Slots of older files hold
 * "CDEMSNPZ" | u64 blob length | the blob as one zlib stream, or the bare "CDEMSNAP" blob;
 * h5i_snap_unpack reads both. */
#include "h5_internal.h"

#include <zlib.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SNAP_MAGIC      "CDEMSNAP"
#define SNAP_VERSION    1
#define SNAP_MAX_ARRAYS 100000
#define PACK_MAGIC      "CDEMSNPT" /* transposed arrays, deflated (written now) */
#define PACK_MAGIC_Z    "CDEMSNPZ" /* the blob deflated as it is (read only) */
#define PACK_HEADER     16         /* magic and the u64 blob length */
#define TYPE_SHUFFLED   0x80       /* in a packed blob's type byte: values byte-transposed */
#define SHUFFLE_PROBE   8192       /* bytes of an array the transposition trial compresses */

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

/* Byte-transposes n values of size bytes from src into dst (dst[b * n + i] = byte b of
 * value i), or back (inverse: src transposed, dst as values). */
static void transpose(unsigned char *dst, const unsigned char *src, size_t n, size_t size,
                      int inverse) {
    for (size_t i = 0; i < n; i++)
        for (size_t b = 0; b < size; b++) {
            if (inverse)
                dst[i * size + b] = src[b * n + i];
            else
                dst[b * n + i] = src[i * size + b];
        }
}

/* The transposition trial: deflate at level 1 of at most SHUFFLE_PROBE bytes, one stream
 * reset for each trial (a fresh stream per trial would allocate and clear zlib's 256 KiB
 * state 2 x 20 times per checkpoint). */
typedef struct {
    z_stream z;                                                /* level 1, reset per trial */
    int ready;                                                 /* 1 once deflateInit succeeded */
    unsigned char as_is[SHUFFLE_PROBE];                        /* the values, first bytes */
    unsigned char shuffled[SHUFFLE_PROBE];                     /* the same transposed */
    unsigned char out[SHUFFLE_PROBE + SHUFFLE_PROBE / 8 + 64]; /* deflate output, discarded */
} probe;

/* Bytes deflate makes of p[0, n) (n + 1 when the trial fails: then nothing is preferred). */
static size_t probe_size(probe *pr, unsigned char *p, size_t n) {
    if (deflateReset(&pr->z) != Z_OK)
        return n + 1;
    pr->z.next_in = p;
    pr->z.avail_in = (uInt)n;
    pr->z.next_out = pr->out;
    pr->z.avail_out = (uInt)sizeof pr->out;
    return deflate(&pr->z, Z_FINISH) == Z_STREAM_END ? (size_t)pr->z.total_out : n + 1;
}

/* Whether deflate does better on the values v (count values of size bytes) transposed,
 * judged on the first SHUFFLE_PROBE bytes. */
static int transposing_helps(probe *pr, const unsigned char *v, size_t count, size_t size) {
    if (!pr->ready)
        return 0;
    size_t n = count < SHUFFLE_PROBE / size ? count : SHUFFLE_PROBE / size;
    memcpy(pr->as_is, v, n * size);
    transpose(pr->shuffled, v, n, size, 0);
    return probe_size(pr, pr->shuffled, n * size) < probe_size(pr, pr->as_is, n * size);
}

/* Walks the arrays of a blob p[0, len) whose header (SNAP_HEADER bytes) has been checked:
 * calls visit for every array whose values are inside the blob; returns 0, or -1 at the
 * first array that does not fit (the packed form is then corrupt). */
typedef void (*array_visit)(unsigned char *type, unsigned char *values, size_t count, size_t size,
                            void *ctx);
static int walk_arrays(unsigned char *p, size_t len, array_visit visit, void *ctx) {
    const uint64_t count = get_le(p + 12, 4);
    size_t at = SNAP_HEADER, end = len - 8;
    for (uint64_t i = 0; i < count; i++) {
        if (end - at < 2)
            return -1;
        size_t nl = (size_t)get_le(p + at, 2);
        if (end - at - 2 < nl + 9)
            return -1;
        at += 2 + nl;
        unsigned char *type = p + at++;
        uint64_t n = get_le(p + at, 8);
        at += 8;
        size_t size = cdem_snapshot_type_size((cdem_snapshot_type)(*type & ~TYPE_SHUFFLED));
        if (size == 0 || n > (end - at) / size)
            return -1;
        visit(type, p + at, (size_t)n, size, ctx);
        at += (size_t)n * size;
    }
    return 0;
}

/* What packing and unpacking an array needs besides the array. */
typedef struct {
    unsigned char *scratch; /* at least as large as the largest array's values */
    probe *trial;           /* packing: the transposition trial */
} pack_state;

static void pack_array(unsigned char *type, unsigned char *values, size_t count, size_t size,
                       void *ctx) {
    pack_state *ps = ctx;
    if (size < 2 || count < 2 || !transposing_helps(ps->trial, values, count, size))
        return;
    transpose(ps->scratch, values, count, size, 0);
    memcpy(values, ps->scratch, count * size);
    *type |= TYPE_SHUFFLED;
}

static void unpack_array(unsigned char *type, unsigned char *values, size_t count, size_t size,
                         void *ctx) {
    pack_state *ps = ctx;
    if (!(*type & TYPE_SHUFFLED))
        return;
    transpose(ps->scratch, values, count, size, 1);
    memcpy(values, ps->scratch, count * size);
    *type &= (unsigned char)~TYPE_SHUFFLED;
}

/* Declared in h5_internal.h (what it does is said there). */
cdem_status h5i_snap_pack(unsigned char *blob, size_t blob_len, unsigned char **buf, size_t *cap,
                          size_t *len, const char *path, cdem_error *err) {
    const uLong bound = compressBound((uLong)blob_len);
    const size_t need = PACK_HEADER + (size_t)bound;
    if (need > *cap) {
        unsigned char *b = realloc(*buf, need);
        if (!b)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                             "%s: out of memory compressing a checkpoint of %zu bytes", path,
                             blob_len);
        *buf = b;
        *cap = need;
    }
    probe *trial = calloc(1, sizeof *trial);
    if (!trial)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory packing a checkpoint", path);
    trial->ready = deflateInit(&trial->z, 1) == Z_OK;
    /* transposed in the blob itself, with the packed buffer (larger than any array) as
     * scratch before it receives the compressed bytes */
    pack_state ps = {*buf, trial};
    int walked = walk_arrays(blob, blob_len, pack_array, &ps);
    if (trial->ready)
        deflateEnd(&trial->z);
    free(trial);
    if (walked != 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: inconsistent checkpoint blob", path);
    uLongf packed = bound;
    int zr = compress2(*buf + PACK_HEADER, &packed, blob, (uLong)blob_len, CKPT_DEFLATE_LEVEL);
    if (zr != Z_OK)
        return CDEM_FAIL(err, zr == Z_MEM_ERROR ? CDEM_ERR_NOMEM : CDEM_ERR_IO,
                         "%s: cannot compress a checkpoint of %zu bytes (zlib error %d)", path,
                         blob_len, zr);
    memcpy(*buf, PACK_MAGIC, 8);
    put_le(*buf + 8, blob_len, 8);
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
    const int transposed = len >= PACK_HEADER && memcmp(p, PACK_MAGIC, 8) == 0;
    if (!transposed && (len < PACK_HEADER || memcmp(p, PACK_MAGIC_Z, 8) != 0))
        return CDEM_FAIL(err, CDEM_ERR_FORMAT, "%s: not a checkpoint (no %s, %s or %s header)",
                         what, SNAP_MAGIC, PACK_MAGIC, PACK_MAGIC_Z);
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
    if (transposed) {
        /* the arrays put back in order; the blob's checksum (h5i_snap_decode) then says
         * whether this gave the bytes that were packed */
        unsigned char *scratch = malloc((size_t)n);
        pack_state ps = {scratch, NULL};
        const int have_memory = scratch != NULL;
        int ok = have_memory && walk_arrays(out, (size_t)n, unpack_array, &ps) == 0;
        free(scratch);
        if (!ok) {
            free(out);
            return have_memory ? CDEM_FAIL(err, CDEM_ERR_FORMAT,
                                           "%s: compressed checkpoint: its array list does not fit "
                                           "its %llu bytes",
                                           what, (unsigned long long)n)
                               : CDEM_FAIL(err, CDEM_ERR_NOMEM,
                                           "%s: out of memory for a checkpoint of %llu bytes", what,
                                           (unsigned long long)n);
        }
    }
    *raw = out;
    *raw_len = (size_t)n;
    *owned = 1;
    return CDEM_OK;
}
