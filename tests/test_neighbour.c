/* Tests of solver/neighbour: the cell/Verlet pair list equals a brute-force search, the
 * rebuild criterion, and contact histories (with a law's history slots) surviving
 * re-sorting, element removal, threaded builds and checkpoints. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "contact.h"
#include "neighbour.h"
#include "snapshot.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Small deterministic generator for test packings (seeded, no clock). */
static double rnd(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

static const double radii[4] = {50.0, 75.0, 100.0, 125.0};

/* n random elements in [0, W] x [0, H]; every 10th is a wall element. */
static void make_box(cdem_state *s, size_t n, double W, double H, uint64_t seed) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, n, 0, &err), CDEM_OK);
    uint64_t g = seed;
    for (size_t i = 0; i < n; i++) {
        double r = radii[(int)(rnd(&g) * 4.0) % 4];
        uint32_t fl = (i % 10 == 0) ? CDEM_FLAG_WALL : 0u;
        const double x = rnd(&g) * W, y = rnd(&g) * H;
        assert_int_equal(cdem_state_append(s, -1, x, y, r, 1.0, 0, fl, 0, NULL, &err), CDEM_OK);
    }
}

/* n random elements in [0, L]^2; every 10th is a wall element. */
static void make_cloud(cdem_state *s, size_t n, double L, uint64_t seed) {
    make_box(s, n, L, L, seed);
}

static int cmp_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Keys of all pairs within R * rf + skin by brute force (test only), sorted. */
static size_t brute_pairs(const cdem_state *s, double rf, double skin, uint64_t **out) {
    size_t cap = 1024, k = 0;
    uint64_t *keys = malloc(cap * sizeof *keys);
    for (size_t i = 0; i < s->n; i++)
        for (size_t j = i + 1; j < s->n; j++) {
            if (cdem_contact_class(s->flags[i], s->flags[j]) < 0)
                continue;
            double R = s->radius[i] + s->radius[j], cut = R * rf + skin;
            double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
            if (dx * dx + dy * dy >= cut * cut)
                continue;
            if (k == cap)
                keys = realloc(keys, (cap *= 2) * sizeof *keys);
            keys[k++] = cdem_pair_key(s->id[i], s->id[j]);
        }
    qsort(keys, k, sizeof *keys, cmp_u64);
    *out = keys;
    return k;
}

static void assert_list_equals_brute(const cdem_neighbour *nb, const cdem_state *s) {
    uint64_t *bk = NULL;
    size_t nbk = brute_pairs(s, nb->reach_factor, nb->skin, &bk);
    uint64_t *lk = malloc((nb->np + 1) * sizeof *lk);
    for (size_t p = 0; p < nb->np; p++) {
        assert_true(nb->pi[p] < nb->pj[p]);
        lk[p] = cdem_pair_key(s->id[nb->pi[p]], s->id[nb->pj[p]]);
    }
    qsort(lk, nb->np, sizeof *lk, cmp_u64);
    assert_int_equal(nb->np, nbk);
    assert_true(nbk > 100);
    assert_memory_equal(lk, bk, nbk * sizeof *bk);
    /* slot lists: every slot once as pi (contiguous ranges) and once as pj */
    assert_int_equal(nb->istart[s->n], (int32_t)nb->np);
    assert_int_equal(nb->jstart[s->n], (int32_t)nb->np);
    for (size_t i = 0; i < s->n; i++) {
        for (int32_t p = nb->istart[i]; p < nb->istart[i + 1]; p++)
            assert_int_equal(nb->pi[p], (int32_t)i);
        for (int32_t e = nb->jstart[i]; e < nb->jstart[i + 1]; e++)
            assert_int_equal(nb->pj[nb->jslot[e]], (int32_t)i);
    }
    free(lk);
    free(bk);
}

static void test_neighbour_matches_brute_force(void **st) {
    (void)st;
    cdem_state s;
    make_cloud(&s, 800, 4000.0, 42);
    cdem_neighbour nb;
    cdem_error err;
    const double skin = 12.5;
    assert_int_equal(cdem_neighbour_init(&nb, skin, 1.0, 5, &err), CDEM_OK);
    assert_true(cdem_neighbour_needs_rebuild(&nb, &s));
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, 0, &err), CDEM_OK);
    assert_list_equals_brute(&nb, &s);
    assert_false(cdem_neighbour_needs_rebuild(&nb, &s));
    /* moves below half the skin: no rebuild needed, and every touching pair is listed */
    uint64_t g = 7;
    for (size_t i = 0; i < s.n; i++) {
        double a = rnd(&g) * 2.0 * M_PI;
        s.x[i] += 0.49 * skin * cos(a);
        s.y[i] += 0.49 * skin * sin(a);
    }
    assert_false(cdem_neighbour_needs_rebuild(&nb, &s));
    uint64_t *touch = NULL;
    size_t ntouch = brute_pairs(&s, 1.0, 0.0, &touch);
    uint64_t *lk = malloc((nb.np + 1) * sizeof *lk);
    for (size_t p = 0; p < nb.np; p++)
        lk[p] = cdem_pair_key(s.id[nb.pi[p]], s.id[nb.pj[p]]);
    qsort(lk, nb.np, sizeof *lk, cmp_u64);
    for (size_t k = 0; k < ntouch; k++)
        assert_non_null(bsearch(&touch[k], lk, nb.np, sizeof *lk, cmp_u64));
    free(lk);
    free(touch);
    /* one element beyond half the skin: rebuild, and the new list is exact again */
    s.x[17] += 0.6 * skin;
    assert_true(cdem_neighbour_needs_rebuild(&nb, &s));
    for (int round = 0; round < 3; round++) {
        for (size_t i = 0; i < s.n; i++) {
            s.x[i] += (rnd(&g) - 0.5) * 4.0 * skin;
            s.y[i] += (rnd(&g) - 0.5) * 4.0 * skin;
        }
        assert_true(cdem_neighbour_needs_rebuild(&nb, &s));
        assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, round == 1 ? 1 : 0, &err), CDEM_OK);
        assert_list_equals_brute(&nb, &s);
    }
    assert_true(nb.n_sorts >= 1);
    /* bonded reach: pairs up to R (1 + r0) + skin */
    cdem_neighbour nb2;
    assert_int_equal(cdem_neighbour_init(&nb2, skin, 1.1, 5, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_build(&nb2, &s, NULL, 0, &err), CDEM_OK);
    assert_list_equals_brute(&nb2, &s);
    assert_true(nb2.np > nb.np);
    cdem_neighbour_free(&nb2);
    cdem_neighbour_free(&nb);
    cdem_state_free(&s);
}

/* A history value derived from the pair's ids, to check it follows the pair. */
static double tag(uint64_t key) {
    return (double)(key % 100003) * 1e-3 + 1.0;
}

static void test_neighbour_history_survives_resort_and_removal(void **st) {
    (void)st;
    cdem_state s;
    make_cloud(&s, 600, 3000.0, 9);
    cdem_neighbour nb;
    cdem_error err;
    assert_int_equal(cdem_neighbour_init(&nb, 12.5, 1.0, 1000, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, -1, &err), CDEM_OK);
    const size_t np0 = nb.np;
    for (size_t p = 0; p < nb.np; p++) {
        uint64_t key = cdem_pair_key(s.id[nb.pi[p]], s.id[nb.pj[p]]);
        nb.xs[p] = tag(key);
        nb.hist[p] = (uint8_t)(CDEM_PAIR_TOUCH | ((key & 1) ? CDEM_PAIR_COHESIVE : 0));
    }
    /* forced re-sort into cell order: indices change, histories follow the ids */
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, 1, &err), CDEM_OK);
    assert_int_equal(nb.np, np0);
    for (size_t p = 0; p < nb.np; p++) {
        uint64_t key = cdem_pair_key(s.id[nb.pi[p]], s.id[nb.pj[p]]);
        assert_float_equal(nb.xs[p], tag(key), 0.0);
        assert_int_equal(nb.hist[p], CDEM_PAIR_TOUCH | ((key & 1) ? CDEM_PAIR_COHESIVE : 0));
    }
    /* ids are sorted by cell now, not by creation: the permutation really happened */
    int unsorted = 0;
    for (size_t i = 1; i < s.n; i++)
        unsorted |= s.id[i] < s.id[i - 1];
    assert_true(unsorted);
    /* remove every 7th element */
    unsigned char *keep = malloc(s.n);
    int32_t *gone = malloc(s.n * sizeof *gone);
    size_t ngone = 0;
    for (size_t i = 0; i < s.n; i++) {
        keep[i] = (unsigned char)(s.id[i] % 7 != 0);
        if (!keep[i])
            gone[ngone++] = s.id[i];
    }
    size_t n_before = s.n;
    assert_int_equal(cdem_neighbour_build(&nb, &s, keep, 0, &err), CDEM_OK);
    assert_int_equal(s.n, n_before - ngone);
    for (size_t i = 0; i < s.n; i++)
        assert_int_not_equal(s.id[i] % 7, 0);
    for (size_t p = 0; p < nb.np; p++) {
        uint64_t key = cdem_pair_key(s.id[nb.pi[p]], s.id[nb.pj[p]]);
        assert_float_equal(nb.xs[p], tag(key), 0.0);
    }
    assert_list_equals_brute(&nb, &s);
    free(keep);
    free(gone);
    cdem_neighbour_free(&nb);
    cdem_state_free(&s);
}

/* Slot k of the pair with key `key`, as the test writes it. */
static double slot_tag(uint64_t key, int k) {
    return tag(key) * (double)(k + 2);
}

/* 1 when every pair of nb (state s) that carries a history has its slots tagged, and every
 * other pair has them at 0 (a new pair's). */
static int slots_follow_ids(const cdem_neighbour *nb, const cdem_state *s) {
    const int m = nb->slot_count;
    for (size_t p = 0; p < nb->np; p++) {
        const uint64_t key = cdem_pair_key(s->id[nb->pi[p]], s->id[nb->pj[p]]);
        for (int k = 0; k < m; k++) {
            const double want = nb->hist[p] ? slot_tag(key, k) : 0.0;
            if (nb->slots[p * (size_t)m + (size_t)k] != want)
                return 0;
        }
    }
    return 1;
}

/* A law's history slots (two a pair here) travel with their pairs as xs does: through a
 * forced re-sort, element removal and a threaded build, and through a checkpoint; a pair
 * without a history (no flags: not a contact) does not keep them. A list restored for another
 * slot count is refused, naming it; the count is fixed before the first build; a list
 * without slots stores none. */
static void test_neighbour_slots_carried_and_stored(void **st) {
    (void)st;
    cdem_state s;
    make_cloud(&s, 600, 3000.0, 9);
    cdem_neighbour nb;
    cdem_error err;
    assert_int_equal(cdem_neighbour_init(&nb, 12.5, 1.0, 1000, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_set_slots(&nb, 2, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, -1, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_set_slots(&nb, 1, &err), CDEM_ERR_INVALID);
    assert_true(nb.np > 100);
    for (size_t p = 0; p < nb.np; p++) {
        const uint64_t key = cdem_pair_key(s.id[nb.pi[p]], s.id[nb.pj[p]]);
        assert_true(nb.slots[2 * p] == 0.0 && nb.slots[2 * p + 1] == 0.0); /* new pairs */
        nb.hist[p] = (uint8_t)(key % 3 == 0 ? 0 : CDEM_PAIR_TOUCH);
        for (int k = 0; k < 2; k++)
            nb.slots[2 * p + (size_t)k] = slot_tag(key, k); /* also where hist is 0 */
    }
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, 1, &err), CDEM_OK); /* re-sort */
    assert_true(slots_follow_ids(&nb, &s));
    unsigned char *keep = malloc(s.n);
    for (size_t i = 0; i < s.n; i++)
        keep[i] = (unsigned char)(s.id[i] % 7 != 0);
    assert_int_equal(cdem_neighbour_build(&nb, &s, keep, 0, &err), CDEM_OK); /* removal */
    free(keep);
    assert_true(slots_follow_ids(&nb, &s));
    nb.par_min = 0;
    omp_set_num_threads(2);
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, 1, &err), CDEM_OK); /* threaded */
    omp_set_num_threads(1);
    assert_true(slots_follow_ids(&nb, &s));
    /* a checkpoint and its restore: the same slots, pair for pair */
    cdem_snapshot *snap = NULL;
    assert_int_equal(cdem_snapshot_alloc(&snap, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_snapshot_put(&nb, snap, &err), CDEM_OK);
    cdem_neighbour back;
    assert_int_equal(cdem_neighbour_init(&back, 12.5, 1.0, 1000, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_set_slots(&back, 2, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_snapshot_get(&back, snap, &s, &err), CDEM_OK);
    assert_int_equal(back.np, nb.np);
    assert_memory_equal(back.slots, nb.slots, 2 * nb.np * sizeof *nb.slots);
    cdem_neighbour_free(&back);
    /* another law's count is refused, naming it */
    for (int other = 0; other <= 3; other += 3) {
        assert_int_equal(cdem_neighbour_init(&back, 12.5, 1.0, 1000, &err), CDEM_OK);
        assert_int_equal(cdem_neighbour_set_slots(&back, other, &err), CDEM_OK);
        assert_int_equal(cdem_neighbour_snapshot_get(&back, snap, &s, &err), CDEM_ERR_CONFLICT);
        assert_non_null(strstr(err.msg, "nb.slot_count = 2"));
        cdem_neighbour_free(&back);
    }
    /* a list without slots stores none, and a restore with slots refuses it */
    cdem_neighbour plain;
    cdem_snapshot *snap0 = NULL;
    assert_int_equal(cdem_snapshot_alloc(&snap0, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_init(&plain, 12.5, 1.0, 1000, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_build(&plain, &s, NULL, -1, &err), CDEM_OK);
    assert_null(plain.slots);
    assert_int_equal(cdem_neighbour_snapshot_put(&plain, snap0, &err), CDEM_OK);
    assert_null(cdem_snapshot_get(snap0, "nb.slots"));
    assert_null(cdem_snapshot_get(snap0, "nb.slot_count"));
    assert_int_equal(cdem_neighbour_init(&back, 12.5, 1.0, 1000, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_set_slots(&back, 2, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_snapshot_get(&back, snap0, &s, &err), CDEM_ERR_CONFLICT);
    assert_non_null(strstr(err.msg, "nb.slot_count = 0"));
    cdem_neighbour_free(&back);
    cdem_neighbour_free(&plain);
    cdem_snapshot_free(snap0);
    cdem_snapshot_free(snap);
    cdem_neighbour_free(&nb);
    cdem_state_free(&s);
}

/* The re-sort orders the elements by cell along the grid's short side first (neighbour.c),
 * so that the threads' chunks, index ranges, are cut across it: in a wide cloud the first
 * half of the indices lies left of the second (up to one cell), in a high one below it, and
 * the walls are spread over both halves (they used to be sorted after the free elements). */
static void test_neighbour_order_along_short_side(void **st) {
    (void)st;
    for (int high = 0; high < 2; high++) {
        cdem_state s;
        make_box(&s, 1200, high ? 2000.0 : 8000.0, high ? 8000.0 : 2000.0, 7);
        cdem_neighbour nb;
        cdem_error err;
        const double skin = 12.5;
        assert_int_equal(cdem_neighbour_init(&nb, skin, 1.0, 5, &err), CDEM_OK);
        assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, 1, &err), CDEM_OK);
        const size_t n = s.n, half = n / 2;
        double max_lo = -INFINITY, min_hi = INFINITY;
        size_t walls = 0, walls_lo = 0;
        for (size_t i = 0; i < n; i++) {
            const double along = high ? s.y[i] : s.x[i];
            if (i < half)
                max_lo = fmax(max_lo, along);
            else
                min_hi = fmin(min_hi, along);
            if (s.flags[i] & CDEM_FLAG_WALL) {
                walls++;
                walls_lo += i < half;
            }
        }
        const double cell = 2.0 * 125.0 + skin; /* the largest reach and the skin */
        assert_true(max_lo <= min_hi + cell);
        assert_true(walls == 120);
        assert_true(walls_lo > 40 && walls_lo < 80);
        cdem_neighbour_free(&nb);
        cdem_state_free(&s);
    }
}

static void test_neighbour_rejects_bad_input(void **st) {
    (void)st;
    cdem_neighbour nb;
    cdem_error err;
    assert_int_equal(cdem_neighbour_init(&nb, 0.0, 1.0, 5, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "skin"));
    assert_int_equal(cdem_neighbour_init(&nb, 1.0, 0.5, 5, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "reach factor"));
    cdem_state s;
    make_cloud(&s, 50, 1000.0, 3);
    s.y[12] = NAN;
    assert_int_equal(cdem_neighbour_init(&nb, 5.0, 1.0, 5, &err), CDEM_OK);
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, 0, &err), CDEM_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "element id 12"));
    /* a stray element far away does not blow up the grid */
    s.y[12] = 1.0e12;
    assert_int_equal(cdem_neighbour_build(&nb, &s, NULL, 0, &err), CDEM_OK);
    cdem_neighbour_free(&nb);
    cdem_neighbour_free(NULL);
    cdem_state_free(&s);
}

/* The list of nb (state s) is the list of ref (state rs), array by array: the elements'
 * order, the pairs with their histories, the CSR and the cells. */
static void assert_same_list(const cdem_neighbour *nb, const cdem_state *s,
                             const cdem_neighbour *ref, const cdem_state *rs) {
    const size_t np = ref->np, n = rs->n;
    assert_int_equal(nb->np, np);
    assert_int_equal(s->n, n);
    assert_memory_equal(s->id, rs->id, n * sizeof *rs->id);
    assert_memory_equal(nb->pi, ref->pi, np * sizeof *ref->pi);
    assert_memory_equal(nb->pj, ref->pj, np * sizeof *ref->pj);
    assert_memory_equal(nb->R, ref->R, np * sizeof *ref->R);
    assert_memory_equal(nb->cls, ref->cls, np * sizeof *ref->cls);
    assert_memory_equal(nb->hist, ref->hist, np * sizeof *ref->hist);
    assert_memory_equal(nb->xs, ref->xs, np * sizeof *ref->xs);
    assert_memory_equal(nb->jslot, ref->jslot, np * sizeof *ref->jslot);
    assert_memory_equal(nb->istart, ref->istart, (n + 1) * sizeof *ref->istart);
    assert_memory_equal(nb->jstart, ref->jstart, (n + 1) * sizeof *ref->jstart);
    assert_memory_equal(nb->cell_of, ref->cell_of, n * sizeof *ref->cell_of);
}

/* The threaded build (par_min 0, 1..3 threads: the enumeration over contiguous element
 * ranges, the carried histories, the bounding box and cells, the CSR) gives the same list,
 * slot for slot, as the serial one, and it equals brute force; so does a second build that
 * carries histories through a re-sort. */
static void test_neighbour_threaded_build_same_list(void **st) {
    (void)st;
    const int saved = omp_get_max_threads();
    cdem_state s[3];
    cdem_neighbour nb[3];
    cdem_error err;
    for (int t = 0; t < 3; t++) {
        make_cloud(&s[t], 3000, 12000.0, 4242);
        assert_int_equal(cdem_neighbour_init(&nb[t], 12.5, 1.0, 1, &err), CDEM_OK);
        nb[t].par_min = t == 0 ? 1000000 : 0;
        omp_set_num_threads(t + 1);
        assert_int_equal(cdem_neighbour_build(&nb[t], &s[t], NULL, 1, &err), CDEM_OK);
    }
    omp_set_num_threads(saved);
    uint64_t *bk = NULL;
    const size_t nbk = brute_pairs(&s[0], nb[0].reach_factor, nb[0].skin, &bk);
    assert_int_equal(nb[0].np, nbk);
    assert_true(nbk > 3000);
    for (size_t p = 0; p < nb[0].np; p++)
        assert_true(nb[0].hist[p] == 0 && nb[0].xs[p] == 0.0);
    for (int t = 1; t < 3; t++)
        assert_same_list(&nb[t], &s[t], &nb[0], &s[0]);
    /* histories on some pairs, every element moved a little, built again with a re-sort */
    for (int t = 0; t < 3; t++) {
        for (size_t p = 0; p < nb[t].np; p++) {
            nb[t].hist[p] = p % 3 == 0 ? CDEM_PAIR_TOUCH : 0;
            nb[t].xs[p] = p % 5 == 0 ? 1e-6 * (double)p : 0.0;
        }
        for (size_t i = 0; i < s[t].n; i++) {
            s[t].x[i] += 0.5 * sin((double)s[t].id[i]);
            s[t].y[i] += 0.5 * cos((double)s[t].id[i]);
        }
        omp_set_num_threads(t + 1);
        assert_int_equal(cdem_neighbour_build(&nb[t], &s[t], NULL, 1, &err), CDEM_OK);
    }
    omp_set_num_threads(saved);
    size_t carried = 0;
    for (size_t p = 0; p < nb[0].np; p++)
        carried += nb[0].hist[p] != 0;
    assert_true(carried > 1000);
    for (int t = 1; t < 3; t++) {
        assert_int_equal(nb[t].ncarry, nb[0].ncarry);
        assert_same_list(&nb[t], &s[t], &nb[0], &s[0]);
    }
    free(bk);
    for (int t = 0; t < 3; t++) {
        cdem_neighbour_free(&nb[t]);
        cdem_state_free(&s[t]);
    }
}

/* The vector distance test of the build (neighbour_avx2.c) gives the scalar test's list, slot
 * for slot with the same R bits, serial and on 2 threads, on a first build and on one after
 * every element moved (no re-sort: the cell order then differs from the index order), and the
 * list of brute force. Elements exactly at the reach of their neighbours are included. */
static void test_neighbour_vector_test_same_list(void **st) {
    (void)st;
    if (!cdem_neighbour_avx2_usable()) {
        fprintf(stderr, "test_neighbour: no AVX2 on this CPU: vector test not compared\n");
        return;
    }
    const int saved = omp_get_max_threads();
    enum { RUNS = 4 };
    cdem_state s[RUNS];
    cdem_neighbour nb[RUNS];
    cdem_error err;
    for (int t = 0; t < RUNS; t++) {
        make_cloud(&s[t], 3000, 12000.0, 777);
        /* a few pairs exactly at the reach (R + skin apart in x) */
        for (size_t k = 0; k + 1 < 40; k += 2) {
            s[t].x[k + 1] = s[t].x[k] + s[t].radius[k] + s[t].radius[k + 1] + 12.5;
            s[t].y[k + 1] = s[t].y[k];
        }
        assert_int_equal(cdem_neighbour_init(&nb[t], 12.5, 1.0, 1000, &err), CDEM_OK);
        nb[t].simd = t % 2 == 0 ? 1 : 2; /* scalar, vector */
        nb[t].par_min = t < 2 ? 1000000 : 0;
        omp_set_num_threads(t < 2 ? 1 : 2);
        assert_int_equal(cdem_neighbour_build(&nb[t], &s[t], NULL, 1, &err), CDEM_OK);
    }
    uint64_t *bk = NULL;
    const size_t nbk = brute_pairs(&s[0], nb[0].reach_factor, nb[0].skin, &bk);
    assert_int_equal(nb[0].np, nbk);
    for (int t = 1; t < RUNS; t++)
        assert_same_list(&nb[t], &s[t], &nb[0], &s[0]);
    for (int t = 0; t < RUNS; t++) {
        for (size_t i = 0; i < s[t].n; i++) {
            s[t].x[i] += 40.0 * sin((double)s[t].id[i]);
            s[t].y[i] += 40.0 * cos((double)s[t].id[i]);
        }
        omp_set_num_threads(t < 2 ? 1 : 2);
        assert_int_equal(cdem_neighbour_build(&nb[t], &s[t], NULL, -1, &err), CDEM_OK);
        assert_int_equal(nb[t].simd, t % 2 == 0 ? 1 : 2);
    }
    omp_set_num_threads(saved);
    for (int t = 1; t < RUNS; t++)
        assert_same_list(&nb[t], &s[t], &nb[0], &s[0]);
    free(bk);
    for (int t = 0; t < RUNS; t++) {
        cdem_neighbour_free(&nb[t]);
        cdem_state_free(&s[t]);
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_neighbour_matches_brute_force),
        cmocka_unit_test(test_neighbour_history_survives_resort_and_removal),
        cmocka_unit_test(test_neighbour_slots_carried_and_stored),
        cmocka_unit_test(test_neighbour_order_along_short_side),
        cmocka_unit_test(test_neighbour_rejects_bad_input),
        cmocka_unit_test(test_neighbour_threaded_build_same_list),
        cmocka_unit_test(test_neighbour_vector_test_same_list),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
