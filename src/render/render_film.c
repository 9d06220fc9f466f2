/* render_film.c — the renderer's films. Every device adds its samples into
 * its own fixed-point films (kernels/film/film.h): the own-pixel film and
 * the splat buffer, which holds the splat film, bdpt's per-strategy layers
 * if asked for and the first-hit AOVs (kernels/film/aov.h) if asked for, so
 * every path that reads, salvages, sums and checkpoints films carries them
 * all. The image is the integer sum of the salvage (films read back from
 * dropped devices, and a resumed checkpoint's), the other ranks' films
 * (rank 0 of a job) and every live device's films, scaled once: the same
 * bits whatever the device count or the split of the sample ranges. */
#include "render/render_film.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "film/aov_layout.h"
#include "film/film.h"

size_t film_bytes(const ajar_renderer *r) { return sizeof(cl_long) * 3 * (size_t)r->width * r->height; }

size_t film_aov_offset(const ajar_renderer *r) { return 3 * (size_t)r->width * r->height * (1 + (size_t)r->nlayers); }

size_t film_splat_count(const ajar_renderer *r)
{
	return film_aov_offset(r) + (r->opt.aov ? (size_t)AOV_CHANNELS * r->width * r->height : 0);
}

size_t film_splat_bytes(const ajar_renderer *r) { return sizeof(cl_long) * film_splat_count(r); }

int film_read(RenderDevice *rd, long **accum, long **splat)
{
	size_t bytes = film_bytes(rd->r), sbytes = film_splat_bytes(rd->r);
	*accum = malloc(bytes);
	*splat = malloc(sbytes);
	if (*accum && *splat &&
	    clEnqueueReadBuffer(rd->dev.queue, rd->accum, CL_TRUE, 0, bytes, *accum, 0, NULL, NULL) == CL_SUCCESS &&
	    clEnqueueReadBuffer(rd->dev.queue, rd->splat, CL_TRUE, 0, sbytes, *splat, 0, NULL, NULL) == CL_SUCCESS)
		return 1;
	free(*accum);
	free(*splat);
	*accum = *splat = NULL;
	return 0;
}

int film_salvage_add(ajar_renderer *r, const long *accum, const long *splat)
{
	size_t n = 3 * (size_t)r->width * r->height, ns = film_splat_count(r);
	if (!r->salvage) {
		r->salvage = calloc(n, sizeof *r->salvage);
		r->salvage_splat = calloc(ns, sizeof *r->salvage_splat);
		if (!r->salvage || !r->salvage_splat) {
			free(r->salvage);
			free(r->salvage_splat);
			r->salvage = r->salvage_splat = NULL;
			return 0;
		}
	}
	for (size_t i = 0; i < n; i++)
		r->salvage[i] += accum[i];
	for (size_t i = 0; i < ns; i++)
		r->salvage_splat[i] += splat[i];
	return 1;
}

ajar_status film_reduce(ajar_renderer *r)
{
	size_t n = 3 * (size_t)r->width * r->height, ns = film_splat_count(r);
	long *sum = r->film, *sum_splat = r->film_splat;
	if (r->job_lost)
		return err_set(AJAR_ERROR_DEVICE, "a rank of the job stopped answering: the films of the job cannot be "
						  "summed (a checkpoint written before is kept)");
	if (r->salvage) {
		memcpy(sum, r->salvage, n * sizeof *sum);
		memcpy(sum_splat, r->salvage_splat, ns * sizeof *sum_splat);
	} else {
		memset(sum, 0, n * sizeof *sum);
		memset(sum_splat, 0, ns * sizeof *sum_splat);
	}
	if (r->remote) { /* rank 0: what the other ranks rendered */
		for (size_t i = 0; i < n; i++)
			sum[i] += r->remote[i];
		for (size_t i = 0; i < ns; i++)
			sum_splat[i] += r->remote_splat[i];
	}
	/* Integer sums first, scaled once: the same bits whatever the device count. */
	for (uint32_t k = 0; k < r->ndev; k++) {
		RenderDevice *rd = &r->devs[k];
		long *a, *s;
		if (!rd->alive || rd->rank) /* another rank's films are in r->remote */
			continue;
		if (!film_read(rd, &a, &s))
			return err_set(AJAR_ERROR_DEVICE, "OpenCL device %s: reading the film back failed",
				       rd->dev.name);
		for (size_t i = 0; i < n; i++)
			sum[i] += a[i];
		for (size_t i = 0; i < ns; i++)
			sum_splat[i] += s[i];
		free(a);
		free(s);
	}
	return AJAR_OK;
}

ajar_status film_image(ajar_renderer *r, float *rgba)
{
	ajar_status st = film_reduce(r);
	if (st != AJAR_OK)
		return st;
	size_t n = 3 * (size_t)r->width * r->height;
	long *sum = r->film, *sum_splat = r->film_splat;
	double scale = r->spp_done ? 1.0 / ((double)FILM_SCALE * r->spp_done) : 0.0;
	for (size_t i = 0; i < n / 3; i++) {
		for (int c = 0; c < 3; c++)
			rgba[4 * i + c] = (float)((double)(sum[3 * i + c] + sum_splat[3 * i + c]) * scale);
		rgba[4 * i + 3] = 1.0f;
	}
	return AJAR_OK;
}

ajar_status film_aovs(ajar_renderer *r, float *px)
{
	ajar_status st = film_reduce(r);
	if (st != AJAR_OK)
		return st;
	size_t npix = (size_t)r->width * r->height;
	const long *a = r->film_splat + film_aov_offset(r);
	double n = r->spp_done, inv = n > 0 ? 1.0 / ((double)FILM_SCALE * n) : 0.0;
	double inv_sq = n > 0 ? 1.0 / ((double)AOV_SQ_SCALE * n) : 0.0;
	static const uint32_t bit[AOV_CHANNELS] = {AJAR_AOV_ALBEDO, AJAR_AOV_ALBEDO, AJAR_AOV_ALBEDO,
						   AJAR_AOV_NORMAL, AJAR_AOV_NORMAL, AJAR_AOV_NORMAL,
						   AJAR_AOV_DEPTH,  AJAR_AOV_VARIANCE, AJAR_AOV_VARIANCE,
						   AJAR_AOV_VARIANCE};
	for (size_t i = 0; i < npix; i++) {
		const long *p = a + AOV_CHANNELS * i;
		float *o = px + AOV_CHANNELS * i;
		for (int c = 0; c < 7; c++)
			o[c] = (r->opt.aov & bit[c]) ? (float)((double)p[c] * inv) : 0.0f;
		/* Sample variance of the pixel's own estimates over n, from
		 * sum(x) (the own-pixel film) and sum(x^2). */
		for (int c = 0; c < 3; c++) {
			double m = (double)r->film[3 * i + c] * inv, m2 = (double)p[7 + c] * inv_sq;
			o[7 + c] = (r->opt.aov & AJAR_AOV_VARIANCE) && n > 1 ? (float)(fmax(0.0, m2 - m * m) / (n - 1))
									       : 0.0f;
		}
	}
	return AJAR_OK;
}
