/* core/comm under mpirun -np 1, 2 and 3 (and without mpirun: one rank): every reduction, the
 * rank-order double sum (the same bits on every rank), bcast, allgatherv and alltoallv with empty,
 * unequal and self blocks, comm_exchange around a ring, the end-of-run agreement, and the
 * traffic counters. Each collective also runs with a message limit of a few bytes, which takes
 * the chunked and point-to-point paths meant for messages beyond 2 GiB.
 *
 * A check that fails on one rank must not leave the others waiting in the next collective: the
 * checks record locally (CHECK), and each test ends with every rank agreeing on the outcome. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/comm.h"

static int bad; /* checks failed on this rank in the current test */

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            if (!bad++)                                                                            \
                fprintf(stderr, "rank %d: %s:%d: check failed: %s\n", comm_rank(), __FILE__,       \
                        __LINE__, #cond);                                                          \
        }                                                                                          \
    } while (0)

/* Every rank passes or fails the test together. */
static void agree(void)
{
    int any = comm_any(bad);
    bad = 0;
    assert_false(any);
}

static int setup(void **state)
{
    (void)state;
    bad = 0;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    comm_set_message_limit(0);
    return 0;
}

/* The message limits each collective test runs with: the defaults, then 7 bytes. */
static const size_t limits[] = {0, 7};

static void test_ranks(void **state)
{
    (void)state;
    const char *env = getenv("OMPI_COMM_WORLD_SIZE");
    CHECK(comm_size() == (env ? atoi(env) : 1));
    CHECK(comm_rank() >= 0 && comm_rank() < comm_size());
    CHECK(comm_available() == 1);
    comm_barrier();
    agree();
}

static void test_reductions(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    for (size_t l = 0; l < sizeof limits / sizeof *limits; l++) {
        comm_set_message_limit(limits[l]);
        double d[3] = {me, -0.5 * me, 1.0 + me}, lo[3] = {d[0], d[1], d[2]}, hi[3];
        memcpy(hi, d, sizeof d);
        comm_sum_double(d, 3);
        comm_min_double(lo, 3);
        comm_max_double(hi, 3);
        double s = 0.5 * P * (P - 1);
        CHECK(d[0] == s && d[1] == -0.5 * s && d[2] == P + s);
        CHECK(lo[0] == 0 && lo[1] == -0.5 * (P - 1) && lo[2] == 1);
        CHECK(hi[0] == P - 1 && hi[1] == 0 && hi[2] == P);

        int64_t big = INT64_C(1) << 40;
        int64_t i[2] = {big + me, -me}, imin[2] = {i[0], i[1]}, imax[2] = {i[0], i[1]};
        comm_sum_i64(i, 2);
        comm_min_i64(imin, 2);
        comm_max_i64(imax, 2);
        CHECK(i[0] == big * P + P * (P - 1) / 2 && i[1] == -(int64_t)P * (P - 1) / 2);
        CHECK(imin[0] == big && imin[1] == -(P - 1));
        CHECK(imax[0] == big + P - 1 && imax[1] == 0);

        comm_sum_double(d, 0); /* nothing to do, on every rank */
        CHECK(comm_any(me == P - 1) == 1);
        CHECK(comm_any(0) == 0);
        CHECK(comm_all(me == P - 1) == (P == 1));
        CHECK(comm_all(7) == 1);
    }
    agree();
}

/* comm_sum_double adds in rank order, left to right, from rank 0's value: exactly the sum a
 * single process would form, on every rank. */
static void test_sum_double_bits(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    double mine[3] = {1e16 * (me + 1) / 3.0, 0.1 * (me + 1), -0.0};
    double v[3] = {mine[0], mine[1], mine[2]};
    comm_sum_double(v, 3);
    double want0 = 1e16 / 3.0, want1 = 0.1;
    for (int r = 1; r < P; r++)
        want0 += 1e16 * (r + 1) / 3.0, want1 += 0.1 * (r + 1);
    CHECK(memcmp(&v[0], &want0, sizeof want0) == 0);
    CHECK(memcmp(&v[1], &want1, sizeof want1) == 0);
    CHECK(v[2] == 0 && signbit(v[2])); /* -0.0 summed stays -0.0, as on one rank */
    /* the same bits everywhere */
    void *all = NULL;
    size_t bytes = 0;
    CHECK(comm_allgatherv(v, sizeof v, &all, &bytes, NULL) == 0);
    CHECK(bytes == (size_t)P * sizeof v);
    for (int r = 0; r < P && all; r++)
        CHECK(memcmp((char *)all + (size_t)r * sizeof v, v, sizeof v) == 0);
    free(all);
    agree();
}

static void test_bcast(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    for (size_t l = 0; l < sizeof limits / sizeof *limits; l++) {
        comm_set_message_limit(limits[l]);
        for (int root = 0; root < P; root++) {
            unsigned char buf[1000];
            for (int k = 0; k < 1000; k++)
                buf[k] = me == root ? (unsigned char)(k * 7 + root) : 0xee;
            comm_bcast(buf, sizeof buf, root);
            int same = 1;
            for (int k = 0; k < 1000; k++)
                same &= buf[k] == (unsigned char)(k * 7 + root);
            CHECK(same);
            comm_bcast(buf, 0, root); /* empty */
        }
    }
    agree();
}

/* Rank r contributes r bytes of value r + 1 (rank 0 nothing). */
static void test_allgatherv(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    for (size_t l = 0; l < sizeof limits / sizeof *limits; l++) {
        comm_set_message_limit(limits[l]);
        unsigned char mine[8];
        memset(mine, me + 1, sizeof mine);
        size_t counts[8];
        void *out = NULL;
        size_t n = 0;
        CHECK(comm_allgatherv(mine, (size_t)me, &out, &n, counts) == 0);
        CHECK(n == (size_t)P * (P - 1) / 2);
        size_t at = 0;
        for (int r = 0; r < P; r++) {
            CHECK(counts[r] == (size_t)r);
            for (int k = 0; k < r; k++)
                CHECK(((unsigned char *)out)[at + k] == r + 1);
            at += counts[r];
        }
        free(out);
        /* every contribution empty */
        out = NULL;
        CHECK(comm_allgatherv(mine, 0, &out, &n, NULL) == 0);
        CHECK(out != NULL && n == 0);
        free(out);
    }
    agree();
}

/* Rank s sends (s + 2 * r) % 4 bytes to rank r -- empty blocks, unequal ones, one to itself --
 * from a send buffer laid out in reverse rank order with gaps; byte k of the block is
 * 16 * s + r + k. */
static void test_alltoallv(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    for (size_t l = 0; l < sizeof limits / sizeof *limits; l++) {
        comm_set_message_limit(limits[l]);
        size_t sb[8], so[8], rb[8], ro[8], at = 3;
        unsigned char send[64];
        memset(send, 0xaa, sizeof send);
        for (int r = P - 1; r >= 0; r--) {
            sb[r] = (size_t)((me + 2 * r) % 4);
            so[r] = at;
            for (size_t k = 0; k < sb[r]; k++)
                send[at + k] = (unsigned char)(16 * me + r + (int)k);
            at += sb[r] + 2;
        }
        void *recv = NULL;
        CHECK(comm_alltoallv(send, sb, so, &recv, rb, ro) == 0);
        size_t expect_off = 0;
        for (int s = 0; s < P; s++) {
            CHECK(rb[s] == (size_t)((s + 2 * me) % 4));
            CHECK(ro[s] == expect_off);
            for (size_t k = 0; k < rb[s]; k++)
                CHECK(((unsigned char *)recv)[ro[s] + k] == (unsigned char)(16 * s + me + (int)k));
            expect_off += rb[s];
        }
        free(recv);
    }
    agree();
}

/* Around a ring: each rank sends 3 + me bytes to its left neighbour and 5 + 2 me to its right
 * one, in one call. With three ranks or more the neighbours differ: from the left comes what it
 * sent to its right. With one or two ranks both neighbours are one process (the other rank, or
 * this one across the seam): messages pair in the order of k, so the first buffer gets that
 * process's first message (its to_left), the second its to_right. */
static void test_exchange_ring(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    const int left = (me + P - 1) % P, right = (me + 1) % P;
    for (size_t l = 0; l < sizeof limits / sizeof *limits; l++) {
        comm_set_message_limit(limits[l]);
        unsigned char to_left[64], to_right[64], r0[64], r1[64];
        for (size_t k = 0; k < 64; k++)
            to_left[k] = (unsigned char)(me + 10 * k), to_right[k] = (unsigned char)(me + 7 * k);
        int peers[2] = {left, right};
        const void *s[2] = {to_left, to_right};
        void *r[2] = {r0, r1};
        size_t sbytes[2] = {3 + (size_t)me, 5 + 2 * (size_t)me}, rbytes[2];
        if (P >= 3)
            rbytes[0] = 5 + 2 * (size_t)left, rbytes[1] = 3 + (size_t)right;
        else
            rbytes[0] = 3 + (size_t)left, rbytes[1] = 5 + 2 * (size_t)right;
        memset(r0, 0xee, sizeof r0), memset(r1, 0xee, sizeof r1);
        comm_exchange(2, peers, s, sbytes, r, rbytes, 3);
        for (size_t k = 0; k < rbytes[0]; k++)
            CHECK(r0[k] == (unsigned char)(left + (P >= 3 ? 7 : 10) * k));
        for (size_t k = 0; k < rbytes[1]; k++)
            CHECK(r1[k] == (unsigned char)(right + (P >= 3 ? 10 : 7) * k));
        CHECK(r0[rbytes[0]] == 0xee && r1[rbytes[1]] == 0xee); /* nothing beyond */
        comm_exchange(0, NULL, NULL, NULL, NULL, NULL, 4);     /* no peers: returns at once */
    }
    agree();
}

static void test_agree(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    int64_t mine[2] = {me, 100 + me}, all[16];
    CHECK(comm_agree(mine, all, -1) == 0);
    for (int r = 0; r < P; r++)
        CHECK(all[2 * r] == r && all[2 * r + 1] == 100 + r);
    agree();
}

static void test_stats(void **state)
{
    (void)state;
    const int P = comm_size(), me = comm_rank();
    comm_stats st;
    comm_reset_stats();
    comm_get_stats(&st);
    CHECK(st.bytes == 0 && st.messages == 0 && st.calls == 0 && st.seconds == 0);

    char buf[100] = {0};
    comm_bcast(buf, sizeof buf, 0);
    comm_get_stats(&st);
    CHECK(st.calls == (P > 1));
    CHECK(st.bytes == (me == 0 ? 100.0 * (P - 1) : 0));
    CHECK(st.messages == (me == 0 ? P - 1 : 0));

    /* alltoallv: bytes to the other ranks only; its internal agreements are not counted again */
    comm_reset_stats();
    size_t sb[8], so[8], rb[8], ro[8];
    char send[8 * 8] = {0};
    for (int r = 0; r < P; r++)
        sb[r] = (size_t)(r + 1), so[r] = 8 * (size_t)r;
    void *recv = NULL;
    CHECK(comm_alltoallv(send, sb, so, &recv, rb, ro) == 0);
    free(recv);
    comm_get_stats(&st);
    double to_others = 0.5 * P * (P + 1) - (me + 1);
    CHECK(st.calls == (P > 1));
    CHECK(st.bytes == (P > 1 ? to_others : 0));
    CHECK(st.messages == P - 1);

    /* a reduction: n values, one message to each other rank */
    comm_reset_stats();
    double d[4] = {0};
    comm_max_double(d, 4);
    comm_get_stats(&st);
    CHECK(st.calls == (P > 1) && st.bytes == (P > 1 ? 32 : 0) && st.messages == P - 1);
    CHECK(st.seconds >= 0);
    agree();
}

int main(int argc, char **argv)
{
    comm_init(&argc, &argv);
    if (comm_size() > 8) {
        fprintf(stderr, "test_comm: at most 8 ranks\n");
        comm_abort(1);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_ranks, setup, teardown),
        cmocka_unit_test_setup_teardown(test_reductions, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sum_double_bits, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bcast, setup, teardown),
        cmocka_unit_test_setup_teardown(test_allgatherv, setup, teardown),
        cmocka_unit_test_setup_teardown(test_alltoallv, setup, teardown),
        cmocka_unit_test_setup_teardown(test_exchange_ring, setup, teardown),
        cmocka_unit_test_setup_teardown(test_agree, setup, teardown),
        cmocka_unit_test_setup_teardown(test_stats, setup, teardown),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    comm_finalize();
    return failed ? 1 : 0;
}
