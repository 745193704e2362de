/* Processes of a distributed run over MPI (see comm.h). The one file of grainlab that includes
 * mpi.h, compiled twice:
 *   - into grainlab itself (GRAINLAB_COMM_MODULE undefined): one rank, no MPI. When the process
 *     was launched by mpirun, comm_init loads the module below with dlopen and every call is
 *     passed on to it; otherwise every call is the one-rank answer.
 *   - into the module grainlab-mpi.so (GRAINLAB_COMM_MODULE, linked with MPI): the calls over
 *     MPI, behind one exported table.
 * So a plain run never loads MPI's seven shared libraries: linking them into grainlab made every
 * start 2.2 ms slower (41.0 against 38.8 ms median for `grainlab -e 'print(1)'`, 150
 * interleaved runs), and a grainlab built with MPI runs on a machine without it. */
#define _POSIX_C_SOURCE 200809L
#include "core/comm.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef GRAINLAB_COMM_MODULE
#include <mpi.h>
#endif

/* The calls the module provides, in this order (both compilations see this one definition). */
typedef struct comm_ops {
    int version;
    void (*init)(int *, char ***);
    void (*finalize)(void);
    void (*abort)(int);
    int (*agree)(const int64_t *, int64_t *, double);
    int (*rank)(void);
    int (*size)(void);
    void (*barrier)(void);
    void (*reduce[6])(void *, size_t); /* sum, min, max of double; sum, min, max of int64 */
    int (*any)(int);
    int (*all)(int);
    void (*bcast)(void *, size_t, int);
    int (*alltoallv_max)(const void *, const size_t *, const size_t *, void **, size_t *,
                         size_t *, int64_t *, int);
    void (*exchange)(int, const int *, const void *const *, const size_t *, void *const *,
                     const size_t *, int);
    void (*get_stats)(comm_stats *);
    void (*reset_stats)(void);
    void (*set_message_limit)(size_t);
} comm_ops;
#define COMM_OPS_VERSION 1

#include "core/clock.h"

static int comm_r;
#ifdef GRAINLAB_COMM_MODULE
static int comm_n = 1;
#endif
static comm_stats stats;

/* Bytes per MPI call (counts are int), and the largest total a v-collective moves with int
 * counts and displacements; tests lower both to take the large-message paths with small data. */
static size_t chunk = (size_t)1 << 30;
static size_t int_limit = (size_t)INT_MAX;

static void set_limit(size_t bytes)
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

#ifdef GRAINLAB_COMM_MODULE /* ---- the module: the calls over MPI ---------------------------- */

int comm_rank(void) { return comm_r; }
int comm_size(void) { return comm_n; }
int comm_available(void) { return 1; }
void comm_set_message_limit(size_t bytes) { set_limit(bytes); }

void comm_get_stats(comm_stats *out) { *out = stats; }
void comm_reset_stats(void) { memset(&stats, 0, sizeof stats); }

static int comm_on; /* MPI_Init was called */
static int depth;   /* comm calls in progress: only the outermost one counts in the stats */

/* The end-of-run agreement (comm_agree) runs on a communicator of its own, so that a rank
 * waiting there never matches a data collective that the other ranks are blocked in. */
static MPI_Comm ctl = MPI_COMM_NULL;

void comm_init(int *argc, char ***argv)
{
    if (comm_on)
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


static void reduce_sum_d(void *v, size_t n) { comm_sum_double(v, n); }
static void reduce_min_d(void *v, size_t n) { comm_min_double(v, n); }
static void reduce_max_d(void *v, size_t n) { comm_max_double(v, n); }
static void reduce_sum_i(void *v, size_t n) { comm_sum_i64(v, n); }
static void reduce_min_i(void *v, size_t n) { comm_min_i64(v, n); }
static void reduce_max_i(void *v, size_t n) { comm_max_i64(v, n); }

/* The module's one exported symbol (the target builds with hidden visibility). */
__attribute__((visibility("default"))) const comm_ops *grainlab_comm_module(void);
const comm_ops *grainlab_comm_module(void)
{
    static const comm_ops ops = {
        COMM_OPS_VERSION, comm_init, comm_finalize, comm_abort, comm_agree, comm_rank,
        comm_size, comm_barrier,
        {reduce_sum_d, reduce_min_d, reduce_max_d, reduce_sum_i, reduce_min_i, reduce_max_i},
        comm_any, comm_all, comm_bcast, comm_alltoallv_max, comm_exchange, comm_get_stats,
        comm_reset_stats, comm_set_message_limit};
    return &ops;
}

#else /* ---- grainlab: one rank, or the module's calls under mpirun ------------------------- */

#include <dlfcn.h>
#include <unistd.h>

static const comm_ops *ops; /* the module, once loaded under mpirun */

/* Launched by mpirun (Open MPI sets OMPI_COMM_WORLD_SIZE; PMIx- and PMI-based launchers set
 * PMIX_RANK or PMI_RANK). A plain run does not start MPI's runtime at all. */
static int launched_by_mpirun(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
}

#if defined(__SANITIZE_ADDRESS__)
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

/* The module: $GRAINLAB_MPI_MODULE, else next to the executable, else where `make install` puts
 * it (relative to the executable), else in the build tree (tests run from its subdirectories). */
static void *load_module(char *tried, size_t cap)
{
    char exe[4096], path[4200];
    const char *env = getenv("GRAINLAB_MPI_MODULE");
    const char *cand[4] = {env, NULL, NULL, GRAINLAB_MPI_MODULE_BUILD};
    char dir[4096] = "";
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len > 0) {
        exe[len] = 0;
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = 0;
            snprintf(dir, sizeof dir, "%s", exe);
        }
    }
    char c1[4200], c2[4200];
    if (dir[0]) {
        snprintf(c1, sizeof c1, "%s/%s", dir, GRAINLAB_MPI_MODULE_NAME);
        snprintf(c2, sizeof c2, "%s/%s/%s", dir, GRAINLAB_MPI_MODULE_INSTALL,
                 GRAINLAB_MPI_MODULE_NAME);
        cand[1] = c1;
        cand[2] = c2;
    }
    tried[0] = 0;
    for (int k = 0; k < 4; k++) {
        if (!cand[k] || !cand[k][0] || (k > 0 && env && env[0]))
            continue;
        snprintf(path, sizeof path, "%s", cand[k]);
        /* RTLD_GLOBAL: Open MPI's own components, which it loads later, look for its symbols */
        void *h = dlopen(path, RTLD_NOW | RTLD_GLOBAL);
        if (h)
            return h;
        size_t used = strlen(tried);
        snprintf(tried + used, cap - used, "\n  %s: %s", path, dlerror());
    }
    return NULL;
}

void comm_init(int *argc, char ***argv)
{
    if (ops || !launched_by_mpirun())
        return;
    if (!GRAINLAB_MPI_MODULE_BUILT) { /* K copies of one run would write the same files */
        fprintf(stderr, "grainlab: launched by mpirun, but this grainlab was built without MPI "
                        "(-DGRAINLAB_MPI=OFF): run it without mpirun, or build it with MPI "
                        "(apt-get install libopenmpi-dev openmpi-bin)\n");
        exit(70);
    }
    char tried[8192];
    void *h = load_module(tried, sizeof tried);
    const comm_ops *(*entry)(void) = NULL;
    if (h)
        *(void **)&entry = dlsym(h, "grainlab_comm_module");
    const comm_ops *o = entry ? entry() : NULL;
    if (!o || o->version != COMM_OPS_VERSION) {
        fprintf(stderr,
                "grainlab: launched by mpirun, but its MPI module %s could not be loaded "
                "(set GRAINLAB_MPI_MODULE to its path):%s\n",
                GRAINLAB_MPI_MODULE_NAME,
                tried[0] ? tried : " it is from another version of grainlab");
        exit(70);
    }
    ops = o;
    ops->init(argc, argv);
}

void comm_finalize(void)
{
    if (ops)
        ops->finalize();
}
void comm_abort(int code)
{
    if (ops)
        ops->abort(code);
    fflush(stdout);
    fflush(stderr);
    exit(code);
}
int comm_agree(const int64_t mine[2], int64_t *all, double timeout_s)
{
    if (ops)
        return ops->agree(mine, all, timeout_s);
    all[0] = mine[0], all[1] = mine[1];
    return 0;
}
int comm_rank(void) { return ops ? ops->rank() : 0; }
int comm_size(void) { return ops ? ops->size() : 1; }
int comm_available(void) { return GRAINLAB_MPI_MODULE_BUILT; }
void comm_get_stats(comm_stats *out)
{
    if (ops)
        ops->get_stats(out);
    else
        *out = stats;
}
void comm_reset_stats(void)
{
    if (ops)
        ops->reset_stats();
    memset(&stats, 0, sizeof stats);
}
void comm_barrier(void)
{
    if (ops)
        ops->barrier();
}
/* one rank: every reduction leaves its values as they are */
#define COMM_REDUCE(name, type, k)                                                                 \
    void name(type *v, size_t n)                                                                   \
    {                                                                                              \
        if (ops)                                                                                   \
            ops->reduce[k](v, n);                                                                  \
    }
COMM_REDUCE(comm_sum_double, double, 0)
COMM_REDUCE(comm_min_double, double, 1)
COMM_REDUCE(comm_max_double, double, 2)
COMM_REDUCE(comm_sum_i64, int64_t, 3)
COMM_REDUCE(comm_min_i64, int64_t, 4)
COMM_REDUCE(comm_max_i64, int64_t, 5)
#undef COMM_REDUCE
int comm_any(int flag) { return ops ? ops->any(flag) : flag != 0; }
int comm_all(int flag) { return ops ? ops->all(flag) : flag != 0; }
void comm_bcast(void *buf, size_t bytes, int root)
{
    if (ops)
        ops->bcast(buf, bytes, root);
}

int comm_alltoallv_max(const void *send, const size_t *send_bytes, const size_t *send_off,
                       void **recv, size_t *recv_bytes, size_t *recv_off, int64_t *words, int nw)
{
    if (ops)
        return ops->alltoallv_max(send, send_bytes, send_off, recv, recv_bytes, recv_off, words,
                                  nw);
    /* one rank: the maximum of the words is this rank's */
    return alltoallv_self(send, send_bytes, send_off, recv, recv_bytes, recv_off);
}

int comm_alltoallv(const void *send, const size_t *send_bytes, const size_t *send_off, void **recv,
                   size_t *recv_bytes, size_t *recv_off)
{
    return comm_alltoallv_max(send, send_bytes, send_off, recv, recv_bytes, recv_off, NULL, 0);
}

void comm_exchange(int npeers, const int *peers, const void *const *send, const size_t *send_bytes,
                   void *const *recv, const size_t *recv_bytes, int tag)
{
    if (ops) {
        ops->exchange(npeers, peers, send, send_bytes, recv, recv_bytes, tag);
        return;
    }
    (void)tag; /* one rank: every peer is itself */
    exchange_self(npeers, peers, send, send_bytes, recv, recv_bytes);
}

void comm_set_message_limit(size_t bytes)
{
    if (ops)
        ops->set_message_limit(bytes);
    set_limit(bytes);
}

#endif

/* With or without MPI: the same block to every rank is an all-to-all with equal blocks (on one
 * rank, alltoallv_self's copy). */
int comm_allgatherv(const void *buf, size_t bytes, void **out, size_t *out_bytes, size_t *counts)
{
    const int P = comm_size();
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
