/* Progress of a long run on stderr: a bar with rate and ETA on a terminal, plain lines at every
 * 10% (and at least every 30 s) when stderr is not a terminal, nothing when quiet. Cheap enough to
 * update every step: it reads the clock and prints only when something is due. */
#ifndef GRAINLAB_CORE_PROGRESS_H
#define GRAINLAB_CORE_PROGRESS_H

#include <stdio.h>

typedef enum progress_style {
    PROGRESS_AUTO,   /* bar on a terminal, lines otherwise */
    PROGRESS_BAR,
    PROGRESS_LINES,
    PROGRESS_QUIET
} progress_style;

typedef struct progress {
    FILE *out;
    progress_style style;   /* resolved: never AUTO */
    char label[64];
    char unit[24];
    double total;           /* <= 0: unknown */
    double done;
    double t_start, t_last_print;
    int next_tenth;         /* lines: next 10% mark to print */
    int active;
} progress;

/* The style new reporters take (the CLI sets PROGRESS_QUIET for --quiet). */
void progress_set_default_style(progress_style style);
progress_style progress_default_style(void);

/* Starts a reporter on stderr. total is the amount of work in `unit`s (steps, frames...). */
void progress_begin(progress *p, const char *label, double total, const char *unit);

/* Like progress_begin with an explicit stream and style (tests use this). */
void progress_begin_on(progress *p, FILE *out, progress_style style, const char *label,
                       double total, const char *unit);

void progress_update(progress *p, double done);

/* Prints the closing line (done, elapsed, rate). */
void progress_end(progress *p);

/* "1:02:03" or "2:03" for a duration in seconds. */
void progress_format_duration(char *buf, size_t size, double seconds);

#endif
