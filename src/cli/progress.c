/* progress.c — see progress.h. The terminal bar is redrawn after every pass
 * (passes are short); plain lines are rate-limited so that a log of a long
 * render stays readable. */
#include "cli/progress.h"

#include <string.h>
#include <unistd.h>

/* Seconds between plain (non-terminal) progress lines. */
#define PLAIN_INTERVAL 5.0
#define BAR_WIDTH 24

void progress_init(Progress *p, FILE *out, int quiet, int noise)
{
	memset(p, 0, sizeof *p);
	p->out = out;
	p->quiet = quiet;
	p->noise = noise;
	p->tty = isatty(fileno(out));
}

void progress_format_time(double s, char *buf, size_t cap)
{
	if (!(s >= 0))
		snprintf(buf, cap, "?");
	else if (s < 60)
		snprintf(buf, cap, "%.1f s", s);
	else if (s < 3600)
		snprintf(buf, cap, "%dm%02ds", (int)(s / 60), (int)s % 60);
	else
		snprintf(buf, cap, "%dh%02dm", (int)(s / 3600), (int)(s / 60) % 60);
}

/* "12/32 spp" with a target, "12 spp" for a time-limited render; and
 * the estimated error under a noise target ("noise 3.2%", "noise ?"
 * before the first estimate). */
static void format_spp(const ajar_progress *now, int noise, char *buf, size_t cap)
{
	if (now->spp_target)
		snprintf(buf, cap, "%u/%u spp", now->spp_done, now->spp_target);
	else
		snprintf(buf, cap, "%u spp", now->spp_done);
	size_t n = strlen(buf);
	if (noise && now->noise >= 0)
		snprintf(buf + n, cap - n, "  noise %.2g%%", 100.0 * now->noise);
	else if (noise)
		snprintf(buf + n, cap - n, "  noise ?");
}

void progress_update(Progress *p, const ajar_progress *now)
{
	p->last = *now;
	if (p->quiet)
		return;
	double frac = now->fraction < 0 ? 0 : (now->fraction > 1 ? 1 : now->fraction);
	char spp[80], elapsed[24], eta[24];
	format_spp(now, p->noise, spp, sizeof spp);
	progress_format_time(now->elapsed, elapsed, sizeof elapsed);
	progress_format_time(now->eta, eta, sizeof eta);
	if (p->tty) {
		char bar[BAR_WIDTH + 1];
		int filled = (int)(frac * BAR_WIDTH + 0.5);
		memset(bar, '#', (size_t)filled);
		memset(bar + filled, '-', (size_t)(BAR_WIDTH - filled));
		bar[BAR_WIDTH] = '\0';
		/* \033[K clears what a longer previous line left behind. */
		fprintf(p->out, "\r%3.0f%% [%s] %s  %.3g M/s  elapsed %s  eta %s\033[K", frac * 100, bar, spp,
			now->samples_per_second * 1e-6, elapsed, eta);
		fflush(p->out);
		p->line_open = 1;
		return;
	}
	if (now->elapsed - p->last_print < PLAIN_INTERVAL)
		return;
	p->last_print = now->elapsed;
	fprintf(p->out, "ajar: %.0f%% %s %.3g Msamples/s elapsed %s eta %s\n", frac * 100, spp,
		now->samples_per_second * 1e-6, elapsed, eta);
	fflush(p->out);
}

void progress_break_line(Progress *p)
{
	if (p->line_open) {
		fputc('\n', p->out);
		p->line_open = 0;
	}
}
