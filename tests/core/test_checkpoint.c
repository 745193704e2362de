/* The checkpoint container: values come back exactly; a truncated, corrupt, foreign,
 * other-engine, other-byte-order or newer file is refused with a message naming the path and the
 * problem; every single flipped byte and every truncation of a small file is caught; a section
 * deleted, duplicated or moved behind a recomputed checksum is caught by the contents list; a
 * FIFO or a device is refused at once (under an alarm that ends the test if it is not). */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cmocka.h>

#include "core/checkpoint.h"
#include "core/error.h"
#include "core/fileio.h"

static char dir[256];
static char path[512];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/grainlab_ckpt_XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    snprintf(path, sizeof path, "%s/a.ckpt", dir);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd);
}

static int entries(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

static unsigned char *slurp(const char *p, size_t *n)
{
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    *n = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*n);
    assert_int_equal(fread(b, 1, *n, f), *n);
    fclose(f);
    return b;
}

static void spit(const char *p, const unsigned char *b, size_t n)
{
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, n, f), n);
    fclose(f);
}

static const double D[3] = {0x1.fffffffffffffp+1023, -0.0, 0x1p-1074};
static const int64_t I[2] = {INT64_MIN, -7};
static const uint32_t U32[4] = {0, 1, 0xdeadbeef, UINT32_MAX};
static const uint64_t U64[1] = {UINT64_MAX};

/* A small file of three sections: "data" (every type), "opt" (optional), "empty". */
static void write_small(const char *p, const char *engine, const char *extra_required)
{
    core_error err;
    ckpt_writer *w;
    assert_int_equal(ckpt_writer_open(&w, p, engine, "0.1.0", &err), CORE_OK);
    assert_int_equal(ckpt_section_begin(w, "data", CKPT_REQUIRED, &err), CORE_OK);
    ckpt_put_u32(w, 42);
    ckpt_put_u64(w, UINT64_C(1) << 40);
    ckpt_put_i64(w, -3);
    ckpt_put_f64(w, 0.1);
    ckpt_put_str(w, "hertz");
    ckpt_put_f64s(w, D, 3);
    ckpt_put_i64s(w, I, 2);
    ckpt_put_u32s(w, U32, 4);
    ckpt_put_u64s(w, U64, 1);
    assert_int_equal(ckpt_section_end(w, &err), CORE_OK);
    assert_int_equal(ckpt_section_begin(w, "opt", 0, &err), CORE_OK);
    ckpt_put_str(w, "a newer writer's extra");
    assert_int_equal(ckpt_section_end(w, &err), CORE_OK);
    assert_int_equal(ckpt_section_begin(w, "empty", CKPT_REQUIRED, &err), CORE_OK);
    assert_int_equal(ckpt_section_end(w, &err), CORE_OK);
    if (extra_required) {
        assert_int_equal(ckpt_section_begin(w, extra_required, CKPT_REQUIRED, &err), CORE_OK);
        ckpt_put_u32(w, 1);
        assert_int_equal(ckpt_section_end(w, &err), CORE_OK);
    }
    assert_int_equal(ckpt_writer_commit(w, &err), CORE_OK);
}

/* Reads what write_small wrote, reading "data" and "empty" only. */
static core_status read_small(const char *p, core_error *err)
{
    ckpt_reader *r;
    core_status st = ckpt_reader_open(&r, p, "dem", err);
    if (st != CORE_OK)
        return st;
    ckpt_section s;
    uint32_t u32;
    uint64_t u64;
    int64_t i64;
    double f;
    char str[16];
    double d[3];
    int64_t i[2];
    uint32_t u[4];
    uint64_t v[1];
    assert_int_equal(ckpt_find(r, "data", &s, err), CORE_OK);
    assert_int_equal(ckpt_get_u32(&s, &u32, err), CORE_OK);
    assert_int_equal(ckpt_get_u64(&s, &u64, err), CORE_OK);
    assert_int_equal(ckpt_get_i64(&s, &i64, err), CORE_OK);
    assert_int_equal(ckpt_get_f64(&s, &f, err), CORE_OK);
    assert_int_equal(ckpt_get_str(&s, str, sizeof str, err), CORE_OK);
    assert_int_equal(ckpt_get_f64s(&s, d, 3, err), CORE_OK);
    assert_int_equal(ckpt_get_i64s(&s, i, 2, err), CORE_OK);
    assert_int_equal(ckpt_get_u32s(&s, u, 4, err), CORE_OK);
    assert_int_equal(ckpt_get_u64s(&s, v, 1, err), CORE_OK);
    assert_int_equal(ckpt_section_done(&s, err), CORE_OK);
    assert_int_equal(u32, 42);
    assert_true(u64 == UINT64_C(1) << 40);
    assert_true(i64 == -3);
    assert_true(f == 0.1);
    assert_string_equal(str, "hertz");
    assert_memory_equal(d, D, sizeof D); /* bits, including -0.0 and the denormal */
    assert_memory_equal(i, I, sizeof I);
    assert_memory_equal(u, U32, sizeof U32);
    assert_memory_equal(v, U64, sizeof U64);
    assert_int_equal(ckpt_find(r, "empty", &s, err), CORE_OK);
    assert_int_equal(s.size, 0);
    assert_int_equal(ckpt_section_done(&s, err), CORE_OK);
    st = ckpt_reader_finish(r, err);
    ckpt_reader_close(r);
    return st;
}

static void test_fnv_vectors(void **state)
{
    (void)state;
    /* The published FNV-1a 64 test vectors (Fowler/Noll/Vo reference test suite). */
    assert_true(ckpt_fnv1a64(CKPT_FNV_OFFSET, "", 0) == UINT64_C(0xcbf29ce484222325));
    assert_true(ckpt_fnv1a64(CKPT_FNV_OFFSET, "a", 1) == UINT64_C(0xaf63dc4c8601ec8c));
    assert_true(ckpt_fnv1a64(CKPT_FNV_OFFSET, "foobar", 6) == UINT64_C(0x85944171f73967e8));
    /* Incremental use gives the same value. */
    assert_true(ckpt_fnv1a64(ckpt_fnv1a64(CKPT_FNV_OFFSET, "foo", 3), "bar", 3) ==
                UINT64_C(0x85944171f73967e8));
}

static void test_round_trip(void **state)
{
    (void)state;
    core_error err;
    write_small(path, "dem", NULL);
    assert_int_equal(entries(), 1); /* no temporary file left */
    assert_int_equal(read_small(path, &err), CORE_OK);
    ckpt_reader *r;
    assert_int_equal(ckpt_reader_open(&r, path, NULL, &err), CORE_OK);
    assert_string_equal(ckpt_reader_engine(r), "dem");
    assert_string_equal(ckpt_reader_version(r), "0.1.0");
    assert_int_equal(ckpt_reader_format(r), CKPT_FORMAT_VERSION);
    assert_int_equal(ckpt_reader_nsections(r), 3);
    assert_string_equal(ckpt_reader_tag(r, 1), "opt");
    assert_true(ckpt_has(r, "opt"));
    assert_false(ckpt_has(r, "nope"));
    ckpt_section s;
    assert_int_equal(ckpt_find(r, "nope", &s, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, "no 'nope' section"));
    assert_non_null(strstr(err.msg, path));
    ckpt_reader_close(r);
    char engine[CKPT_ENGINE_MAX + 1];
    assert_int_equal(ckpt_peek_engine(path, engine, &err), CORE_OK);
    assert_string_equal(engine, "dem");
}

static void test_section_bounds(void **state)
{
    (void)state;
    core_error err;
    write_small(path, "dem", NULL);
    ckpt_reader *r;
    assert_int_equal(ckpt_reader_open(&r, path, "dem", &err), CORE_OK);
    ckpt_section s;
    uint32_t u;
    uint64_t big;
    double d[2];
    /* A partly read section is not done. */
    assert_int_equal(ckpt_find(r, "data", &s, &err), CORE_OK);
    assert_int_equal(ckpt_get_u32(&s, &u, &err), CORE_OK);
    assert_int_equal(ckpt_section_done(&s, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, "section 'data'"));
    /* An array whose count differs from the expected one. */
    assert_int_equal(ckpt_get_u64(&s, &big, &err), CORE_OK);
    int64_t i64;
    assert_int_equal(ckpt_get_i64(&s, &i64, &err), CORE_OK);
    assert_int_equal(ckpt_get_f64(&s, d, &err), CORE_OK);
    char small[3];
    assert_int_equal(ckpt_get_str(&s, small, sizeof small, &err), CORE_ERR_IO); /* "hertz" > 2 */
    char str[8];
    assert_int_equal(ckpt_get_str(&s, str, sizeof str, &err), CORE_OK);
    assert_int_equal(ckpt_get_f64s(&s, d, 2, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, "3 doubles where 2 were expected"));
    size_t n;
    assert_int_equal(ckpt_peek_count(&s, 10, &n, &err), CORE_OK);
    assert_int_equal(n, 3);
    assert_int_equal(ckpt_peek_count(&s, 2, &n, &err), CORE_ERR_IO);
    /* Reading past the end. */
    assert_int_equal(ckpt_find(r, "empty", &s, &err), CORE_OK);
    assert_int_equal(ckpt_get_u32(&s, &u, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, "section 'empty' is shorter"));
    ckpt_reader_close(r);
}

static void test_unknown_sections(void **state)
{
    (void)state;
    core_error err;
    /* The optional "opt" is never read: fine. */
    write_small(path, "dem", NULL);
    assert_int_equal(read_small(path, &err), CORE_OK);
    /* A required section this reader does not know: refused, named. */
    write_small(path, "dem", "bonds");
    assert_int_equal(read_small(path, &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, "required section 'bonds'"));
    assert_non_null(strstr(err.msg, path));
}

static void expect_refused(const char *engine, const char *needle)
{
    core_error err;
    ckpt_reader *r = (ckpt_reader *)1;
    core_status st = ckpt_reader_open(&r, path, engine, &err);
    if (st == CORE_OK)
        fail_msg("'%s' was accepted", path);
    assert_null(r);
    assert_non_null(strstr(err.msg, path));
    if (needle && !strstr(err.msg, needle))
        fail_msg("message '%s' lacks '%s'", err.msg, needle);
}

static void test_every_flipped_byte(void **state)
{
    (void)state;
    write_small(path, "dem", NULL);
    size_t n;
    unsigned char *good = slurp(path, &n);
    unsigned char *bad = malloc(n);
    for (size_t k = 0; k < n; k++)
        for (int bit = 0; bit < 8; bit += 7) { /* the lowest and the highest bit */
            memcpy(bad, good, n);
            bad[k] ^= (unsigned char)(1u << bit);
            spit(path, bad, n);
            expect_refused("dem", NULL);
        }
    spit(path, good, n);
    core_error err;
    assert_int_equal(read_small(path, &err), CORE_OK);
    free(bad);
    free(good);
}

static void test_every_truncation(void **state)
{
    (void)state;
    write_small(path, "dem", NULL);
    size_t n;
    unsigned char *good = slurp(path, &n);
    for (size_t k = 0; k < n; k++) {
        spit(path, good, k);
        expect_refused("dem", k == 0 ? "empty" : k < 8 ? "truncated" : NULL);
    }
    /* And an extra byte after the end. */
    unsigned char *longer = calloc(n + 1, 1);
    memcpy(longer, good, n);
    spit(path, longer, n + 1);
    expect_refused("dem", NULL);
    free(longer);
    free(good);
}

static void test_foreign_and_missing(void **state)
{
    (void)state;
    const char *png = "\x89PNG\r\n\x1a\n and then some more bytes to be long enough.........";
    spit(path, (const unsigned char *)png, strlen(png));
    expect_refused("dem", "not a grainlab checkpoint");
    spit(path, (const unsigned char *)"-- a lua script\nprint(1)\n", 25);
    expect_refused("dem", "not a grainlab checkpoint");
    unlink(path);
    expect_refused("dem", "No such file");
    expect_refused(NULL, "cannot read checkpoint");
    snprintf(path, sizeof path, "%s", dir);
    expect_refused("dem", "is a directory");
    snprintf(path, sizeof path, "%s/a.ckpt", dir);
}

static void test_other_engine(void **state)
{
    (void)state;
    write_small(path, "mpm", NULL);
    expect_refused("dem", "is an mpm checkpoint, not a dem one");
    write_small(path, "dsmc", NULL);
    expect_refused("mpm", "is a dsmc checkpoint, not an mpm one");
}

/* Rewrites the checksum after editing the header, as a real newer writer would produce. */
static void reseal(unsigned char *b, size_t n)
{
    uint64_t h = ckpt_fnv1a64(CKPT_FNV_OFFSET, b, n - 8);
    memcpy(b + n - 8, &h, 8);
}

static void test_newer_and_other_byte_order(void **state)
{
    (void)state;
    write_small(path, "dem", NULL);
    size_t n;
    unsigned char *b = slurp(path, &n);
    uint32_t v = CKPT_FORMAT_VERSION + 1;
    memcpy(b + 12, &v, 4);
    reseal(b, n);
    spit(path, b, n);
    char want[128];
    snprintf(want, sizeof want,
             "format version %u (written by grainlab 0.1.0); this grainlab "
             "reads format versions up to %d",
             (unsigned)v, CKPT_FORMAT_VERSION);
    expect_refused("dem", want);
    v = 0;
    memcpy(b + 12, &v, 4);
    reseal(b, n);
    spit(path, b, n);
    expect_refused("dem", "unknown checkpoint format version 0");
    free(b);

    /* The other byte order: every multi-byte field swapped would be needed for a real file;
     * the byte-order mark alone decides the refusal, before anything else is interpreted. */
    write_small(path, "dem", NULL);
    b = slurp(path, &n);
    const unsigned char swapped[4] = {b[11], b[10], b[9], b[8]};
    memcpy(b + 8, swapped, 4);
    spit(path, b, n);
    expect_refused("dem", "endian machine");
    expect_refused("dem", "not converted");
    free(b);
}

/* The sections of a file as (offset, length) of each whole section (header, payload, padding). */
typedef struct piece {
    size_t at, len;
    char tag[17];
} piece;

static int pieces(const unsigned char *b, size_t n, piece *out, int max)
{
    int k = 0;
    for (size_t at = 64; at < n - 24 && k < max; k++) {
        uint64_t size;
        memcpy(&size, b + at + 24, 8);
        const size_t len = 32 + (size_t)size + (8 - (size_t)size % 8) % 8;
        out[k].at = at;
        out[k].len = len;
        memcpy(out[k].tag, b + at, 16);
        out[k].tag[16] = '\0';
        at += len;
    }
    return k;
}

/* The file of header, the sections order[0..m) of b and a trailer with the right size and
 * checksum, written to path. */
static void rebuild(const unsigned char *b, const piece *p, const int *order, int m)
{
    size_t n = 64;
    for (int k = 0; k < m; k++)
        n += p[order[k]].len;
    unsigned char *o = malloc(n + 24);
    memcpy(o, b, 64);
    size_t at = 64;
    for (int k = 0; k < m; k++) {
        memcpy(o + at, b + p[order[k]].at, p[order[k]].len);
        at += p[order[k]].len;
    }
    const uint64_t size = n + 24;
    memcpy(o + at, "GRAINEND", 8);
    memcpy(o + at + 8, &size, 8);
    reseal(o, n + 24);
    spit(path, o, n + 24);
    free(o);
}

static void test_contents(void **state)
{
    (void)state;
    core_error err;
    write_small(path, "dem", NULL);
    size_t n;
    unsigned char *b = slurp(path, &n);
    piece p[8];
    /* data, opt, empty, and the contents list last (its tag is the container's own) */
    assert_int_equal(pieces(b, n, p, 8), 4);
    assert_string_equal(p[3].tag, "contents");
    ckpt_writer *w;
    assert_int_equal(ckpt_writer_open(&w, path, "dem", "0.1.0", &err), CORE_OK);
    assert_int_equal(ckpt_section_begin(w, "contents", 0, &err), CORE_ERR_ARG);
    ckpt_writer_abort(w);
    /* a section deleted, optional or not: the file is incomplete, the section named */
    rebuild(b, p, (const int[]){0, 2, 3}, 3);
    expect_refused("dem", "is incomplete: section 'opt' (number 2 of the 3 its writer listed) is "
                          "missing");
    rebuild(b, p, (const int[]){1, 2, 3}, 3);
    expect_refused("dem", "is incomplete: section 'data' (number 1 of the 3");
    /* duplicated, moved: not where the list has it */
    rebuild(b, p, (const int[]){0, 1, 1, 2, 3}, 5);
    expect_refused("dem", "section 'opt', number 3 of the file, is not where its writer listed it");
    rebuild(b, p, (const int[]){2, 1, 0, 3}, 4);
    expect_refused("dem", "section 'empty', number 1 of the file, is not where its writer listed");
    /* the list not last */
    rebuild(b, p, (const int[]){0, 3, 1, 2}, 4);
    expect_refused("dem", "section 'contents' is section 2 of 4, not the last");
    /* its count inflated */
    unsigned char *c = malloc(n);
    memcpy(c, b, n);
    const uint64_t many = UINT64_C(1) << 40;
    memcpy(c + p[3].at + 32, &many, 8);
    reseal(c, n);
    spit(path, c, n);
    expect_refused("dem", "section 'contents' of 56 bytes does not hold a list of tags");
    free(c);
    /* without the list at all, the file of an older writer: read as it is */
    rebuild(b, p, (const int[]){0, 1, 2}, 3);
    assert_int_equal(read_small(path, &err), CORE_OK);
    ckpt_reader *r;
    spit(path, b, n);
    assert_int_equal(ckpt_reader_open(&r, path, "dem", &err), CORE_OK);
    assert_int_equal(ckpt_reader_nsections(r), 3);
    assert_false(ckpt_has(r, "contents"));
    ckpt_reader_close(r);
    free(b);
}

/* A FIFO with no writer, and devices: refused at once, never read. The alarm ends the test if a
 * read blocks (a FIFO) or never ends (/dev/zero). */
static void test_not_regular(void **state)
{
    (void)state;
    char fifo[300];
    snprintf(fifo, sizeof fifo, "%s/fifo", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    alarm(20);
    snprintf(path, sizeof path, "%s", fifo);
    expect_refused("dem", "it is a FIFO (named pipe), not a regular file");
    snprintf(path, sizeof path, "/dev/zero");
    expect_refused("dem", "cannot read checkpoint '/dev/zero': it is a character device");
    snprintf(path, sizeof path, "/dev/null");
    expect_refused(NULL, "it is a character device, not a regular file");
    FILE *fp = (FILE *)1;
    core_error err;
    assert_int_equal(fileio_open_read(fifo, "data file", &fp, NULL, &err), CORE_ERR_IO);
    assert_null(fp);
    assert_non_null(strstr(err.msg, "cannot read data file '"));
    alarm(0);
    snprintf(path, sizeof path, "%s/a.ckpt", dir);
    /* a regular file: opened, its size given */
    write_small(path, "dem", NULL);
    uint64_t size = 0;
    assert_int_equal(fileio_open_read(path, "checkpoint", &fp, &size, &err), CORE_OK);
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    assert_true(size == (uint64_t)st.st_size);
    fclose(fp);
}

static void test_write_failures(void **state)
{
    (void)state;
    core_error err;
    ckpt_writer *w;
    char p[600];
    snprintf(p, sizeof p, "%s/missing/dir/a.ckpt", dir);
    assert_int_equal(ckpt_writer_open(&w, p, "dem", "0.1.0", &err), CORE_ERR_IO);
    assert_non_null(strstr(err.msg, p));
    assert_null(w);
    assert_int_equal(ckpt_writer_open(&w, path, "toolongname", "0.1.0", &err), CORE_ERR_ARG);
    /* An aborted write leaves nothing. */
    int before = entries();
    assert_int_equal(ckpt_writer_open(&w, path, "dem", "0.1.0", &err), CORE_OK);
    assert_int_equal(ckpt_section_begin(w, "x", 0, &err), CORE_OK);
    assert_int_equal(ckpt_section_begin(w, "y", 0, &err), CORE_ERR_STATE);
    ckpt_put_f64(w, 1.0);
    assert_int_equal(ckpt_section_end(w, &err), CORE_OK);
    assert_int_equal(ckpt_section_begin(w, "", 0, &err), CORE_ERR_ARG);
    assert_int_equal(ckpt_section_begin(w, "sixteen_chars_xx", 0, &err), CORE_ERR_ARG);
    ckpt_writer_abort(w);
    assert_int_equal(entries(), before);
    assert_int_equal(fileio_live_temporaries(), 0);
    /* Data outside a section is a sticky error reported at commit, and nothing is written. */
    unlink(path);
    before = entries();
    assert_int_equal(ckpt_writer_open(&w, path, "dem", "0.1.0", &err), CORE_OK);
    ckpt_put_u32(w, 1);
    assert_int_equal(ckpt_writer_commit(w, &err), CORE_ERR_STATE);
    assert_non_null(strstr(err.msg, "outside a section"));
    assert_int_equal(entries(), before);
    assert_int_equal(fileio_live_temporaries(), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fnv_vectors),
        cmocka_unit_test_setup_teardown(test_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(test_section_bounds, setup, teardown),
        cmocka_unit_test_setup_teardown(test_unknown_sections, setup, teardown),
        cmocka_unit_test_setup_teardown(test_every_flipped_byte, setup, teardown),
        cmocka_unit_test_setup_teardown(test_every_truncation, setup, teardown),
        cmocka_unit_test_setup_teardown(test_foreign_and_missing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_other_engine, setup, teardown),
        cmocka_unit_test_setup_teardown(test_newer_and_other_byte_order, setup, teardown),
        cmocka_unit_test_setup_teardown(test_contents, setup, teardown),
        cmocka_unit_test_setup_teardown(test_not_regular, setup, teardown),
        cmocka_unit_test_setup_teardown(test_write_failures, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
