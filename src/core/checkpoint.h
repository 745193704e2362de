/* grainlab's checkpoint container: a versioned binary file of tagged, length-prefixed sections
 * with a byte-order mark and a checksum. Plain C, no engine knowledge: an engine writes its state
 * as sections (src/dem/checkpoint.c) and reads them back by tag.
 *
 * Layout (all integers and doubles in the writer's byte order, which must be the reader's):
 *
 *   header, 64 bytes
 *     0  char[8]  "GRAINLAB"                  magic
 *     8  uint32   0x01020304                  byte-order mark
 *    12  uint32   format version              CKPT_FORMAT_VERSION
 *    16  double   -0x1.23456789abcdep+7       double byte-order mark
 *    24  char[8]  engine kind, NUL-padded     "dem", "mpm", "dsmc"
 *    32  char[32] grainlab version, NUL-padded
 *   sections, each
 *     char[16] tag, NUL-padded; uint32 flags (CKPT_REQUIRED); uint32 0; uint64 payload size;
 *     payload, then zero padding to a multiple of 8 bytes
 *   last, the section "contents" (flags 0): uint64 count, then the tags (char[16]) of every
 *     section before it, in order
 *   trailer, 24 bytes
 *     char[8] "GRAINEND"; uint64 file size; uint64 FNV-1a 64 of every byte before this field
 *
 * The checksum cannot tell a section that was cut out of a file and the checksum recomputed
 * (a tool, a forged file) from a file written without it; "contents" can: a reader refuses a
 * file that lacks a section its contents list, or holds one they do not. Files written before
 * "contents" existed (none at the end) are read as they are. The reader checks and drops it:
 * ckpt_reader_nsections and ckpt_has do not see it, and a writer cannot use the tag.
 *
 * The header fields up to the version, and the trailer, keep this layout in every format version,
 * so that any grainlab can tell a newer file from a corrupt one. A reader refuses a section it does
 * not know only if the writer marked it CKPT_REQUIRED (ckpt_reader_finish); unknown optional
 * sections (extra data a newer writer adds) are skipped. */
#ifndef GRAINLAB_CORE_CHECKPOINT_H
#define GRAINLAB_CORE_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

enum { CKPT_FORMAT_VERSION = 1 };
enum { CKPT_REQUIRED = 1u }; /* section flag: a reader that does not know the tag must refuse */
enum { CKPT_TAG_MAX = 15, CKPT_ENGINE_MAX = 7, CKPT_VERSION_MAX = 31 };

/* Step counters and other counts a run accumulates: a reader refuses more than 2^53 (9.0e15; a
 * run of 10^9 steps a second takes 104 days to get there). Beyond it a counter is no longer exact
 * as a double, and a run continued from near 2^63 would overflow a signed counter. */
#define CKPT_COUNTER_MAX (INT64_C(1) << 53)

/* FNV-1a 64 of len bytes, continuing from h (start with CKPT_FNV_OFFSET). */
#define CKPT_FNV_OFFSET UINT64_C(0xcbf29ce484222325)
uint64_t ckpt_fnv1a64(uint64_t h, const void *data, size_t len);

/* ---- writing ---------------------------------------------------------------------------- */

typedef struct ckpt_writer ckpt_writer;

/* Opens a temporary file beside path (fileio.h); nothing appears at path before commit. */
core_status ckpt_writer_open(ckpt_writer **w, const char *path, const char *engine,
                             const char *version, core_error *err);

/* Starts a section; the put functions append to it; section_end writes it out. Failures
 * (memory, disk) are sticky and reported by section_end and commit. */
core_status ckpt_section_begin(ckpt_writer *w, const char *tag, uint32_t flags, core_error *err);
void ckpt_put_bytes(ckpt_writer *w, const void *data, size_t len);
void ckpt_put_u32(ckpt_writer *w, uint32_t v);
void ckpt_put_u64(ckpt_writer *w, uint64_t v);
void ckpt_put_i64(ckpt_writer *w, int64_t v);
void ckpt_put_f64(ckpt_writer *w, double v);
void ckpt_put_str(ckpt_writer *w, const char *s); /* uint64 length + bytes */
/* Arrays: a uint64 element count, then the elements. */
void ckpt_put_f64s(ckpt_writer *w, const double *v, size_t n);
void ckpt_put_i64s(ckpt_writer *w, const int64_t *v, size_t n);
void ckpt_put_u32s(ckpt_writer *w, const uint32_t *v, size_t n);
void ckpt_put_u64s(ckpt_writer *w, const uint64_t *v, size_t n);
core_status ckpt_section_end(ckpt_writer *w, core_error *err);

/* Writes the trailer and renames the file into place; frees w (also on failure, which removes
 * the temporary file). */
core_status ckpt_writer_commit(ckpt_writer *w, core_error *err);
/* Removes the temporary file and frees w (NULL is fine). */
void ckpt_writer_abort(ckpt_writer *w);

/* ---- reading ---------------------------------------------------------------------------- */

typedef struct ckpt_reader ckpt_reader;

/* A cursor over one section's payload. */
typedef struct ckpt_section {
    ckpt_reader *r;
    const char *tag;
    const unsigned char *data;
    size_t size, pos;
} ckpt_section;

/* Reads the whole file and verifies magic, byte order, trailer, size, checksum, format version,
 * the engine (when engine is not NULL) and every section's bounds. Every refusal names the path
 * and the problem: "'f.ckpt' is an mpm checkpoint, not a dem one". */
/* An engine's refusal of values read from PATH (its create or add call made for them), said as
 * the file's: "'PATH' is a corrupt KIND checkpoint: <the engine's message>". CORE_OK and
 * out-of-memory pass through unchanged. */
core_status ckpt_blame_file(core_error *err, core_status st, const char *path, const char *kind);
core_status ckpt_reader_open(ckpt_reader **r, const char *path, const char *engine,
                             core_error *err);
const char *ckpt_reader_path(const ckpt_reader *r);
const char *ckpt_reader_engine(const ckpt_reader *r);
const char *ckpt_reader_version(const ckpt_reader *r); /* grainlab version that wrote it */
uint32_t ckpt_reader_format(const ckpt_reader *r);
int ckpt_reader_nsections(const ckpt_reader *r);
const char *ckpt_reader_tag(const ckpt_reader *r, int k);

/* 1 if the file has a section of that tag. */
int ckpt_has(const ckpt_reader *r, const char *tag);
/* Finds a section (the first of that tag) and marks it read; a missing one is an error. */
core_status ckpt_find(ckpt_reader *r, const char *tag, ckpt_section *s, core_error *err);

/* Typed reads with bounds checks; a read past the section's end is an error naming it. */
core_status ckpt_get_bytes(ckpt_section *s, void *out, size_t len, core_error *err);
core_status ckpt_get_u32(ckpt_section *s, uint32_t *v, core_error *err);
core_status ckpt_get_u64(ckpt_section *s, uint64_t *v, core_error *err);
core_status ckpt_get_i64(ckpt_section *s, int64_t *v, core_error *err);
core_status ckpt_get_f64(ckpt_section *s, double *v, core_error *err);
/* A string of at most cap-1 bytes, NUL-terminated into out. */
core_status ckpt_get_str(ckpt_section *s, char *out, size_t cap, core_error *err);
/* Arrays written by ckpt_put_*s: the stored count must equal n. */
core_status ckpt_get_f64s(ckpt_section *s, double *out, size_t n, core_error *err);
/* n doubles into a new malloc'd array of cap >= n entries, *out (NULL on failure: out of memory,
 * or the section ended or held something else). */
core_status ckpt_get_new_f64s(ckpt_section *s, size_t n, size_t cap, double **out,
                              core_error *err);
core_status ckpt_get_i64s(ckpt_section *s, int64_t *out, size_t n, core_error *err);
core_status ckpt_get_u32s(ckpt_section *s, uint32_t *out, size_t n, core_error *err);
core_status ckpt_get_u64s(ckpt_section *s, uint64_t *out, size_t n, core_error *err);
/* The count of the array that follows, without consuming it (to size a buffer); at most max. */
core_status ckpt_peek_count(ckpt_section *s, size_t max, size_t *n, core_error *err);
/* An int64 in [lo, hi] into *out, or "'PATH' is a corrupt ENGINE checkpoint: WHAT = V is outside
 * [lo, hi]"; a finite double, or "... WHAT is not finite". Values a checksum cannot vouch for
 * (a forged file) never reach an engine. */
core_status ckpt_get_int_in(ckpt_section *s, long lo, long hi, const char *what, long *out,
                            core_error *err);
core_status ckpt_get_finite(ckpt_section *s, const char *what, double *out, core_error *err);
/* The section must have been read to its end (a size mismatch is corruption). */
core_status ckpt_section_done(ckpt_section *s, core_error *err);

/* Refuses a CKPT_REQUIRED section nobody read (written by a newer grainlab with a feature this
 * one lacks); optional unknown sections are ignored. */
core_status ckpt_reader_finish(ckpt_reader *r, core_error *err);
void ckpt_reader_close(ckpt_reader *r);

/* Reads only the header: the engine kind of a checkpoint file (for a generic loader). */
core_status ckpt_peek_engine(const char *path, char out[CKPT_ENGINE_MAX + 1], core_error *err);

#endif
