/* Bar / line / quiet progress reporting. */
#define _POSIX_C_SOURCE 200809L
#include "core/progress.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "core/clock.h"
#include "core/comm.h"

static progress_style default_style = PROGRESS_AUTO;
static const double BAR_INTERVAL_S = 0.1;
static const double LINE_INTERVAL_S = 30.0;

void progress_set_default_style(progress_style style) { default_style = style; }
progress_style progress_default_style(void) { return default_style; }

double progress_unasked_delay(void)
{
    const char *env = getenv("GRAINLAB_PROGRESS_DELAY");
    char *end;
    double d = env && *env ? strtod(env, &end) : 2.0;
    return env && *env && (*end || !(d >= 0)) ? 2.0 : d;
}

void progress_format_duration(char *buf, size_t size, double s)
{
    if (!(s >= 0) || s > 1e8) {
        snprintf(buf, size, "--:--");
        return;
    }
    long t = lround(s);
    if (t >= 3600)
        snprintf(buf, size, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
    else
        snprintf(buf, size, "%ld:%02ld", t / 60, t % 60);
}

void progress_begin_on(progress *p, FILE *out, progress_style style, const char *label,
                       double total, const char *unit)
{
    memset(p, 0, sizeof *p);
    p->out = out;
    if (style == PROGRESS_AUTO)
        style = isatty(fileno(out)) ? PROGRESS_BAR : PROGRESS_LINES;
    p->style = style;
    snprintf(p->label, sizeof p->label, "%s", label ? label : "run");
    snprintf(p->unit, sizeof p->unit, "%s", unit ? unit : "steps");
    p->total = total > 0 ? total : 0;
    p->t_start = p->t_last_print = clock_wall();
    p->next_tenth = 1;
    p->active = 1;
}

void progress_begin(progress *p, const char *label, double total, const char *unit)
{
    /* A distributed run reports once, from rank 0 (every rank runs the same steps). */
    progress_style style = comm_rank() > 0 ? PROGRESS_QUIET : default_style;
    progress_begin_on(p, stderr, style, label, total, unit);
}

static int terminal_width(FILE *out)
{
    struct winsize ws;
    if (ioctl(fileno(out), TIOCGWINSZ, &ws) == 0 && ws.ws_col >= 40)
        return ws.ws_col;
    return 80;
}

/* An estimated total (a time-based run at a varying dt) can be passed: then the work shows as
 * an amount without percentage, never as 104%. */
static int known_total(const progress *p) { return p->total > 0 && p->done <= p->total; }

static void draw_bar(progress *p, double now)
{
    double elapsed = now - p->t_start;
    double rate = elapsed > 0 ? p->done / elapsed : 0;
    char tail[96], eta[32];
    if (known_total(p)) {
        progress_format_duration(eta, sizeof eta, rate > 0 ? (p->total - p->done) / rate : -1);
        snprintf(tail, sizeof tail, " %5.1f%% %9.3g %s/s ETA %s", 100 * p->done / p->total, rate,
                 p->unit, eta);
    } else {
        progress_format_duration(eta, sizeof eta, elapsed);
        snprintf(tail, sizeof tail, " %.0f %s %9.3g %s/s %s", p->done, p->unit, rate, p->unit, eta);
    }
    int width = terminal_width(p->out) - 1;
    int room = width - (int)strlen(p->label) - (int)strlen(tail) - 3;
    fprintf(p->out, "\r%s ", p->label);
    if (known_total(p) && room >= 10) {
        int fill = (int)(room * fmin(1.0, p->done / p->total));
        fputc('[', p->out);
        for (int i = 0; i < room; i++)
            fputc(i < fill ? '#' : '-', p->out);
        fputc(']', p->out);
    }
    fputs(tail, p->out);
    fputs("\033[K", p->out); /* clear the rest of a previous, longer line */
    fflush(p->out);
}

static void print_line(progress *p, double now)
{
    double elapsed = now - p->t_start;
    double rate = elapsed > 0 ? p->done / elapsed : 0;
    char el[32], eta[32];
    progress_format_duration(el, sizeof el, elapsed);
    if (known_total(p)) {
        progress_format_duration(eta, sizeof eta, rate > 0 ? (p->total - p->done) / rate : -1);
        fprintf(p->out, "%s: %3.0f%% (%.0f/%.0f %s) %.3g %s/s, elapsed %s, ETA %s\n", p->label,
                100 * p->done / p->total, p->done, p->total, p->unit, rate, p->unit, el, eta);
    } else {
        fprintf(p->out, "%s: %.0f %s, %.3g %s/s, elapsed %s\n", p->label, p->done, p->unit, rate,
                p->unit, el);
    }
    fflush(p->out);
}

void progress_update(progress *p, double done)
{
    p->done = p->base + done;
    if (!p->active || p->style == PROGRESS_QUIET)
        return;
    done = p->done;
    double now = clock_wall();
    int waiting = now - p->t_start < p->delay;
    if (p->style == PROGRESS_BAR) {
        if (!waiting && (!p->shown || now - p->t_last_print >= BAR_INTERVAL_S)) {
            draw_bar(p, now);
            p->t_last_print = now;
            p->shown = 1;
        }
        return;
    }
    int due = now - p->t_last_print >= LINE_INTERVAL_S || (!p->shown && p->delay > 0);
    if (p->total > 0) {
        int tenth = (int)floor(10 * done / p->total);
        if (tenth >= p->next_tenth && tenth < 10) {
            p->next_tenth = tenth + 1;
            due = 1;
        }
    }
    if (due && !waiting) {
        print_line(p, now);
        p->t_last_print = now;
        p->shown = 1;
    }
}

/* Nothing is printed for a reporter still in its silent start. */
static int closing_silent(progress *p, double now)
{
    p->active = 0;
    return p->style == PROGRESS_QUIET || (p->delay > 0 && now - p->t_start < p->delay);
}

void progress_end_early(progress *p, const char *why)
{
    if (!p->active)
        return;
    double now = clock_wall();
    if (closing_silent(p, now))
        return;
    char el[32];
    progress_format_duration(el, sizeof el, now - p->t_start);
    if (p->style == PROGRESS_BAR)
        fputs("\r\033[K", p->out);
    int steps = strcmp(p->unit, "steps") == 0;
    fprintf(p->out, "%s: %s at %s%.0f", p->label, why, steps ? "step " : "", p->done);
    if (known_total(p))
        fprintf(p->out, " of %.0f", p->total);
    fprintf(p->out, "%s%s after %s\n", steps ? "" : " ", steps ? "" : p->unit, el);
    fflush(p->out);
}

void progress_end(progress *p)
{
    if (!p->active)
        return;
    double now = clock_wall(), elapsed = now - p->t_start;
    if (closing_silent(p, now))
        return;
    char el[32];
    progress_format_duration(el, sizeof el, elapsed);
    if (p->style == PROGRESS_BAR)
        fputs("\r\033[K", p->out);
    fprintf(p->out, "%s: done, %.0f %s in %s (%.3g %s/s)\n", p->label, p->done, p->unit, el,
            elapsed > 0 ? p->done / elapsed : 0.0, p->unit);
    fflush(p->out);
}
