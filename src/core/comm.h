/* Processes of a distributed run: a thin layer over MPI, as threads.c is over OpenMP. Only
 * comm.c includes mpi.h, compiled into the module grainlab-mpi.so that grainlab loads when
 * mpirun started it; a run started without mpirun is one rank, and every call below then works
 * on that one rank with no MPI loaded at all.
 *
 * Every collective call must be made by all ranks in the same order (SPMD, as the Lua script is
 * run by every rank). Byte counts are size_t; messages larger than INT_MAX bytes are split.
 * Errors from MPI abort the run (MPI_ERRORS_ARE_FATAL): a rank that fails cannot be recovered. */
#ifndef GRAINLAB_CORE_COMM_H
#define GRAINLAB_CORE_COMM_H

#include <stddef.h>
#include <stdint.h>

/* Starts MPI when the process was launched by mpirun (Open MPI's or PMIx's environment
 * variables are set): loads the module and calls MPI_Init, or exits with status 70 saying why it
 * cannot (no module, a build without MPI). Otherwise does nothing, so a plain run never loads
 * MPI's runtime. Call once, first thing in main. */
void comm_init(int *argc, char ***argv);
/* Ends MPI (no-op without it). Call once before exit; comm_abort instead when one rank fails. */
void comm_finalize(void);
/* Ends every rank of the run with exit code `code` (exit() on one rank). */
void comm_abort(int code) __attribute__((noreturn));

/* End-of-run agreement among all ranks, on a channel of its own that never matches the data
 * collectives above: every rank contributes two numbers (the CLI: its exit status and a digest
 * of its error message) and gets all ranks' pairs in rank order (all: 2 * comm_size()). Returns
 * 0, or -1 when not every rank joined within timeout_s seconds (< 0: wait for ever), which
 * means another rank is still running or blocked elsewhere: the caller then ends the run with
 * comm_abort. */
int comm_agree(const int64_t mine[2], int64_t *all, double timeout_s);

int comm_rank(void);
int comm_size(void);
/* Whether this build can run distributed at all (compiled with MPI). */
int comm_available(void);

void comm_barrier(void);

/* In-place reductions over all ranks of n values; every rank gets the result. The sum of doubles
 * is in rank order (MPI does not promise that: comm gathers and adds on every rank, so the
 * result is the same on every rank and for the same per-rank inputs). */
void comm_sum_double(double *v, size_t n);
void comm_min_double(double *v, size_t n);
void comm_max_double(double *v, size_t n);
void comm_sum_i64(int64_t *v, size_t n);
void comm_min_i64(int64_t *v, size_t n);
void comm_max_i64(int64_t *v, size_t n);
/* Logical or/and of one flag. */
int comm_any(int flag);
int comm_all(int flag);

/* Root's `bytes` bytes of buf to every rank. */
void comm_bcast(void *buf, size_t bytes, int root);

/* Every rank contributes `bytes` bytes; every rank gets the concatenation in rank order in a
 * new malloc'd buffer (*out, *out_bytes; counts[r] bytes from rank r if counts is not NULL,
 * comm_size() entries). Returns 0, or -1 when out of memory (on any rank: all ranks agree). */
int comm_allgatherv(const void *buf, size_t bytes, void **out, size_t *out_bytes, size_t *counts);

/* Personalised all-to-all: send_bytes[r] bytes from send + send_off[r] go to rank r. Every rank
 * gets what each rank sent it, concatenated in rank order, in a new malloc'd buffer (*recv,
 * recv_bytes[r] from rank r, recv_off[r] its offset). Collective. Returns 0, or -1 when out of
 * memory (all ranks agree). */
int comm_alltoallv(const void *send, const size_t *send_bytes, const size_t *send_off, void **recv,
                   size_t *recv_bytes, size_t *recv_off);
/* The same, with a maximum over the ranks of nw words riding on the exchange of the sizes
 * (words: this rank's in, the maximum out), so that a per-step flag (a failed step, an
 * allocation) costs no collective of its own. Three collectives in all, one of them the data. */
int comm_alltoallv_max(const void *send, const size_t *send_bytes, const size_t *send_off,
                       void **recv, size_t *recv_bytes, size_t *recv_off, int64_t *words, int nw);

/* Point-to-point exchange with a known set of peers (a halo whose sizes both sides know):
 * sends send_bytes[k] bytes from send[k] to peers[k] and receives recv_bytes[k] bytes from
 * peers[k] into recv[k], for k < npeers, all at once. Not collective over all ranks: only the
 * peers named take part, and both sides must name each other with matching sizes. tag keeps
 * separate exchanges apart. A peer named more than once (both neighbours of a ring of two, or
 * this rank itself across a periodic seam) is matched in the order of k on both sides: the
 * first message sent to it fills the first buffer it receives into, and so on; order the
 * peers (or use one tag per direction) so that this pairs the right buffers. A peer may be this
 * rank itself, also in a run without MPI (the message is copied). */
void comm_exchange(int npeers, const int *peers, const void *const *send, const size_t *send_bytes,
                   void *const *recv, const size_t *recv_bytes, int tag);

/* Traffic counters of this rank since the last reset: bytes sent and messages sent by the calls
 * above (collectives count what this rank sent), and the wall time spent inside them. For the
 * communication model of scripts/bench/scaling.lua. */
typedef struct comm_stats {
    double bytes, messages, seconds;
    long calls;
} comm_stats;
void comm_get_stats(comm_stats *out);
void comm_reset_stats(void);
/* What is counted, per call made by the caller (comm's own internal calls are not counted
 * again): one call; bytes: reductions n values of their type, bcast (bytes * (size - 1)) on the
 * root and 0 elsewhere, alltoallv and allgatherv the bytes this rank sends to other ranks,
 * comm_exchange the bytes sent to peers; messages: size - 1 for reductions and barrier, bcast
 * as its bytes, and one per peer or other rank with a non-empty block. */

/* Tests: the largest message (bytes) sent in one MPI call and moved by one v-collective, so
 * that the chunked and point-to-point paths for huge data run with small data (0: defaults). */
void comm_set_message_limit(size_t bytes);

#endif
