/* progress.h — render progress on stderr: a bar redrawn in place when
 * stderr is a terminal, plain lines every few seconds when it is not
 * (logs, CI), nothing at all with --quiet. */
#ifndef AJAR_CLI_PROGRESS_H
#define AJAR_CLI_PROGRESS_H
#include <stdio.h>

#include "ajar.h"

typedef struct {
	FILE *out;
	int quiet;
	int noise;         /* a noise target: show the estimated error */
	int tty;           /* redraw one line with \r */
	int line_open;     /* a bar is on screen without its newline */
	double last_print; /* elapsed seconds at the last plain line */
	ajar_progress last;
} Progress;

void progress_init(Progress *p, FILE *out, int quiet, int noise);
/* Shows one update (called from the renderer's progress callback). */
void progress_update(Progress *p, const ajar_progress *now);
/* Ends the bar's line so that other messages start on a fresh one. */
void progress_break_line(Progress *p);
/* "1.2 s", "3m05s", "2h07m". */
void progress_format_time(double seconds, char *buf, size_t cap);
#endif
