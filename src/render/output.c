/* output.c — a renderer's image to files: the EXR with its ajar:* header,
 * the strategy layers as one multi-channel EXR, the PNG preview. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "image/exr.h"
#include "render/render_info.h"
#include "film/aov_layout.h"
#include "base/compat.h"
#include "film/film.h"
#include "mis/strategies.h"

static ajar_status read_image(ajar_renderer *r, float **rgba)
{
	uint32_t w, h;
	ajar_renderer_image(r, NULL, &w, &h);
	*rgba = malloc(sizeof(float) * 4 * (size_t)w * h);
	if (!*rgba)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for the image");
	ajar_status st = ajar_renderer_image(r, *rgba, NULL, NULL);
	if (st != AJAR_OK)
		free(*rgba);
	return st;
}

/* The header attributes every output of this renderer carries. */
typedef struct {
	RenderInfo info;
	char spp[32], seed[32], depth[32], secs[32];
	const char *kv[20];
} Header;

static uint32_t header_fill(ajar_renderer *r, Header *h)
{
	render_info(r, &h->info);
	snprintf(h->spp, sizeof h->spp, "%u", h->info.spp);
	snprintf(h->seed, sizeof h->seed, "%u", h->info.seed);
	snprintf(h->depth, sizeof h->depth, "%u", h->info.max_depth);
	snprintf(h->secs, sizeof h->secs, "%.3f", h->info.seconds);
	const char *kv[] = {"ajar:spp", h->spp, "ajar:integrator", h->info.integrator,
			    "ajar:seed", h->seed, "ajar:max_depth", h->depth, "ajar:render_seconds", h->secs,
			    "ajar:device", h->info.devices, "ajar:devices", h->info.shares,
			    "ajar:scene", h->info.scene, "ajar:version", AJAR_VERSION_STRING};
	memcpy(h->kv, kv, sizeof kv);
	return sizeof kv / sizeof kv[0] / 2;
}

/* RGBA plus the AOVs asked for, as the channels denoisers read. */
static ajar_status write_with_aovs(ajar_renderer *r, const char *path, const float *rgba, const Header *h,
				   uint32_t nattrs)
{
	static const struct {
		uint32_t bit;
		int first, count;
		const char *names[3];
	} groups[] = {{AJAR_AOV_ALBEDO, 0, 3, {"albedo.R", "albedo.G", "albedo.B"}},
		      {AJAR_AOV_NORMAL, 3, 3, {"normal.X", "normal.Y", "normal.Z"}},
		      {AJAR_AOV_DEPTH, 6, 1, {"depth.Z"}},
		      {AJAR_AOV_VARIANCE, 7, 3, {"variance.R", "variance.G", "variance.B"}}};
	const char *names[4 + AOV_CHANNELS] = {"R", "G", "B", "A"};
	int src[4 + AOV_CHANNELS], nch = 4;
	for (size_t g = 0; g < sizeof groups / sizeof groups[0]; g++)
		if (h->info.aov & groups[g].bit)
			for (int c = 0; c < groups[g].count; c++) {
				src[nch] = groups[g].first + c;
				names[nch++] = groups[g].names[c];
			}
	size_t npix = (size_t)h->info.width * h->info.height;
	float *aov = malloc(sizeof(float) * AOV_CHANNELS * npix), *px = malloc(sizeof(float) * (size_t)nch * npix);
	ajar_status st = !aov || !px ? err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for the AOVs", path)
				     : ajar_renderer_aovs(r, aov);
	if (st == AJAR_OK) {
		for (size_t i = 0; i < npix; i++) {
			memcpy(&px[nch * i], &rgba[4 * i], 4 * sizeof(float));
			for (int c = 4; c < nch; c++)
				px[nch * i + c] = aov[AOV_CHANNELS * i + src[c]];
		}
		st = exr_write_channels(path, px, nch, names, h->info.width, h->info.height, h->kv, nattrs);
	}
	free(aov);
	free(px);
	return st;
}

ajar_status ajar_renderer_write_exr(ajar_renderer *r, const char *path)
{
	float *rgba;
	ajar_status st;
	Header h;
	if (!r || !path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_write_exr: NULL argument");
	if ((st = read_image(r, &rgba)) != AJAR_OK)
		return st;
	uint32_t n = header_fill(r, &h);
	if (h.info.aov)
		st = write_with_aovs(r, path, rgba, &h, n);
	else
		st = ajar_write_exr(path, rgba, h.info.width, h.info.height, h.kv, n);
	free(rgba);
	return st;
}

ajar_status ajar_renderer_write_strategies(ajar_renderer *r, const char *path)
{
	float *rgba;
	ajar_status st;
	Header h;
	if (!r || !path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_write_strategies: NULL argument");
	if ((st = read_image(r, &rgba)) != AJAR_OK) /* also reduces the layers */
		return st;
	uint32_t n = header_fill(r, &h);
	const RenderInfo *ri = &h.info;
	if (ri->nlayers == 0) {
		free(rgba);
		return err_set(AJAR_ERROR_INVALID_ARGUMENT,
			       "%s: the renderer keeps no strategy images (set ajar_options.strategy_len)", path);
	}
	size_t npix = (size_t)ri->width * ri->height;
	int nch = 4 + 3 * ri->nlayers;
	float *px = malloc(sizeof(float) * nch * npix);
	char(*names)[48] = malloc(sizeof *names * nch);
	const char **np = malloc(sizeof *np * nch);
	if (!px || !names || !np) {
		free(px);
		free(names);
		free(np);
		free(rgba);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for strategy images", path);
	}
	static const char rgb[] = "RGB";
	for (int c = 0; c < 4; c++)
		snprintf(names[c], sizeof names[c], "%c", "RGBA"[c]);
	int len = ri->strategy_len;
	for (int n = 1; n <= len; n++)
		for (int s = 0; s <= n; s++)
			for (int c = 0; c < 3; c++)
				snprintf(names[4 + 3 * bdpt_layer(n, s) + c], sizeof names[0], "len%d.s%dt%d.%c", n, s,
					 n + 1 - s, rgb[c]);
	if (ri->nlayers > bdpt_layer_count(len)) /* the portal integrator's groups */
		for (int n = 2; n <= len; n++)
			for (int t = 1; t < n; t++)
				for (int s = 0; s + t < n; s++)
					for (int c = 0; c < 3; c++)
						snprintf(names[4 + 3 * (bdpt_layer_count(len) + portal_layer(n, s, t)) + c],
							 sizeof names[0], "len%d.portal.s%dt%d.%c", n, s, t, rgb[c]);
	for (int c = 0; c < nch; c++)
		np[c] = names[c];
	double scale = ri->spp ? 1.0 / ((double)FILM_SCALE * ri->spp) : 0.0;
	for (size_t i = 0; i < npix; i++) {
		memcpy(&px[nch * i], &rgba[4 * i], 4 * sizeof(float));
		for (int l = 0; l < ri->nlayers; l++)
			for (int c = 0; c < 3; c++)
				px[nch * i + 4 + 3 * l + c] =
					(float)(ri->layers[3 * npix * (size_t)l + 3 * i + c] * scale);
	}
	h.kv[2 * n] = "ajar:strategies";
	h.kv[2 * n + 1] = ri->strategy_unweighted ? "unweighted"
						 : "weighted (they sum to the image of paths up to their length)";
	st = exr_write_channels(path, px, nch, np, ri->width, ri->height, h.kv, n + 1);
	free(px);
	free(names);
	free(np);
	free(rgba);
	return st;
}

ajar_status ajar_renderer_write_png(ajar_renderer *r, const char *path)
{
	float *rgba;
	ajar_status st;
	if (!r || !path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_renderer_write_png: NULL argument");
	if ((st = read_image(r, &rgba)) != AJAR_OK)
		return st;
	uint32_t w, hgt;
	ajar_renderer_image(r, NULL, &w, &hgt);
	st = ajar_write_png(path, rgba, w, hgt);
	free(rgba);
	return st;
}

