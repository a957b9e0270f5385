/* gen_damaged: makes the damaged run files of tests/data/damaged/ (docs/reliability.md,
 * "Damaged files") from a completed run file and a killed one, each damage placed where it
 * hurts and seeded, so the corpus can be made again. Not part of the build; run by
 * tests/fuzz/make_damaged.sh, which also makes the two input files with cdem-run:
 *   gen_damaged COMPLETE.h5 KILLED.h5 OUTDIR
 * writes into OUTDIR:
 *   killed-flipped.h5    KILLED with 50 bits flipped at seeded random places (issue 19: a
 *                        reader of such a file sat in HDF5's SWMR retry loop for ever)
 *   killed-truncated.h5  KILLED cut to 70 % of its length
 *   truncated.h5         COMPLETE cut to 60 % of its length
 *   index-flipped.h5     COMPLETE with one bit flipped in the net displacement of the last
 *                        row of /increments/index (once read as 5.7e78 m)
 *   series-flipped.h5    COMPLETE with one bit flipped in the time of sample 5 of /series
 *   metadata-flipped.h5  COMPLETE with one byte flipped in the root object header (the root
 *                        attributes: once reported as "not a cdem file")
 * Build: cc -std=c17 -D_DEFAULT_SOURCE $(pkg-config --cflags hdf5) tests/fuzz/gen_damaged.c \
 *          $(pkg-config --libs hdf5) -o /tmp/gen_damaged */
#include <hdf5.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    unsigned char *b; /* file bytes */
    size_t n;         /* length */
} blob;

static blob slurp(const char *path) {
    blob f = {NULL, 0};
    FILE *fp = fopen(path, "rb");
    if (!fp || fseek(fp, 0, SEEK_END) != 0) {
        fprintf(stderr, "gen_damaged: cannot read %s\n", path);
        exit(1);
    }
    f.n = (size_t)ftell(fp);
    rewind(fp);
    f.b = malloc(f.n ? f.n : 1);
    if (!f.b || fread(f.b, 1, f.n, fp) != f.n) {
        fprintf(stderr, "gen_damaged: cannot read %s\n", path);
        exit(1);
    }
    fclose(fp);
    return f;
}

static void spit(const char *dir, const char *name, const unsigned char *b, size_t n) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "wb");
    if (!fp || fwrite(b, 1, n, fp) != n || fclose(fp) != 0) {
        fprintf(stderr, "gen_damaged: cannot write %s\n", path);
        exit(1);
    }
    printf("%s: %zu bytes\n", path, n);
}

/* File address of the first chunk of dataset name. */
static haddr_t first_chunk(const char *path, const char *name) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_file_locking(fapl, 0, 1);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    hid_t ds = f >= 0 ? H5Dopen2(f, name, H5P_DEFAULT) : -1;
    hid_t sp = ds >= 0 ? H5Dget_space(ds) : -1;
    hsize_t offset[1] = {0}, size = 0;
    unsigned mask = 0;
    haddr_t addr = HADDR_UNDEF;
    if (sp < 0 || H5Dget_chunk_info(ds, sp, 0, offset, &mask, &addr, &size) < 0) {
        fprintf(stderr, "gen_damaged: %s: no chunk of %s\n", path, name);
        exit(1);
    }
    H5Sclose(sp);
    H5Dclose(ds);
    H5Fclose(f);
    H5Pclose(fapl);
    return addr;
}

static hsize_t rows_of(const char *path, const char *name) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_file_locking(fapl, 0, 1);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    hid_t sp = H5Dget_space(ds);
    hsize_t n = 0;
    H5Sget_simple_extent_dims(sp, &n, NULL);
    H5Sclose(sp);
    H5Dclose(ds);
    H5Fclose(f);
    H5Pclose(fapl);
    return n;
}

static uint64_t next(uint64_t *s) { /* splitmix64 */
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: gen_damaged COMPLETE.h5 KILLED.h5 OUTDIR\n");
        return 2;
    }
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    const char *complete = argv[1], *killed = argv[2], *dir = argv[3];
    blob c = slurp(complete), k = slurp(killed);
    unsigned char *work = malloc(c.n > k.n ? c.n : k.n);
    if (!work)
        return 1;

    uint64_t seed = 19;
    memcpy(work, k.b, k.n);
    for (int i = 0; i < 50; i++) {
        size_t at = (size_t)(next(&seed) % k.n);
        work[at] ^= (unsigned char)(1u << (next(&seed) % 8));
    }
    spit(dir, "killed-flipped.h5", work, k.n);
    spit(dir, "killed-truncated.h5", k.b, k.n * 7 / 10);
    spit(dir, "truncated.h5", c.b, c.n * 6 / 10);

    /* /increments/index rows are packed little-endian: number i32, step i64, time f64,
     * phase i32, net_displacement f64, ... (84 bytes); the net displacement is at byte 24 */
    hsize_t rows = rows_of(complete, "increments/index");
    haddr_t ix = first_chunk(complete, "increments/index");
    memcpy(work, c.b, c.n);
    work[ix + (rows - 1) * 84 + 24 + 7] ^= 0x10; /* exponent bit: the value x 2^256 or so */
    spit(dir, "index-flipped.h5", work, c.n);

    haddr_t st = first_chunk(complete, "series/time");
    memcpy(work, c.b, c.n);
    work[st + 5 * 8 + 6] ^= 0x20; /* an exponent bit of the time of sample 5 */
    spit(dir, "series-flipped.h5", work, c.n);

    /* superblock v3: signature 8, version, sizes, flags (12 bytes), then base, extension,
     * end-of-file and root object header addresses (8 bytes each) */
    uint64_t root = 0;
    for (int i = 7; i >= 0; i--)
        root = (root << 8) | c.b[36 + i];
    memcpy(work, c.b, c.n);
    work[root + 100] ^= 0xff;
    spit(dir, "metadata-flipped.h5", work, c.n);
    free(work);
    free(c.b);
    free(k.b);
    return 0;
}
