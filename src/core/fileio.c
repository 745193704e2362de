/* Whole-file writes through a temporary file and rename(2); reads of regular files only. */
#define _POSIX_C_SOURCE 200809L
#include "core/fileio.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/comm.h"

/* The temporary files being written now, so that a process ended by a signal can remove them
 * (an unfinished file is never renamed into place, and must not stay beside the outputs). */
enum { MAX_LIVE = 64 };
static const char *volatile live[MAX_LIVE];

static void track(const char *tmp)
{
    for (int k = 0; k < MAX_LIVE; k++)
        if (!live[k]) {
            live[k] = tmp;
            return;
        }
}

static void untrack(const char *tmp)
{
    for (int k = 0; k < MAX_LIVE; k++)
        if (live[k] == tmp)
            live[k] = NULL;
}

int fileio_remove_temporaries(void)
{
    int n = 0;
    for (int k = 0; k < MAX_LIVE; k++) {
        const char *t = live[k];
        if (t) {
            live[k] = NULL;
            n += unlink(t) == 0;
        }
    }
    return n;
}

int fileio_live_temporaries(void)
{
    int n = 0;
    for (int k = 0; k < MAX_LIVE; k++)
        n += live[k] != NULL;
    return n;
}

core_status atomic_open(atomic_file *f, const char *path, core_error *err)
{
    f->fp = NULL;
    if (!path || !*path)
        return core_fail(err, CORE_ERR_ARG, "empty file name");
    if (strlen(path) >= sizeof f->path)
        return core_fail(err, CORE_ERR_ARG, "file name too long (%zu characters)", strlen(path));
    strcpy(f->path, path);
    snprintf(f->tmp, sizeof f->tmp, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(f->tmp);
    if (fd < 0)
        return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", path, strerror(errno));
    f->sink = comm_rank() > 0;
    if (f->sink) { /* rank 0 writes the file: here the check above, then nothing */
        close(fd);
        unlink(f->tmp);
        f->fp = fopen("/dev/null", "wb");
        if (!f->fp)
            return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", path, strerror(errno));
        return CORE_OK;
    }
    f->fp = fdopen(fd, "wb");
    if (!f->fp) {
        int e = errno;
        close(fd);
        unlink(f->tmp);
        return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", path, strerror(e));
    }
    track(f->tmp);
    return CORE_OK;
}

core_status atomic_commit(atomic_file *f, core_error *err)
{
    if (!f->fp)
        return core_fail(err, CORE_ERR_STATE, "file '%s' is not open", f->path);
    if (f->sink) {
        struct stat st;
        int bad = ferror(f->fp) || fflush(f->fp) != 0, e = errno;
        fclose(f->fp);
        f->fp = NULL;
        if (!bad && stat(f->path, &st) == 0 && S_ISDIR(st.st_mode)) /* rename(2) would fail */
            bad = 1, e = EISDIR;
        return bad ? core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", f->path, strerror(e))
                   : CORE_OK;
    }
    /* mkstemp creates 0600; give the file the permissions an ordinary fopen would. */
    mode_t mask = umask(0);
    umask(mask);
    int bad = ferror(f->fp) || fflush(f->fp) != 0 || fchmod(fileno(f->fp), 0666 & ~mask) != 0;
    int e = errno;
    if (fclose(f->fp) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    f->fp = NULL;
    if (!bad && rename(f->tmp, f->path) != 0) {
        bad = 1;
        e = errno;
    }
    untrack(f->tmp); /* after the rename: a signal in between removes a name that is gone */
    if (bad) {
        unlink(f->tmp);
        return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", f->path, strerror(e));
    }
    return CORE_OK;
}

void atomic_abort(atomic_file *f)
{
    if (f->fp && f->sink) {
        fclose(f->fp);
        f->fp = NULL;
    } else if (f->fp) {
        fclose(f->fp);
        f->fp = NULL;
        untrack(f->tmp);
        unlink(f->tmp);
    }
}

core_status atomic_write(const char *path, const void *data, size_t len, core_error *err)
{
    atomic_file f;
    core_status st = atomic_open(&f, path, err);
    if (st != CORE_OK)
        return st;
    if (len && fwrite(data, 1, len, f.fp) != len) {
        int e = errno;
        atomic_abort(&f);
        return core_fail(err, CORE_ERR_IO, "cannot write '%s': %s", path, strerror(e));
    }
    return atomic_commit(&f, err);
}

/* What a file that is not a regular file is, for a refusal. */
static const char *file_kind(mode_t m)
{
    if (S_ISDIR(m))
        return "a directory";
    if (S_ISFIFO(m))
        return "a FIFO (named pipe)";
    if (S_ISCHR(m))
        return "a character device";
    if (S_ISBLK(m))
        return "a block device";
    if (S_ISSOCK(m))
        return "a socket";
    return "not a regular file";
}

core_status fileio_open_read(const char *path, const char *what, FILE **fp, uint64_t *size,
                             core_error *err)
{
    *fp = NULL;
    if (size)
        *size = 0;
    if (!path || !*path)
        return core_fail(err, CORE_ERR_ARG, "empty %s file name", what);
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return core_fail(err, CORE_ERR_IO, "cannot read %s '%s': %s", what, path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        return core_fail(err, CORE_ERR_IO, "cannot read %s '%s': %s", what, path, strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        const char *kind = file_kind(st.st_mode);
        return core_fail(err, CORE_ERR_IO, "cannot read %s '%s': it is %s%s", what, path, kind,
                         strncmp(kind, "a ", 2) == 0 ? ", not a regular file" : "");
    }
    int flags = fcntl(fd, F_GETFL);
    FILE *f = NULL;
    if (flags >= 0 && fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == 0)
        f = fdopen(fd, "rb");
    if (!f) {
        int e = errno;
        close(fd);
        return core_fail(err, CORE_ERR_IO, "cannot read %s '%s': %s", what, path, strerror(e));
    }
    *fp = f;
    if (size)
        *size = st.st_size > 0 ? (uint64_t)st.st_size : 0;
    return CORE_OK;
}
