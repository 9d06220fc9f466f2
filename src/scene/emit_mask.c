/* emit_mask.c — an emissive texture's black parts emit nothing, so
 * triangles whose texture coordinates see only black are no emitters
 * (emit_mask.h). The answer once read every texel under a triangle's box:
 * a 72 KB scene of one black 2000 x 2000 texture on a quad instanced 1,000
 * times took 24 s for `ajar info`. A summed-area table per texture (built
 * once, linear in its texels) counts the non-black texels of any rectangle
 * in four reads; a box that wraps is at most a few rectangles per axis. */
#include "scene/emit_mask.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "material/texture.h"
#include "scene/scene.h"

/* Triangle i's texture coordinates under tex's transform, in texels. */
void scene_tri_texel_coords(const SceneView *v, uint32_t i, int tex, double x[3], double y[3])
{
	const TriShade *sh = &v->shade[i];
	const Texture *t = &v->textures[tex];
	float u[3] = {sh->u0, sh->u1, sh->u2}, w[3] = {sh->v0, sh->v1, sh->v2};
	if (t->flags & TEX_UV1) {
		const TriExtra *e = v->tris[i].flags & TRI_EXTRA ? &v->extra[i] : NULL;
		u[0] = e ? e->u0 : 0.0f, u[1] = e ? e->u1 : 0.0f, u[2] = e ? e->u2 : 0.0f;
		w[0] = e ? e->v0 : 0.0f, w[1] = e ? e->v1 : 0.0f, w[2] = e ? e->v2 : 0.0f;
	}
	for (int k = 0; k < 3; k++) {
		x[k] = ((double)t->xf[0] * u[k] + (double)t->xf[1] * w[k] + t->xf[2]) * t->width;
		y[k] = ((double)t->xf[3] * u[k] + (double)t->xf[4] * w[k] + t->xf[5]) * t->height;
	}
}

static int lit(uint32_t texel) { return (texel & 0xffffffu) != 0; }

void emit_mask_free(EmitMask *m)
{
	free(m->at);
	free(m->sat);
	memset(m, 0, sizeof *m);
}

ajar_status emit_mask_build(EmitMask *m, const Texture *textures, uint32_t ntextures, const uint32_t *texels,
			    const Material *materials, uint32_t nmaterials)
{
	memset(m, 0, sizeof *m);
	if (ntextures == 0)
		return AJAR_OK;
	m->at = malloc(sizeof *m->at * ntextures);
	if (!m->at)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for the emissive textures' tables");
	m->ntextures = ntextures;
	for (uint32_t t = 0; t < ntextures; t++)
		m->at[t] = SIZE_MAX;
	/* Which textures need a table, and the entries they take. */
	size_t total = 0;
	for (uint32_t k = 0; k < nmaterials; k++) {
		int t = materials[k].emissive_tex - 1;
		if (t < 0 || (uint32_t)t >= ntextures || m->at[t] != SIZE_MAX)
			continue;
		m->at[t] = total;
		for (uint32_t u = 0; u < (uint32_t)t; u++) /* same image: same table */
			if (m->at[u] != SIZE_MAX && textures[u].offset == textures[t].offset &&
			    textures[u].width == textures[t].width && textures[u].height == textures[t].height) {
				m->at[t] = m->at[u];
				break;
			}
		if (m->at[t] == total)
			total += ((size_t)textures[t].width + 1) * ((size_t)textures[t].height + 1);
	}
	if (total == 0)
		return AJAR_OK;
	m->sat = malloc(sizeof *m->sat * total);
	if (!m->sat) {
		emit_mask_free(m);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for the emissive textures' tables");
	}
	size_t built = 0;
	for (uint32_t t = 0; t < ntextures; t++) {
		if (m->at[t] != built)
			continue; /* none, or shares an earlier table */
		const Texture *x = &textures[t];
		size_t w = (size_t)x->width, h = (size_t)x->height, row = w + 1;
		uint32_t *s = m->sat + built;
		memset(s, 0, sizeof *s * row);
		for (size_t y = 0; y < h; y++) {
			const uint32_t *px = texels + x->offset + y * w;
			uint32_t *above = s + y * row, *cur = above + row, run = 0;
			cur[0] = 0;
			for (size_t i = 0; i < w; i++) {
				run += (uint32_t)lit(px[i]);
				cur[i + 1] = above[i + 1] + run;
			}
		}
		built += row * (h + 1);
	}
	return AJAR_OK;
}

/* Texel indices lo..hi (of n) as a small range [*a, *b] that the wrap
 * mode maps onto the same texels: clamped, or shifted by whole periods
 * (two images wide, for mirrored repeat), or all of one period. */
static void scan_range(double lo, double hi, int n, int mode, long *a, long *b)
{
	if (mode == TEX_WRAP_CLAMP) {
		*a = (long)fmin(fmax(lo, 0.0), n - 1.0);
		*b = (long)fmin(fmax(hi, 0.0), n - 1.0);
	} else if (hi - lo >= 2.0 * n) {
		*a = 0;
		*b = 2L * n - 1;
	} else {
		double shift = 2.0 * n * floor(lo / (2.0 * n));
		*a = (long)(lo - shift);
		*b = (long)(hi - shift);
	}
}

/* The texels [a, b] maps to, as intervals of [0, n): the range is cut at
 * every multiple of n, inside which the wrap is monotone. At most 5 (b - a
 * < 4n after scan_range). */
static int axis_spans(long a, long b, int n, int mode, int lo[5], int hi[5])
{
	int k = 0;
	for (long s = a; s <= b && k < 5;) {
		long e = (s / n + 1) * (long)n - 1;
		if (e > b)
			e = b;
		int p = texture_wrap((int)s, n, mode), q = texture_wrap((int)e, n, mode);
		lo[k] = p < q ? p : q;
		hi[k] = p < q ? q : p;
		k++;
		s = e + 1;
	}
	return k;
}

/* Non-black texels in columns [x0, x1] and rows [y0, y1] of a table. */
static uint32_t rect(const uint32_t *s, size_t row, int x0, int x1, int y0, int y1)
{
	return s[(size_t)(y1 + 1) * row + (size_t)x1 + 1] - s[(size_t)y0 * row + (size_t)x1 + 1] -
	       s[(size_t)(y1 + 1) * row + (size_t)x0] + s[(size_t)y0 * row + (size_t)x0];
}

int emit_mask_can_emit(const EmitMask *m, const SceneView *v, uint32_t i, int tex)
{
	const Texture *t = &v->textures[tex];
	double x[3], y[3];
	scene_tri_texel_coords(v, i, tex, x, y);
	const double eps = 1e-3; /* float rounding in the kernel's lookup */
	double x0 = floor(fmin(x[0], fmin(x[1], x[2])) - 0.5 - eps), x1 = floor(fmax(x[0], fmax(x[1], x[2])) - 0.5 + eps) + 1;
	double y0 = floor(fmin(y[0], fmin(y[1], y[2])) - 0.5 - eps), y1 = floor(fmax(y[0], fmax(y[1], y[2])) - 0.5 + eps) + 1;
	if (!(x1 - x0 < 1e15 && y1 - y0 < 1e15))
		return 1; /* coordinates beyond any lookup's precision: may emit anywhere */
	long ax, bx, ay, by;
	scan_range(x0, x1, t->width, TEX_WRAP_S(t->flags), &ax, &bx);
	scan_range(y0, y1, t->height, TEX_WRAP_T(t->flags), &ay, &by);
	int xl[5], xh[5], yl[5], yh[5];
	int nx = axis_spans(ax, bx, t->width, TEX_WRAP_S(t->flags), xl, xh);
	int ny = axis_spans(ay, by, t->height, TEX_WRAP_T(t->flags), yl, yh);
	if (m && (uint32_t)tex < m->ntextures && m->at[tex] != SIZE_MAX) {
		const uint32_t *s = m->sat + m->at[tex];
		for (int a = 0; a < ny; a++)
			for (int b = 0; b < nx; b++)
				if (rect(s, (size_t)t->width + 1, xl[b], xh[b], yl[a], yh[a]))
					return 1;
		return 0;
	}
	for (int a = 0; a < ny; a++)
		for (int yy = yl[a]; yy <= yh[a]; yy++)
			for (int b = 0; b < nx; b++)
				for (int xx = xl[b]; xx <= xh[b]; xx++)
					if (lit(v->texels[t->offset + (size_t)yy * t->width + xx]))
						return 1;
	return 0;
}
