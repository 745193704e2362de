/* Processes of a distributed run over MPI (see comm.h). The one file of grainlab that includes
 * mpi.h. Built without GRAINLAB_HAVE_MPI, every function is the one-rank answer. */
#define _POSIX_C_SOURCE 200809L
#include "core/comm.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef GRAINLAB_HAVE_MPI
#include <mpi.h>
#endif

#include "core/clock.h"

static int comm_r, comm_n = 1;
static comm_stats stats;

/* Bytes per MPI call (counts are int), and the largest total a v-collective moves with int
 * counts and displacements; tests lower both to take the large-message paths with small data. */
static size_t chunk = (size_t)1 << 30;
static size_t int_limit = (size_t)INT_MAX;

void comm_set_message_limit(size_t bytes)
{
    if (bytes == 0) {
        chunk = (size_t)1 << 30;
        int_limit = (size_t)INT_MAX;
    } else {
        chunk = bytes < ((size_t)1 << 30) ? bytes : (size_t)1 << 30;
        int_limit = bytes < (size_t)INT_MAX ? bytes : (size_t)INT_MAX;
    }
}
#define CHUNK chunk

/* Messages to and from this rank itself (a periodic seam on one rank): matched in the order of
 * k, as MPI matches messages between one pair of ranks with one tag. */
static void exchange_self(int npeers, const int *peers, const void *const *send,
                          const size_t *send_bytes, void *const *recv, const size_t *recv_bytes)
{
    int j = 0;
    for (int k = 0; k < npeers; k++) {
        if (peers[k] != comm_r)
            continue;
        while (j < npeers && peers[j] != comm_r)
            j++;
        if (j == npeers)
            return;
        size_t n = send_bytes[k] < recv_bytes[j] ? send_bytes[k] : recv_bytes[j];
        if (n)
            memmove(recv[j], send[k], n);
        j++;
    }
}

/* One rank's all-to-all: its own block, copied (with or without MPI). */
static int alltoallv_self(const void *send, const size_t *send_bytes, const size_t *send_off,
                          void **recv, size_t *recv_bytes, size_t *recv_off)
{
    recv_bytes[0] = send_bytes[0];
    recv_off[0] = 0;
    *recv = malloc(send_bytes[0] ? send_bytes[0] : 1);
    if (!*recv)
        return -1;
    memcpy(*recv, (const char *)send + send_off[0], send_bytes[0]);
    return 0;
}

int comm_available(void)
{
#ifdef GRAINLAB_HAVE_MPI
    return 1;
#else
    return 0;
#endif
}

int comm_rank(void) { return comm_r; }
int comm_size(void) { return comm_n; }

void comm_get_stats(comm_stats *out) { *out = stats; }
void comm_reset_stats(void) { memset(&stats, 0, sizeof stats); }

#ifdef GRAINLAB_HAVE_MPI

static int comm_on; /* MPI_Init was called */
static int depth;   /* comm calls in progress: only the outermost one counts in the stats */

/* Launched by mpirun (Open MPI sets OMPI_COMM_WORLD_SIZE; PMIx- and PMI-based launchers set
 * PMIX_RANK or PMI_RANK). A plain run does not start MPI's runtime at all. */
static int launched_by_mpirun(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
}

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
/* Sanitizer builds only: Open MPI unloads its components in MPI_Finalize, before LeakSanitizer
 * reports the allocations they keep for the life of the process; their frames then have no
 * module name, and tests/mpi/lsan_mpi.supp could not tell them from ours. Keeping every library
 * loaded to the end (as valgrind users of Open MPI do) names them. */
int dlclose(void *handle)
{
    (void)handle;
    return 0;
}
#endif

/* The end-of-run agreement (comm_agree) runs on a communicator of its own, so that a rank
 * waiting there never matches a data collective that the other ranks are blocked in. */
static MPI_Comm ctl = MPI_COMM_NULL;

void comm_init(int *argc, char ***argv)
{
    if (comm_on || !launched_by_mpirun())
        return;
    int provided = 0;
    /* Threads (OpenMP) run inside a rank, but only the main thread calls MPI. */
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    comm_on = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &comm_r);
    MPI_Comm_size(MPI_COMM_WORLD, &comm_n);
    MPI_Comm_dup(MPI_COMM_WORLD, &ctl);
}

void comm_finalize(void)
{
    if (comm_on) {
        if (ctl != MPI_COMM_NULL)
            MPI_Comm_free(&ctl);
        MPI_Finalize();
    }
    comm_on = 0;
}

void comm_abort(int code)
{
    fflush(stdout);
    fflush(stderr);
    if (comm_on && comm_n > 1)
        MPI_Abort(MPI_COMM_WORLD, code);
    if (comm_on) /* one rank under mpirun: an exit without MPI_Finalize is reported as a crash */
        MPI_Finalize();
    exit(code);
}

int comm_agree(const int64_t mine[2], int64_t *all, double timeout_s)
{
    if (!comm_on || comm_n == 1) {
        all[0] = mine[0], all[1] = mine[1];
        return 0;
    }
    MPI_Request req;
    MPI_Iallgather(mine, 2, MPI_INT64_T, all, 2, MPI_INT64_T, ctl, &req);
    double t0 = clock_wall();
    for (;;) {
        int done = 0;
        MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        if (done)
            return 0;
        if (timeout_s >= 0 && clock_wall() - t0 > timeout_s)
            return -1; /* the caller aborts the run: the request dies with it */
        struct timespec nap = {0, 1000000};
        nanosleep(&nap, NULL);
    }
}

static double t_enter(void) { return depth++ ? 0 : clock_wall(); }
static void t_leave(double t0, double bytes, double messages)
{
    if (--depth)
        return;
    stats.seconds += clock_wall() - t0;
    stats.bytes += bytes;
    stats.messages += messages;
    stats.calls++;
}

void comm_barrier(void)
{
    if (comm_n > 1) {
        double t0 = t_enter();
        MPI_Barrier(MPI_COMM_WORLD);
        t_leave(t0, 0, comm_n - 1);
    }
}

static void allreduce(void *v, size_t n, MPI_Datatype type, size_t size, MPI_Op op)
{
    if (comm_n == 1 || n == 0)
        return;
    double t0 = t_enter();
    size_t per = CHUNK / size ? CHUNK / size : 1;
    for (size_t off = 0; off < n; off += per) {
        size_t k = n - off < per ? n - off : per;
        MPI_Allreduce(MPI_IN_PLACE, (char *)v + off * size, (int)k, type, op, MPI_COMM_WORLD);
    }
    t_leave(t0, (double)(n * size), comm_n - 1);
}

void comm_sum_double(double *v, size_t n)
{
    if (comm_n == 1 || n == 0)
        return;
    /* Gather every rank's values and add them in rank order on every rank: the same bits on
     * all ranks whatever the reduction tree MPI would choose. */
    void *all = NULL;
    size_t bytes = 0;
    if (comm_allgatherv(v, n * sizeof *v, &all, &bytes, NULL) != 0)
        comm_abort(70);
    const double *a = all;
    for (size_t i = 0; i < n; i++) {
        double s = a[i]; /* not 0 + a[i]: -0.0 stays -0.0, as on one rank */
        for (int r = 1; r < comm_n; r++)
            s += a[(size_t)r * n + i];
        v[i] = s;
    }
    free(all);
}

void comm_min_double(double *v, size_t n) { allreduce(v, n, MPI_DOUBLE, sizeof *v, MPI_MIN); }
void comm_max_double(double *v, size_t n) { allreduce(v, n, MPI_DOUBLE, sizeof *v, MPI_MAX); }
void comm_sum_i64(int64_t *v, size_t n) { allreduce(v, n, MPI_INT64_T, sizeof *v, MPI_SUM); }
void comm_min_i64(int64_t *v, size_t n) { allreduce(v, n, MPI_INT64_T, sizeof *v, MPI_MIN); }
void comm_max_i64(int64_t *v, size_t n) { allreduce(v, n, MPI_INT64_T, sizeof *v, MPI_MAX); }

int comm_any(int flag)
{
    int v = flag != 0;
    allreduce(&v, 1, MPI_INT, sizeof v, MPI_LOR);
    return v;
}

int comm_all(int flag)
{
    int v = flag != 0;
    allreduce(&v, 1, MPI_INT, sizeof v, MPI_LAND);
    return v;
}

void comm_bcast(void *buf, size_t bytes, int root)
{
    if (comm_n == 1 || bytes == 0)
        return;
    double t0 = t_enter();
    for (size_t off = 0; off < bytes; off += CHUNK) {
        size_t k = bytes - off < CHUNK ? bytes - off : CHUNK;
        MPI_Bcast((char *)buf + off, (int)k, MPI_BYTE, root, MPI_COMM_WORLD);
    }
    t_leave(t0, comm_r == root ? (double)bytes * (comm_n - 1) : 0, comm_r == root ? comm_n - 1 : 0);
}

/* Byte counts between ranks go as MPI_BYTE in chunks below INT_MAX; counts and displacements of
 * the v-collectives are ints, so large transfers go through point-to-point messages instead.
 * Every block must end below the limit: a small block far into a large buffer does not fit. */
static int fits_int(const size_t *c, const size_t *off, int n)
{
    size_t total = 0;
    for (int r = 0; r < n; r++) {
        total += c[r];
        if (off && (off[r] > int_limit || c[r] > int_limit - off[r]))
            return 0;
    }
    return total <= int_limit;
}

int comm_alltoallv_max(const void *send, const size_t *send_bytes, const size_t *send_off,
                       void **recv, size_t *recv_bytes, size_t *recv_off, int64_t *words, int nw)
{
    const int P = comm_n;
    if (P == 1)
        return alltoallv_self(send, send_bytes, send_off, recv, recv_bytes, recv_off);
    double t0 = t_enter();
    /* Sizes first, each with the caller's words, which every rank reduces itself. */
    const size_t w = 1 + (size_t)nw;
    int64_t *sb = malloc(2 * (size_t)P * w * sizeof *sb);
    if (!sb)
        comm_abort(70);
    int64_t *rb = sb + (size_t)P * w;
    for (int r = 0; r < P; r++) {
        sb[(size_t)r * w] = (int64_t)send_bytes[r];
        for (int k = 0; k < nw; k++)
            sb[(size_t)r * w + 1 + (size_t)k] = words[k];
    }
    MPI_Alltoall(sb, (int)w, MPI_INT64_T, rb, (int)w, MPI_INT64_T, MPI_COMM_WORLD);
    size_t total = 0;
    for (int r = 0; r < P; r++) {
        recv_bytes[r] = (size_t)rb[(size_t)r * w];
        recv_off[r] = total;
        total += recv_bytes[r];
        for (int k = 0; k < nw; k++)
            if (rb[(size_t)r * w + 1 + (size_t)k] > words[k])
                words[k] = rb[(size_t)r * w + 1 + (size_t)k];
    }
    *recv = malloc(total ? total : 1);
    /* one agreement for both: the buffer was allocated, and every block fits MPI's int counts */
    int agree[2] = {*recv != NULL,
                    fits_int(send_bytes, send_off, P) && fits_int(recv_bytes, NULL, P)};
    allreduce(agree, 2, MPI_INT, sizeof *agree, MPI_LAND);
    if (!agree[0]) {
        free(*recv), *recv = NULL, free(sb);
        t_leave(t0, 0, 0);
        return -1;
    }
    double sent = 0, msgs = 0;
    for (int r = 0; r < P; r++)
        if (r != comm_r && send_bytes[r])
            sent += (double)send_bytes[r], msgs++;
    if (agree[1]) {
        int *ci = malloc(4 * (size_t)P * sizeof *ci);
        if (!ci)
            comm_abort(70);
        for (int r = 0; r < P; r++) {
            ci[r] = (int)send_bytes[r], ci[P + r] = (int)send_off[r];
            ci[2 * P + r] = (int)recv_bytes[r], ci[3 * P + r] = (int)recv_off[r];
        }
        MPI_Alltoallv(send, ci, ci + P, MPI_BYTE, *recv, ci + 2 * P, ci + 3 * P, MPI_BYTE,
                      MPI_COMM_WORLD);
        free(ci);
    } else {
        /* Our own copy, and point-to-point messages in chunks for the others. */
        memcpy((char *)*recv + recv_off[comm_r], (const char *)send + send_off[comm_r],
               send_bytes[comm_r]);
        int npeer = 0;
        int *peers = malloc((size_t)P * sizeof *peers);
        const void **sp = malloc((size_t)P * sizeof *sp);
        void **rp = malloc((size_t)P * sizeof *rp);
        size_t *sbz = malloc(2 * (size_t)P * sizeof *sbz);
        if (!peers || !sp || !rp || !sbz)
            comm_abort(70);
        for (int r = 0; r < P; r++) {
            if (r == comm_r)
                continue;
            peers[npeer] = r;
            sp[npeer] = (const char *)send + send_off[r];
            sbz[npeer] = send_bytes[r];
            rp[npeer] = (char *)*recv + recv_off[r];
            sbz[P + npeer] = recv_bytes[r];
            npeer++;
        }
        comm_exchange(npeer, peers, sp, sbz, rp, sbz + P, 0x7a11); /* counted once below */
        free(peers), free(sp), free(rp), free(sbz);
    }
    free(sb);
    t_leave(t0, sent, msgs);
    return 0;
}

int comm_alltoallv(const void *send, const size_t *send_bytes, const size_t *send_off, void **recv,
                   size_t *recv_bytes, size_t *recv_off)
{
    return comm_alltoallv_max(send, send_bytes, send_off, recv, recv_bytes, recv_off, NULL, 0);
}


void comm_exchange(int npeers, const int *peers, const void *const *send, const size_t *send_bytes,
                   void *const *recv, const size_t *recv_bytes, int tag)
{
    if (npeers == 0)
        return;
    if (!comm_on || comm_n == 1) { /* no MPI running: every peer is this rank */
        exchange_self(npeers, peers, send, send_bytes, recv, recv_bytes);
        return;
    }
    double t0 = t_enter();
    size_t nreq = 0;
    for (int k = 0; k < npeers; k++)
        nreq += (send_bytes[k] + CHUNK - 1) / CHUNK + (recv_bytes[k] + CHUNK - 1) / CHUNK;
    MPI_Request *req = malloc((nreq ? nreq : 1) * sizeof *req);
    if (!req)
        comm_abort(70);
    size_t q = 0;
    double sent = 0, msgs = 0;
    for (int k = 0; k < npeers; k++)
        for (size_t off = 0; off < recv_bytes[k]; off += CHUNK) {
            size_t c = recv_bytes[k] - off < CHUNK ? recv_bytes[k] - off : CHUNK;
            MPI_Irecv((char *)recv[k] + off, (int)c, MPI_BYTE, peers[k], tag, MPI_COMM_WORLD,
                      &req[q++]);
        }
    for (int k = 0; k < npeers; k++)
        for (size_t off = 0; off < send_bytes[k]; off += CHUNK) {
            size_t c = send_bytes[k] - off < CHUNK ? send_bytes[k] - off : CHUNK;
            MPI_Isend((const char *)send[k] + off, (int)c, MPI_BYTE, peers[k], tag, MPI_COMM_WORLD,
                      &req[q++]);
            sent += (double)c, msgs++;
        }
    MPI_Waitall((int)q, req, MPI_STATUSES_IGNORE);
    free(req);
    t_leave(t0, sent, msgs);
}

#else /* one rank, no MPI */

void comm_init(int *argc, char ***argv) { (void)argc, (void)argv; }
void comm_finalize(void) {}
void comm_abort(int code)
{
    fflush(stdout);
    fflush(stderr);
    exit(code);
}
int comm_agree(const int64_t mine[2], int64_t *all, double timeout_s)
{
    (void)timeout_s;
    all[0] = mine[0], all[1] = mine[1];
    return 0;
}
void comm_barrier(void) {}
void comm_sum_double(double *v, size_t n) { (void)v, (void)n; }
void comm_min_double(double *v, size_t n) { (void)v, (void)n; }
void comm_max_double(double *v, size_t n) { (void)v, (void)n; }
void comm_sum_i64(int64_t *v, size_t n) { (void)v, (void)n; }
void comm_min_i64(int64_t *v, size_t n) { (void)v, (void)n; }
void comm_max_i64(int64_t *v, size_t n) { (void)v, (void)n; }
int comm_any(int flag) { return flag != 0; }
int comm_all(int flag) { return flag != 0; }
void comm_bcast(void *buf, size_t bytes, int root) { (void)buf, (void)bytes, (void)root; }


int comm_alltoallv(const void *send, const size_t *send_bytes, const size_t *send_off, void **recv,
                   size_t *recv_bytes, size_t *recv_off)
{
    return alltoallv_self(send, send_bytes, send_off, recv, recv_bytes, recv_off);
}

int comm_alltoallv_max(const void *send, const size_t *send_bytes, const size_t *send_off,
                       void **recv, size_t *recv_bytes, size_t *recv_off, int64_t *words, int nw)
{
    (void)words, (void)nw; /* the maximum over one rank */
    return alltoallv_self(send, send_bytes, send_off, recv, recv_bytes, recv_off);
}

void comm_exchange(int npeers, const int *peers, const void *const *send, const size_t *send_bytes,
                   void *const *recv, const size_t *recv_bytes, int tag)
{
    (void)tag; /* one rank: every peer is itself */
    exchange_self(npeers, peers, send, send_bytes, recv, recv_bytes);
}

#endif

/* With or without MPI: the same block to every rank is an all-to-all with equal blocks (on one
 * rank, alltoallv_self's copy). */
int comm_allgatherv(const void *buf, size_t bytes, void **out, size_t *out_bytes, size_t *counts)
{
    const int P = comm_n;
    size_t *sb = malloc(4 * (size_t)P * sizeof *sb);
    if (!sb)
        comm_abort(70);
    size_t *so = sb + P, *rb = sb + 2 * P, *ro = sb + 3 * P;
    for (int r = 0; r < P; r++)
        sb[r] = bytes, so[r] = 0;
    int st = comm_alltoallv(buf, sb, so, out, rb, ro);
    if (st == 0) {
        *out_bytes = ro[P - 1] + rb[P - 1];
        if (counts)
            memcpy(counts, rb, (size_t)P * sizeof *counts);
    }
    free(sb);
    return st;
}
