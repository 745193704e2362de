/* Files read: fileio_open_read opens a regular file only. A FIFO, a device, a socket or a
 * directory is refused at once, never read: a named pipe with no writer blocks, and a device
 * such as /dev/zero never ends.
 *
 * Output files are written whole: data goes to a temporary file beside the target, which is
 * renamed over it only when complete, so a failed or interrupted write never leaves half a file.
 * In a distributed run only rank 0 writes: on the other ranks the same calls make the same
 * checks (the directory takes a new file, the target is not a directory) and succeed or fail as
 * rank 0's do, but the data goes to the null device. Not collective: a write made by one rank
 * only is fine. */
#ifndef GRAINLAB_CORE_FILEIO_H
#define GRAINLAB_CORE_FILEIO_H

#include <stdint.h>
#include <stdio.h>

#include "core/error.h"

typedef struct atomic_file {
    FILE *fp;        /* write here */
    int sink;        /* a rank other than 0: fp is the null device */
    char path[4096]; /* final name */
    char tmp[4096 + 32];
} atomic_file;

/* Opens a temporary file in the target's directory. */
core_status atomic_open(atomic_file *f, const char *path, core_error *err);

/* Flushes, closes and renames into place; on any failure removes the temporary file. */
core_status atomic_commit(atomic_file *f, core_error *err);

/* Closes and removes the temporary file (for a writer that failed half-way). */
void atomic_abort(atomic_file *f);

/* Removes the temporary files of writes still open (committed or aborted ones are gone already)
 * and forgets them; returns how many were removed. Async-signal-safe (unlink only): the CLI
 * calls it on its way out after SIGTERM. */
int fileio_remove_temporaries(void);

/* Number of writes open now (tests). */
int fileio_live_temporaries(void);

/* Writes len bytes to path whole. */
core_status atomic_write(const char *path, const void *data, size_t len, core_error *err);

/* Opens path for reading ("rb") if it is a regular file: *fp, and its size in *size (NULL is
 * fine). The open itself does not wait for a FIFO's writer (O_NONBLOCK, cleared after the
 * check). Refusals name what (e.g. "checkpoint", "LAMMPS data file"), the path and the reason:
 * "cannot read checkpoint 'p': it is a FIFO (named pipe), not a regular file". */
core_status fileio_open_read(const char *path, const char *what, FILE **fp, uint64_t *size,
                             core_error *err);

#endif
