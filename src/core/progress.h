/* Progress of a long run on stderr: a bar with rate and ETA on a terminal, plain lines at every
 * 10% (and at least every 30 s) when stderr is not a terminal, nothing when quiet. Cheap enough to
 * update every step: it reads the clock and prints only when something is due. A reporter nobody
 * asked for waits: it shows nothing until the work has taken `delay` seconds, so short runs stay
 * silent and only long ones report. */
#ifndef GRAINLAB_CORE_PROGRESS_H
#define GRAINLAB_CORE_PROGRESS_H

#include <stdio.h>

typedef enum progress_style {
    PROGRESS_AUTO, /* bar on a terminal, lines otherwise */
    PROGRESS_BAR,
    PROGRESS_LINES,
    PROGRESS_QUIET
} progress_style;

typedef struct progress {
    FILE *out;
    progress_style style; /* resolved: never AUTO */
    char label[64];
    char unit[24];
    double total; /* <= 0: unknown */
    double done;
    double base;  /* work done before the current call: progress_update(p, k) records
                   * base + k (a run advancing in chunks, each counting from 0) */
    double delay; /* seconds of silence before anything is printed (0: none) */
    double t_start, t_last_print;
    int next_tenth; /* lines: next 10% mark to print */
    int shown;      /* something was printed */
    int active;
} progress;

/* The style new reporters take (the CLI sets PROGRESS_QUIET for --quiet). */
void progress_set_default_style(progress_style style);
progress_style progress_default_style(void);

/* Seconds an unasked reporter stays silent: 2, or GRAINLAB_PROGRESS_DELAY (tests set 0). */
double progress_unasked_delay(void);

/* Starts a reporter on stderr. total is the amount of work in `unit`s (steps, frames...). */
void progress_begin(progress *p, const char *label, double total, const char *unit);

/* Like progress_begin with an explicit stream and style (tests use this). */
void progress_begin_on(progress *p, FILE *out, progress_style style, const char *label,
                       double total, const char *unit);

/* Records base + done units of work (done is also recorded when the reporter is not active). */
void progress_update(progress *p, double done);

/* Prints the closing line (done, elapsed, rate). */
void progress_end(progress *p);

/* Closes a reporter whose work ended early: "label: WHY at step k of N after 0:12" (why:
 * "interrupted", "stopped", "failed"). */
void progress_end_early(progress *p, const char *why);

/* "1:02:03" or "2:03" for a duration in seconds. */
void progress_format_duration(char *buf, size_t size, double seconds);

#endif
