/* render_noise.c — stopping at a noise level (ajar_options.noise): the
 * image's relative error, estimated from two disjoint halves of its
 * samples.
 *
 * Every sample index has its own random stream, so the samples of any two
 * disjoint sets of indices are independent and each set's mean is an
 * unbiased image. At an estimate the devices pause and the films are
 * reduced (as for a checkpoint): S_n, the integer sums of the n samples per
 * pixel done, own pixels and light-traced splats together. Kept from an
 * earlier estimate, S_m of m samples (the kept m nearest n/2; they are
 * kept at doublings, so m lies in about [n/4, 3n/4]; the sets nested), so
 *     X = S_m / m  and  Y = (S_n - S_m) / (n - m)
 * are independent with per-pixel variances s^2/m and s^2/(n - m), and
 *     D = X - Y,  E[D^2] = s^2 (1/m + 1/(n - m)),
 * while the image I = S_n / n has var(I) = s^2 / n = E[D^2] m (n - m) / n^2.
 * The estimate is the root of the mean over pixels and channels of
 * D^2 m (n - m) / n^2 / (I^2 + (0.1 mean I)^2), the relative MSE that
 * tests/bench measures against references, with the same floor for dark
 * pixels. It is the same for every integrator (splats counted) and global:
 * the stopping rule reads one number for the whole image, not a pixel's own
 * samples, so no pixel stops early on its own luck.
 *
 * Its bias: each pixel's D^2 is unbiased for its variance, but the mean
 * over pixels divides by I^2 from the same samples, and heavy tails (a
 * rare bright path not met yet) make early estimates low; hence estimates
 * start at NOISE_FIRST samples per pixel with at least NOISE_HALF in each
 * half, and follow the samples geometrically (every NOISE_GROWTH). */
#include "render/render_noise.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "film/film.h"
#include "render/cluster.h"
#include "render/render_film.h"
#include "render/render_job.h"

#define NOISE_FIRST 8      /* samples per pixel before the first estimate */
#define NOISE_HALF 4       /* at least this many in each half */
#define NOISE_GROWTH 1.15  /* the next estimate after this many times the samples */

void noise_reset(ajar_renderer *r)
{
	for (int k = 0; k < 2; k++) {
		free(r->noise_snap[k]);
		r->noise_snap[k] = NULL;
		r->noise_snap_spp[k] = 0;
	}
	r->noise_nsnap = 0;
	r->noise = -1.0;
	r->noise_next = NOISE_FIRST;
	r->noise_reached = 0;
}

/* The relative error of the image of the n samples in `now` (image sums,
 * 3 longs a pixel), from the m samples in `then`. */
static double estimate(const long *now, uint32_t n, const long *then, uint32_t m, size_t npix)
{
	double in = 1.0 / ((double)FILM_SCALE * n), im = 1.0 / ((double)FILM_SCALE * m),
	       inm = 1.0 / ((double)FILM_SCALE * (n - m)), w = (double)m * (n - m) / ((double)n * n);
	double mean = 0.0;
	for (size_t i = 0; i < 3 * npix; i++)
		mean += (double)now[i] * in;
	mean /= 3.0 * npix;
	double floor2 = 0.01 * mean * mean, sum = 0.0;
	if (!(floor2 > 0.0))
		return 0.0; /* a black image has no error */
	for (size_t i = 0; i < 3 * npix; i++) {
		double img = (double)now[i] * in, x = (double)then[i] * im, y = (double)(now[i] - then[i]) * inm, d = x - y;
		sum += d * d * w / (img * img + floor2);
	}
	return sqrt(sum / (3.0 * npix));
}

/* The image sums (own pixels and splats) of the reduced films. */
static void image_sums(const ajar_renderer *r, long *out, size_t n)
{
	for (size_t i = 0; i < n; i++)
		out[i] = r->film[i] + r->film_splat[i];
}

void noise_update(ajar_renderer *r)
{
	uint32_t n = r->spp_done;
	size_t len = 3 * (size_t)r->width * r->height;
	ajar_status st = cluster_size() > 1 ? job_gather(r) : AJAR_OK;
	if (st == AJAR_OK)
		st = film_reduce(r);
	long *now = st == AJAR_OK ? malloc(sizeof *now * len) : NULL;
	if (!now) {
		log_msg(AJAR_LOG_WARNING, "noise estimate skipped: %s", st == AJAR_OK ? "out of memory" : ajar_last_error());
		return;
	}
	image_sums(r, now, len);
	/* The kept sums nearest half of n, at least NOISE_HALF samples on
	 * each side. */
	int k = -1;
	for (int j = 0; j < r->noise_nsnap; j++) {
		uint32_t m = r->noise_snap_spp[j];
		if (m >= NOISE_HALF && m + NOISE_HALF <= n &&
		    (k < 0 || fabs(m - 0.5 * n) < fabs(r->noise_snap_spp[k] - 0.5 * n)))
			k = j;
	}
	if (k >= 0)
		r->noise = estimate(now, n, r->noise_snap[k], r->noise_snap_spp[k], len / 3);
	/* Kept: the sums at n, once n is at least twice the newest kept (so
	 * later estimates find kept sums in [n'/4, n'/2]); the older of two
	 * goes. */
	int newest = r->noise_nsnap ? (r->noise_nsnap == 2 && r->noise_snap_spp[1] > r->noise_snap_spp[0]) : -1;
	if (newest < 0 || n >= 2u * r->noise_snap_spp[newest]) {
		int slot = r->noise_nsnap < 2 ? r->noise_nsnap++ : (r->noise_snap_spp[0] < r->noise_snap_spp[1] ? 0 : 1);
		free(r->noise_snap[slot]);
		r->noise_snap[slot] = now;
		r->noise_snap_spp[slot] = n;
		now = NULL;
	}
	free(now);
	/* The next estimate: NOISE_GROWTH times the samples, or sooner where
	 * the error, falling as 1/sqrt(samples), should reach the target. */
	double grow = NOISE_GROWTH;
	if (r->noise > 0.0) {
		double q = r->noise / r->opt.noise;
		grow = fmin(grow, fmax(1.0, q * q));
	}
	uint32_t next = (uint32_t)fmin(4e9, ceil(n * grow));
	r->noise_next = next > n + 1 ? next : n + 1;
}

void noise_during(ajar_renderer *r)
{
	r->pausing = 1;
	while (r->in_flight > 0)
		pthread_cond_wait(&r->cond, &r->lock);
	pthread_mutex_unlock(&r->lock);
	noise_update(r);
	pthread_mutex_lock(&r->lock);
	if (r->noise >= 0.0 && r->noise <= r->opt.noise) {
		r->noise_reached = 1;
		atomic_store(&r->cancel, 1); /* no device takes another range */
	}
	r->pausing = 0;
	pthread_cond_broadcast(&r->cond);
}

double ajar_renderer_noise(const ajar_renderer *r)
{
	return r ? r->noise : -1.0;
}
