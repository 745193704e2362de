/* The checkpoint container (layout in checkpoint.h). The writer streams sections to a temporary
 * file with a running FNV-1a 64; the reader loads the whole file and checks everything before
 * any section is handed out, so an engine never sees half a file. */
#define _POSIX_C_SOURCE 200809L
#include "core/checkpoint.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/fileio.h"

static const char MAGIC[8] = {'G', 'R', 'A', 'I', 'N', 'L', 'A', 'B'};
static const char END_MAGIC[8] = {'G', 'R', 'A', 'I', 'N', 'E', 'N', 'D'};
#define BOM UINT32_C(0x01020304)
#define BOM_SWAPPED UINT32_C(0x04030201)
/* A double whose bytes are all different, so a mixed-endian double layout is caught too. */
#define DOUBLE_MARK (-0x1.23456789abcdep+7)
enum { HEADER = 64, SECTION_HEADER = 32, TRAILER = 24 };

uint64_t ckpt_fnv1a64(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = data;
    for (size_t k = 0; k < len; k++) {
        h ^= p[k];
        h *= UINT64_C(0x100000001b3);
    }
    return h;
}

static int little_endian(void)
{
    const uint32_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

/* ---- writer ----------------------------------------------------------------------------- */

struct ckpt_writer {
    atomic_file f;
    uint64_t hash, written;
    core_status status; /* sticky: the first failure */
    char msg[4608];     /* room for the whole path; core_error keeps its first 511 bytes */
    int in_section;
    char tag[CKPT_TAG_MAX + 1];
    uint32_t flags;
    unsigned char *buf;
    size_t len, cap;
    char (*tags)[16]; /* every section written, for "contents" */
    size_t ntags, cap_tags;
};

static const char CONTENTS[] = "contents";

static void fail_w(ckpt_writer *w, core_status st, const char *what)
{
    if (w->status != CORE_OK)
        return;
    w->status = st;
    snprintf(w->msg, sizeof w->msg, "cannot write '%s': %s", w->f.path, what);
}

static void emit(ckpt_writer *w, const void *data, size_t len)
{
    if (w->status != CORE_OK || len == 0)
        return;
    if (fwrite(data, 1, len, w->f.fp) != len) {
        fail_w(w, CORE_ERR_IO, strerror(errno));
        return;
    }
    w->hash = ckpt_fnv1a64(w->hash, data, len);
    w->written += len;
}

static void padded(char *out, size_t cap, const char *s)
{
    memset(out, 0, cap);
    memcpy(out, s, strlen(s));
}

core_status ckpt_writer_open(ckpt_writer **wp, const char *path, const char *engine,
                             const char *version, core_error *err)
{
    *wp = NULL;
    if (!engine || !*engine || strlen(engine) > CKPT_ENGINE_MAX)
        return core_fail(err, CORE_ERR_ARG, "checkpoint engine kind must be 1 to %d characters",
                         CKPT_ENGINE_MAX);
    if (!version || strlen(version) > CKPT_VERSION_MAX)
        return core_fail(err, CORE_ERR_ARG, "grainlab version string longer than %d characters",
                         CKPT_VERSION_MAX);
    ckpt_writer *w = calloc(1, sizeof *w);
    if (!w)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory opening checkpoint '%s'", path);
    core_status st = atomic_open(&w->f, path, err);
    if (st != CORE_OK) {
        free(w);
        return st;
    }
    w->hash = CKPT_FNV_OFFSET;
    unsigned char h[HEADER] = {0};
    const uint32_t bom = BOM, ver = CKPT_FORMAT_VERSION;
    const double mark = DOUBLE_MARK;
    memcpy(h, MAGIC, 8);
    memcpy(h + 8, &bom, 4);
    memcpy(h + 12, &ver, 4);
    memcpy(h + 16, &mark, 8);
    padded((char *)h + 24, 8, engine);
    padded((char *)h + 32, 32, version);
    emit(w, h, sizeof h);
    if (w->status != CORE_OK) {
        st = core_fail(err, w->status, "%s", w->msg);
        ckpt_writer_abort(w);
        return st;
    }
    *wp = w;
    return CORE_OK;
}

core_status ckpt_section_begin(ckpt_writer *w, const char *tag, uint32_t flags, core_error *err)
{
    if (w->in_section)
        return core_fail(err, CORE_ERR_STATE, "checkpoint section '%s' is still open", w->tag);
    if (!tag || !*tag || strlen(tag) > CKPT_TAG_MAX)
        return core_fail(err, CORE_ERR_ARG, "checkpoint section tag must be 1 to %d characters",
                         CKPT_TAG_MAX);
    if (strcmp(tag, CONTENTS) == 0)
        return core_fail(err, CORE_ERR_ARG, "checkpoint section tag '%s' is the container's own",
                         tag);
    w->in_section = 1;
    padded(w->tag, sizeof w->tag, tag);
    w->flags = flags;
    w->len = 0;
    return CORE_OK;
}

void ckpt_put_bytes(ckpt_writer *w, const void *data, size_t len)
{
    if (w->status != CORE_OK || len == 0)
        return;
    if (!w->in_section) {
        fail_w(w, CORE_ERR_STATE, "data written outside a section");
        return;
    }
    if (len > w->cap - w->len) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap - w->len < len) {
            if (cap > SIZE_MAX / 2) {
                fail_w(w, CORE_ERR_NOMEM, "section too large");
                return;
            }
            cap *= 2;
        }
        unsigned char *b = realloc(w->buf, cap);
        if (!b) {
            fail_w(w, CORE_ERR_NOMEM, "out of memory");
            return;
        }
        w->buf = b;
        w->cap = cap;
    }
    memcpy(w->buf + w->len, data, len);
    w->len += len;
}

void ckpt_put_u32(ckpt_writer *w, uint32_t v) { ckpt_put_bytes(w, &v, sizeof v); }
void ckpt_put_u64(ckpt_writer *w, uint64_t v) { ckpt_put_bytes(w, &v, sizeof v); }
void ckpt_put_i64(ckpt_writer *w, int64_t v) { ckpt_put_bytes(w, &v, sizeof v); }
void ckpt_put_f64(ckpt_writer *w, double v) { ckpt_put_bytes(w, &v, sizeof v); }

void ckpt_put_str(ckpt_writer *w, const char *s)
{
    size_t n = s ? strlen(s) : 0;
    ckpt_put_u64(w, n);
    ckpt_put_bytes(w, s, n);
}

void ckpt_put_f64s(ckpt_writer *w, const double *v, size_t n)
{
    ckpt_put_u64(w, n);
    ckpt_put_bytes(w, v, n * sizeof *v);
}

void ckpt_put_i64s(ckpt_writer *w, const int64_t *v, size_t n)
{
    ckpt_put_u64(w, n);
    ckpt_put_bytes(w, v, n * sizeof *v);
}

void ckpt_put_u32s(ckpt_writer *w, const uint32_t *v, size_t n)
{
    ckpt_put_u64(w, n);
    ckpt_put_bytes(w, v, n * sizeof *v);
}

void ckpt_put_u64s(ckpt_writer *w, const uint64_t *v, size_t n)
{
    ckpt_put_u64(w, n);
    ckpt_put_bytes(w, v, n * sizeof *v);
}

core_status ckpt_section_end(ckpt_writer *w, core_error *err)
{
    if (!w->in_section)
        return core_fail(err, CORE_ERR_STATE, "no checkpoint section is open");
    w->in_section = 0;
    unsigned char h[SECTION_HEADER] = {0};
    const uint64_t size = w->len;
    memcpy(h, w->tag, 16);
    memcpy(h + 16, &w->flags, 4);
    memcpy(h + 24, &size, 8);
    emit(w, h, sizeof h);
    emit(w, w->buf, w->len);
    static const unsigned char zeros[8] = {0};
    emit(w, zeros, (8 - w->len % 8) % 8);
    if (w->status == CORE_OK && w->ntags == w->cap_tags) {
        size_t cap = w->cap_tags ? 2 * w->cap_tags : 16;
        char(*t)[16] = realloc(w->tags, cap * sizeof *t);
        if (!t)
            fail_w(w, CORE_ERR_NOMEM, "out of memory");
        else
            w->tags = t, w->cap_tags = cap;
    }
    if (w->status != CORE_OK)
        return core_fail(err, w->status, "%s", w->msg);
    memcpy(w->tags[w->ntags++], w->tag, 16);
    return CORE_OK;
}

core_status ckpt_writer_commit(ckpt_writer *w, core_error *err)
{
    if (w->in_section)
        fail_w(w, CORE_ERR_STATE, "a section is still open");
    if (w->status == CORE_OK) { /* "contents": the tags of every section above */
        w->in_section = 1;
        padded(w->tag, sizeof w->tag, CONTENTS);
        w->flags = 0;
        w->len = 0;
        const size_t ntags = w->ntags;
        ckpt_put_u64(w, ntags);
        ckpt_put_bytes(w, w->tags, ntags * sizeof *w->tags);
        core_error ignored;
        ckpt_section_end(w, &ignored); /* a failure is sticky: reported below */
    }
    emit(w, END_MAGIC, 8);
    const uint64_t size = w->written + 16;
    emit(w, &size, 8);
    const uint64_t hash = w->hash; /* covers everything before the checksum itself */
    emit(w, &hash, 8);
    if (w->status != CORE_OK) {
        core_status st = core_fail(err, w->status, "%s", w->msg);
        ckpt_writer_abort(w);
        return st;
    }
    core_status st = atomic_commit(&w->f, err);
    free(w->buf);
    free(w->tags);
    free(w);
    return st;
}

void ckpt_writer_abort(ckpt_writer *w)
{
    if (!w)
        return;
    if (w->f.fp)
        atomic_abort(&w->f);
    free(w->buf);
    free(w->tags);
    free(w);
}

/* ---- reader ----------------------------------------------------------------------------- */

typedef struct entry {
    char tag[CKPT_TAG_MAX + 1];
    uint32_t flags;
    const unsigned char *data;
    size_t size;
    int read;
} entry;

struct ckpt_reader {
    char path[4096];
    char engine[CKPT_ENGINE_MAX + 1];
    char version[CKPT_VERSION_MAX + 1];
    uint32_t format;
    unsigned char *file;
    size_t size;
    entry *sec;
    int nsec;
};

/* Reads path whole into a new buffer; refuses what is not a regular file. */
static core_status slurp(const char *path, unsigned char **out, size_t *size, core_error *err)
{
    *out = NULL;
    *size = 0;
    FILE *fp;
    uint64_t bytes;
    core_status st = fileio_open_read(path, "checkpoint", &fp, &bytes, err);
    if (st != CORE_OK)
        return st;
    if (bytes > SIZE_MAX - 1) {
        fclose(fp);
        return core_fail(err, CORE_ERR_NOMEM, "checkpoint '%s' is too large (%llu bytes)", path,
                         (unsigned long long)bytes);
    }
    size_t n = (size_t)bytes;
    unsigned char *buf = malloc(n ? n : 1);
    if (!buf) {
        fclose(fp);
        return core_fail(err, CORE_ERR_NOMEM, "out of memory reading checkpoint '%s' (%zu bytes)",
                         path, n);
    }
    size_t got = fread(buf, 1, n, fp);
    int bad = ferror(fp);
    fclose(fp);
    if (bad || got != n) {
        free(buf);
        return core_fail(err, CORE_ERR_IO, "cannot read checkpoint '%s': read error", path);
    }
    *out = buf;
    *size = n;
    return CORE_OK;
}

static uint32_t rd32(const unsigned char *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}

static uint64_t rd64(const unsigned char *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

/* A NUL-padded text field of cap bytes: NUL-terminated inside, printable before the NUL. */
static int text_field(const unsigned char *p, size_t cap, char *out)
{
    size_t n = 0;
    while (n < cap && p[n])
        n++;
    if (n == cap)
        return 0;
    for (size_t k = 0; k < n; k++)
        if (p[k] < 32 || p[k] > 126)
            return 0;
    for (size_t k = n; k < cap; k++)
        if (p[k])
            return 0;
    memcpy(out, p, n);
    out[n] = '\0';
    return 1;
}

/* Engine kinds are acronyms read letter by letter: "an mpm", "a dem", "a dsmc". */
static const char *article(const char *acronym)
{
    return acronym[0] && strchr("aefhilmnorsx", acronym[0]) ? "an" : "a";
}

/* Header, trailer and checksum; the order gives the most telling message first. */
static core_status check_frame(ckpt_reader *r, const char *engine, core_error *err)
{
    const char *path = r->path;
    const unsigned char *f = r->file;
    const size_t n = r->size;
    if (n == 0)
        return core_fail(err, CORE_ERR_IO, "'%s' is not a grainlab checkpoint: the file is empty",
                         path);
    if (memcmp(f, MAGIC, n < 8 ? n : 8) != 0)
        return core_fail(err, CORE_ERR_IO, "'%s' is not a grainlab checkpoint (no GRAINLAB header)",
                         path);
    if (n < 16)
        return core_fail(err, CORE_ERR_IO, "'%s' is truncated (%zu bytes)", path, n);
    const uint32_t bom = rd32(f + 8);
    if (bom == BOM_SWAPPED)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' was written on a %s-endian machine and this one is %s-endian; "
                         "checkpoints are not converted between byte orders",
                         path, little_endian() ? "big" : "little",
                         little_endian() ? "little" : "big");
    if (bom != BOM)
        return core_fail(err, CORE_ERR_IO, "'%s' is corrupt (damaged byte-order mark)", path);
    if (n < HEADER + TRAILER)
        return core_fail(err, CORE_ERR_IO, "'%s' is truncated (%zu bytes)", path, n);
    const unsigned char *t = f + n - TRAILER;
    if (memcmp(t, END_MAGIC, 8) != 0)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is truncated or corrupt (no end marker; %zu bytes)", path, n);
    if (rd64(t + 8) != n)
        return core_fail(err, CORE_ERR_IO, "'%s' is truncated or corrupt (%zu bytes, written %llu)",
                         path, n, (unsigned long long)rd64(t + 8));
    if (ckpt_fnv1a64(CKPT_FNV_OFFSET, f, n - 8) != rd64(t + 16))
        return core_fail(err, CORE_ERR_IO, "'%s' is corrupt (checksum mismatch)", path);
    r->format = rd32(f + 12);
    char version[CKPT_VERSION_MAX + 1] = "?";
    text_field(f + 32, 32, version);
    if (r->format > CKPT_FORMAT_VERSION)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' has checkpoint format version %u (written by grainlab %s); this "
                         "grainlab reads format versions up to %d",
                         path, (unsigned)r->format, version, CKPT_FORMAT_VERSION);
    if (r->format < 1)
        return core_fail(err, CORE_ERR_IO, "'%s' has an unknown checkpoint format version %u", path,
                         (unsigned)r->format);
    double mark;
    memcpy(&mark, f + 16, 8);
    if (mark != DOUBLE_MARK)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' stores doubles in a byte order this machine does not use", path);
    if (!text_field(f + 24, 8, r->engine) || !r->engine[0] || !text_field(f + 32, 32, r->version))
        return core_fail(err, CORE_ERR_IO, "'%s' is corrupt (bad header text)", path);
    if (engine && strcmp(engine, r->engine) != 0)
        return core_fail(err, CORE_ERR_ARG, "'%s' is %s %s checkpoint, not %s %s one", path,
                         article(r->engine), r->engine, article(engine), engine);
    return CORE_OK;
}

/* The last section, "contents", against the sections before it (see checkpoint.h); then it is
 * dropped from the index. */
static core_status check_contents(ckpt_reader *r, core_error *err)
{
    for (int k = 0; k + 1 < r->nsec; k++)
        if (strcmp(r->sec[k].tag, CONTENTS) == 0)
            return core_fail(err, CORE_ERR_IO,
                             "'%s' is corrupt (section '%s' is section %d of %d, not the last)",
                             r->path, CONTENTS, k + 1, r->nsec);
    if (r->nsec == 0 || strcmp(r->sec[r->nsec - 1].tag, CONTENTS) != 0)
        return CORE_OK; /* written before "contents" existed */
    const entry *c = &r->sec[r->nsec - 1];
    const int n = r->nsec - 1;
    uint64_t listed = c->size >= 8 ? rd64(c->data) : UINT64_MAX;
    if (c->size < 8 || (c->size - 8) % 16 != 0 || listed != (c->size - 8) / 16)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s' of %zu bytes does not hold a list of "
                         "tags)",
                         r->path, CONTENTS, c->size);
    const unsigned char *t = c->data + 8;
    char tag[CKPT_TAG_MAX + 1];
    for (uint64_t q = 0; q < listed; q++)
        if (!text_field(t + 16 * q, 16, tag) || !tag[0])
            return core_fail(err, CORE_ERR_IO,
                             "'%s' is corrupt (section '%s': entry %llu is not a tag)", r->path,
                             CONTENTS, (unsigned long long)q + 1);
    /* The first place where the file and the list differ (linear: a forged list may be long):
     * with fewer sections than listed, the listed one there is missing; else the file's one
     * there is out of place. */
    uint64_t k = 0;
    while (k < listed && k < (uint64_t)n &&
           strncmp((const char *)t + 16 * k, r->sec[k].tag, 16) == 0)
        k++;
    if ((uint64_t)n < listed) {
        text_field(t + 16 * k, 16, tag);
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is incomplete: section '%s' (number %llu of the %llu its writer "
                         "listed) is missing",
                         r->path, tag, (unsigned long long)k + 1, (unsigned long long)listed);
    }
    if (k < (uint64_t)n)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s', number %llu of the file, is not where "
                         "its writer listed it)",
                         r->path, r->sec[k].tag, (unsigned long long)k + 1);
    r->nsec = n;
    return CORE_OK;
}

static core_status index_sections(ckpt_reader *r, core_error *err)
{
    const size_t end = r->size - TRAILER;
    int cap = 0;
    for (size_t at = HEADER; at < end;) {
        if (end - at < SECTION_HEADER)
            return core_fail(err, CORE_ERR_IO,
                             "'%s' is corrupt (section header at byte %zu "
                             "runs past the end)",
                             r->path, at);
        const unsigned char *h = r->file + at;
        entry e = {0};
        if (!text_field(h, 16, e.tag) || !e.tag[0] || rd32(h + 20) != 0)
            return core_fail(err, CORE_ERR_IO, "'%s' is corrupt (bad section header at byte %zu)",
                             r->path, at);
        e.flags = rd32(h + 16);
        const uint64_t size = rd64(h + 24);
        at += SECTION_HEADER;
        const uint64_t padded_size = size + (8 - size % 8) % 8;
        if (size > end - at || padded_size > end - at)
            return core_fail(err, CORE_ERR_IO,
                             "'%s' is corrupt (section '%s' of %llu bytes runs "
                             "past the end)",
                             r->path, e.tag, (unsigned long long)size);
        e.data = r->file + at;
        e.size = (size_t)size;
        at += (size_t)padded_size;
        if (r->nsec == cap) {
            cap = cap ? 2 * cap : 16;
            entry *s = realloc(r->sec, (size_t)cap * sizeof *s);
            if (!s)
                return core_fail(err, CORE_ERR_NOMEM, "out of memory reading '%s'", r->path);
            r->sec = s;
        }
        r->sec[r->nsec++] = e;
    }
    return check_contents(r, err);
}

core_status ckpt_reader_open(ckpt_reader **rp, const char *path, const char *engine,
                             core_error *err)
{
    *rp = NULL;
    if (!path || !*path)
        return core_fail(err, CORE_ERR_ARG, "empty checkpoint file name");
    if (strlen(path) >= sizeof((ckpt_reader *)0)->path)
        return core_fail(err, CORE_ERR_ARG, "checkpoint file name too long");
    ckpt_reader *r = calloc(1, sizeof *r);
    if (!r)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory reading '%s'", path);
    strcpy(r->path, path);
    core_status st = slurp(path, &r->file, &r->size, err);
    if (st == CORE_OK)
        st = check_frame(r, engine, err);
    if (st == CORE_OK)
        st = index_sections(r, err);
    if (st != CORE_OK) {
        ckpt_reader_close(r);
        return st;
    }
    *rp = r;
    return CORE_OK;
}

const char *ckpt_reader_path(const ckpt_reader *r) { return r->path; }
const char *ckpt_reader_engine(const ckpt_reader *r) { return r->engine; }
const char *ckpt_reader_version(const ckpt_reader *r) { return r->version; }
uint32_t ckpt_reader_format(const ckpt_reader *r) { return r->format; }
int ckpt_reader_nsections(const ckpt_reader *r) { return r->nsec; }
const char *ckpt_reader_tag(const ckpt_reader *r, int k)
{
    return k >= 0 && k < r->nsec ? r->sec[k].tag : NULL;
}

int ckpt_has(const ckpt_reader *r, const char *tag)
{
    for (int k = 0; k < r->nsec; k++)
        if (strcmp(r->sec[k].tag, tag) == 0)
            return 1;
    return 0;
}

core_status ckpt_find(ckpt_reader *r, const char *tag, ckpt_section *s, core_error *err)
{
    for (int k = 0; k < r->nsec; k++)
        if (strcmp(r->sec[k].tag, tag) == 0) {
            r->sec[k].read = 1;
            *s = (ckpt_section){r, r->sec[k].tag, r->sec[k].data, r->sec[k].size, 0};
            return CORE_OK;
        }
    return core_fail(err, CORE_ERR_IO, "'%s' is incomplete (no '%s' section)", r->path, tag);
}

core_status ckpt_get_bytes(ckpt_section *s, void *out, size_t len, core_error *err)
{
    if (len > s->size - s->pos)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s' is shorter than its contents: %zu bytes "
                         "wanted at offset %zu of %zu)",
                         s->r->path, s->tag, len, s->pos, s->size);
    if (len)
        memcpy(out, s->data + s->pos, len);
    s->pos += len;
    return CORE_OK;
}

core_status ckpt_get_u32(ckpt_section *s, uint32_t *v, core_error *err)
{
    return ckpt_get_bytes(s, v, sizeof *v, err);
}
core_status ckpt_get_u64(ckpt_section *s, uint64_t *v, core_error *err)
{
    return ckpt_get_bytes(s, v, sizeof *v, err);
}
core_status ckpt_get_i64(ckpt_section *s, int64_t *v, core_error *err)
{
    return ckpt_get_bytes(s, v, sizeof *v, err);
}
core_status ckpt_get_f64(ckpt_section *s, double *v, core_error *err)
{
    return ckpt_get_bytes(s, v, sizeof *v, err);
}

core_status ckpt_peek_count(ckpt_section *s, size_t max, size_t *n, core_error *err)
{
    uint64_t c = 0;
    const size_t pos = s->pos;
    core_status st = ckpt_get_u64(s, &c, err);
    s->pos = pos;
    if (st != CORE_OK)
        return st;
    if (c > max || c > s->size - s->pos)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s' claims %llu elements, at most %zu fit)",
                         s->r->path, s->tag, (unsigned long long)c,
                         max < s->size - s->pos ? max : s->size - s->pos);
    *n = (size_t)c;
    return CORE_OK;
}

core_status ckpt_get_str(ckpt_section *s, char *out, size_t cap, core_error *err)
{
    size_t n = 0;
    core_status st = ckpt_peek_count(s, cap - 1, &n, err);
    if (st != CORE_OK)
        return st;
    s->pos += 8;
    st = ckpt_get_bytes(s, out, n, err);
    out[st == CORE_OK ? n : 0] = '\0';
    return st;
}

static core_status get_array(ckpt_section *s, void *out, size_t n, size_t elem, const char *kind,
                             core_error *err)
{
    uint64_t c = 0;
    const size_t pos = s->pos; /* a failed read leaves the cursor where it was */
    core_status st = ckpt_get_u64(s, &c, err);
    if (st != CORE_OK)
        return st;
    s->pos = pos;
    if (c != n)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s' has %llu %s where %zu were expected)",
                         s->r->path, s->tag, (unsigned long long)c, kind, n);
    if (n > SIZE_MAX / elem)
        return core_fail(err, CORE_ERR_IO, "'%s' is corrupt (section '%s' too large)", s->r->path,
                         s->tag);
    if (n * elem > s->size - s->pos - 8)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s' is shorter than its %zu %s)", s->r->path,
                         s->tag, n, kind);
    s->pos += 8;
    return ckpt_get_bytes(s, out, n * elem, err);
}

core_status ckpt_get_f64s(ckpt_section *s, double *out, size_t n, core_error *err)
{
    return get_array(s, out, n, sizeof *out, "doubles", err);
}
core_status ckpt_get_new_f64s(ckpt_section *s, size_t n, size_t cap, double **out,
                              core_error *err)
{
    *out = malloc((cap > n ? cap : n ? n : 1) * sizeof **out);
    if (!*out)
        return core_fail(err, CORE_ERR_NOMEM, "out of memory loading a checkpoint");
    core_status st = ckpt_get_f64s(s, *out, n, err);
    if (st) {
        free(*out);
        *out = NULL;
    }
    return st;
}
core_status ckpt_get_i64s(ckpt_section *s, int64_t *out, size_t n, core_error *err)
{
    return get_array(s, out, n, sizeof *out, "int64 values", err);
}
core_status ckpt_get_u32s(ckpt_section *s, uint32_t *out, size_t n, core_error *err)
{
    return get_array(s, out, n, sizeof *out, "uint32 values", err);
}
core_status ckpt_get_u64s(ckpt_section *s, uint64_t *out, size_t n, core_error *err)
{
    return get_array(s, out, n, sizeof *out, "uint64 values", err);
}

core_status ckpt_get_int_in(ckpt_section *s, long lo, long hi, const char *what, long *out,
                            core_error *err)
{
    int64_t v = 0;
    *out = 0; /* defined on every path */
    core_status st = ckpt_get_i64(s, &v, err);
    if (st)
        return st;
    if (v < lo || v > hi)
        return core_fail(err, CORE_ERR_ARG,
                         "'%s' is a corrupt %s checkpoint: %s = %lld is outside [%ld, %ld]",
                         s->r->path, s->r->engine, what, (long long)v, lo, hi);
    *out = (long)v;
    return CORE_OK;
}

core_status ckpt_get_finite(ckpt_section *s, const char *what, double *out, core_error *err)
{
    *out = 0;
    core_status st = ckpt_get_f64(s, out, err);
    if (st)
        return st;
    if (!isfinite(*out))
        return core_fail(err, CORE_ERR_ARG, "'%s' is a corrupt %s checkpoint: %s is not finite",
                         s->r->path, s->r->engine, what);
    return CORE_OK;
}

core_status ckpt_section_done(ckpt_section *s, core_error *err)
{
    if (s->pos != s->size)
        return core_fail(err, CORE_ERR_IO,
                         "'%s' is corrupt (section '%s' has %zu bytes, %zu were read)", s->r->path,
                         s->tag, s->size, s->pos);
    return CORE_OK;
}

core_status ckpt_reader_finish(ckpt_reader *r, core_error *err)
{
    for (int k = 0; k < r->nsec; k++)
        if (!r->sec[k].read && (r->sec[k].flags & CKPT_REQUIRED))
            return core_fail(err, CORE_ERR_IO,
                             "'%s' needs a feature this grainlab lacks (required section '%s', "
                             "written by grainlab %s)",
                             r->path, r->sec[k].tag, r->version);
    return CORE_OK;
}

void ckpt_reader_close(ckpt_reader *r)
{
    if (!r)
        return;
    free(r->file);
    free(r->sec);
    free(r);
}

core_status ckpt_peek_engine(const char *path, char out[CKPT_ENGINE_MAX + 1], core_error *err)
{
    ckpt_reader *r;
    core_status st = ckpt_reader_open(&r, path, NULL, err);
    if (st != CORE_OK)
        return st;
    memcpy(out, r->engine, sizeof r->engine);
    ckpt_reader_close(r);
    return CORE_OK;
}

core_status ckpt_blame_file(core_error *err, core_status st, const char *path, const char *kind)
{
    if (st == CORE_OK || st == CORE_ERR_NOMEM || !err)
        return st;
    char why[sizeof err->msg];
    snprintf(why, sizeof why, "%s", err->msg);
    return core_fail(err, CORE_ERR_ARG, "'%s' is a corrupt %s checkpoint: %s", path, kind, why);
}
