/* h5_superblock: reads the HDF5 superblock before HDF5 does. Its status flags say whether a
 * writer left the file open (running or killed: SWMR-read or the "clear_status_flags" open,
 * h5_reader.c), and its end-of-file address, compared with the real size, catches a
 * truncated file before HDF5 parses anything (HDF5's SWMR retries never end on a damaged
 * file). Only v2/v3 superblocks are checked; older ones are left to HDF5. */
#include "h5_internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static uint64_t le_u64(const unsigned char *b, int size) {
    uint64_t v = 0;
    for (int i = size - 1; i >= 0; i--)
        v = (v << 8) | b[i];
    return v;
}

/* Looks at the superblock before HDF5 does. *status receives the status flags of a v3
 * superblock (bit 0: open for write, bit 2: open for SWMR write; 0 when closed). Fails on
 * truncation (stored end-of-file beyond the real size), except for a file open for SWMR
 * write, whose writer may have moved the end-of-file ahead of the data it is writing. */
cdem_status h5i_precheck_superblock(const char *path, int *status, cdem_error *err) {
    *status = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0) {
        fclose(f);
        return CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    }
    uint64_t size = (uint64_t)sb.st_size;
    static const unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char b[64];
    cdem_status st = CDEM_OK;
    for (uint64_t at = 0; at + 8 <= size; at = at ? 2 * at : 512) {
        if (fseek(f, (long)at, SEEK_SET) != 0)
            break;
        size_t got = fread(b, 1, sizeof b, f);
        if (got < 8 || memcmp(b, sig, 8) != 0)
            continue;
        if (got < 12)
            break;
        int version = b[8];
        if (version < 2 || version > 3)
            break; /* older superblocks: leave the checks to HDF5 */
        int so = b[9];
        if (so != 2 && so != 4 && so != 8) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: corrupt HDF5 superblock (size of offsets %d; allowed 2, 4, 8)",
                           path, so);
            break;
        }
        if (got < (size_t)(12 + 4 * so)) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: truncated file: %llu bytes end inside the HDF5 superblock", path,
                           (unsigned long long)size);
            break;
        }
        uint64_t base = le_u64(b + 12, so), eof = le_u64(b + 12 + 2 * so, so);
        int swmr_writer = version == 3 && (b[11] & 0x04);
        if (base + eof > size && !swmr_writer) {
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: truncated file: it has %llu bytes but its HDF5 superblock says "
                           "%llu (copy interrupted or disk full?)",
                           path, (unsigned long long)size, (unsigned long long)(base + eof));
            break;
        }
        if (version == 3)
            *status = b[11] & 0x05;
        break;
    }
    fclose(f);
    return st;
}

/* The end of the file according to its v2/v3 superblock (base address + end-of-file
 * address), or 0 when it cannot be read. */
uint64_t h5i_superblock_eoa(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    static const unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char b[64];
    uint64_t eoa = 0;
    for (uint64_t at = 0; at < ((uint64_t)1 << 40); at = at ? 2 * at : 512) {
        if (fseek(f, (long)at, SEEK_SET) != 0)
            break;
        size_t got = fread(b, 1, sizeof b, f);
        if (got < 12)
            break;
        if (memcmp(b, sig, 8) != 0)
            continue;
        int so = b[9];
        if ((b[8] == 2 || b[8] == 3) && (so == 2 || so == 4 || so == 8) &&
            got >= (size_t)(12 + 4 * so))
            eoa = le_u64(b + 12, so) + le_u64(b + 12 + 2 * so, so);
        break;
    }
    fclose(f);
    return eoa;
}
