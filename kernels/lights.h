/* lights.h — evaluating and sampling what emits light: emissive triangles
 * (one-sided, front = CCW) and the environment (env.h, env_portal.h), for
 * next-event estimation, and the portal triangles where intermediate
 * subpaths start. Tables come from src/lights.c and src/portal_flux.c.
 * Every pdf names its measure: _a area, _w solid angle. */
#ifndef AJAR_KERNEL_LIGHTS_H
#define AJAR_KERNEL_LIGHTS_H
#include "types.h"
#include "sampling.h"
#include "bvh.h"
#include "env_portal.h"
#include "surface.h"

/* Emitted radiance of emitter triangle `tri` at its point p, front face:
 * the material's emission times its emissive texture (sRGB colour) and,
 * on alpha-tested triangles, its coverage (texture.h). */
INLINE V3 emitter_emission(const SceneView *sc, int tri, V3 p)
{
	GLOBAL const Tri *t = &sc->tris[tri];
	GLOBAL const Material *m = &sc->materials[t->material];
	if (!m->emissive_tex && !(t->flags & TRI_ALPHA))
		return m->emission;
	float b1, b2;
	tri_barycentric(t, p, &b1, &b2);
	V3 e = m->emission;
	if (m->emissive_tex)
		e = v3_mul(e, tri_texture(sc, tri, b1, b2, m->emissive_tex - 1, 1).rgb);
	/* Where rays pass through it (alpha), it emits that much less. */
	if (t->flags & TRI_ALPHA)
		e = v3_scale(e, tri_coverage(sc, tri, b1, b2));
	return e;
}

/* Radiance leaving triangle `tri` at its point p in direction w (any
 * length): the emission on the front face, 0 behind it or if not an
 * emitter. */
INLINE V3 emitter_radiance(const SceneView *sc, int tri, V3 p, V3 w)
{
	GLOBAL const Tri *t = &sc->tris[tri];
	if (t->emitter < 0 || !(v3_dot(tri_normal(t), w) > 0.0f))
		return v3(0.0f, 0.0f, 0.0f);
	return emitter_emission(sc, tri, p);
}

/* The cells of an emitter at level L (src/lights.c): the triangle's
 * barycentric square (b1, b2) cut into an n x n grid, n = 2^L; square
 * (i, j) with i + j < n holds a lower half (i, j), (i + 1, j), (i, j + 1)
 * and, where i + j < n - 1, an upper half (i + 1, j), (i + 1, j + 1),
 * (i, j + 1): n^2 triangles of equal area. Row i (b1 in [i, i + 1) / n)
 * has 2 (n - i) - 1 cells and starts at cell i (2n - i); in a row, lower
 * then upper half of each square in order of j. */
INLINE int emitter_cell_of(int level, float b1, float b2)
{
	int n = 1 << level;
	float x = b1 * (float)n, y = b2 * (float)n;
	int i = min((int)x, n - 1);
	int j = min((int)y, n - 1 - i);
	int upper = i + j < n - 1 && (x - (float)i) + (y - (float)j) > 1.0f;
	return i * (2 * n - i) + 2 * j + upper;
}

/* Corners of cell c at `level` in barycentric coordinates (b1, b2). */
INLINE void emitter_cell_corners(int level, int c, float *b1, float *b2)
{
	int n = 1 << level;
	int i = (int)((float)n - sqrt((float)n * (float)n - (float)c));
	i = max(min(i, n - 1), 0);
	while (i > 0 && i * (2 * n - i) > c)
		i--;
	while (i + 1 < n && (i + 1) * (2 * n - i - 1) <= c)
		i++;
	int r = c - i * (2 * n - i), j = r >> 1;
	float s = 1.0f / (float)n;
	if (r & 1) {
		b1[0] = (float)(i + 1) * s, b2[0] = (float)j * s;
		b1[1] = (float)(i + 1) * s, b2[1] = (float)(j + 1) * s;
	} else {
		b1[0] = (float)i * s, b2[0] = (float)j * s;
		b1[1] = (float)(i + 1) * s, b2[1] = (float)j * s;
	}
	b1[2] = (float)i * s, b2[2] = (float)(j + 1) * s;
}

/* Area density (selection included) of sampling point p on `tri`. */
INLINE float emitter_pdf_a(const SceneView *sc, int tri, V3 p)
{
	int e = sc->tris[tri].emitter;
	if (e < 0)
		return 0.0f;
	int level = EMITTER_LEVEL(sc->emitters[e].cell);
	if (level) {
		float b1, b2;
		tri_barycentric(&sc->tris[tri], p, &b1, &b2);
		e += emitter_cell_of(level, b1, b2);
	}
	return sc->emitters[e].pdf_select / sc->emitters[e].area;
}

/* Picks an emitter (or emitter cell) by power (u_sel) and a uniform point
 * on it (u1, u2): position *p, unit front normal *n, *pdf_a including the
 * selection. Returns the triangle index, or -1 if there are no emitters. */
INLINE int emitter_sample(const SceneView *sc, float u_sel, float u1, float u2, V3 *p, V3 *n,
			  float *pdf_a)
{
	float p_sel, u_rest;
	*pdf_a = 0.0f;
	*p = v3(0.0f, 0.0f, 0.0f);
	*n = v3(0.0f, 0.0f, 1.0f);
	int k = sample_cdf(sc->emitter_cdf, sc->params->num_emitters, u_sel, &p_sel, &u_rest);
	if (k < 0)
		return -1;
	GLOBAL const Emitter *e = &sc->emitters[k];
	GLOBAL const Tri *t = &sc->tris[e->tri];
	int level = EMITTER_LEVEL(e->cell);
	if (!level) {
		sample_triangle_point(t->p0, t->p1, t->p2, u1, u2, p, n);
	} else {
		float b1[3], b2[3];
		emitter_cell_corners(level, EMITTER_INDEX(e->cell), b1, b2);
		V3 c[3], e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
		for (int i = 0; i < 3; i++)
			c[i] = v3_add(t->p0, v3_add(v3_scale(e1, b1[i]), v3_scale(e2, b2[i])));
		sample_triangle_point(c[0], c[1], c[2], u1, u2, p, n);
		*n = v3_norm(tri_normal(t)); /* the cell's own cross product is less exact */
	}
	*pdf_a = e->pdf_select / e->area;
	return e->tri;
}

typedef struct {
	V3 p;        /* point on the emitter (x itself for the environment) */
	V3 n;        /* unit light normal (-wi for the environment) */
	V3 wi;       /* unit, from x toward the light */
	float dist;  /* to p, or AJAR_INF for the environment */
	V3 Le;       /* radiance arriving at x along -wi */
	float pdf_w; /* solid angle at x, selection included */
	int is_env;
	int tri;     /* the emitter triangle, -1 for the environment */
} LightSample;

/* The emitter half of light_sample: an emitter by power (u), a uniform
 * point on it (u1, u2), chosen in all with probability p_emitters. */
INLINE int light_sample_emitter(const SceneView *sc, V3 x, float u, float u1, float u2, float p_emitters,
				LightSample *ls)
{
	float pdf_a;
	V3 p, n;
	int tri = emitter_sample(sc, u, u1, u2, &p, &n, &pdf_a);
	if (tri < 0)
		return 0;
	V3 to = v3_sub(p, x);
	float dist2 = v3_len2(to);
	if (!(dist2 > 0.0f))
		return 0;
	float dist = sqrt(dist2);
	V3 wi = v3_scale(to, 1.0f / dist);
	float cos_light = -v3_dot(n, wi);
	if (!(cos_light > 0.0f) || !(pdf_a > 0.0f))
		return 0;
	ls->is_env = 0;
	ls->p = p;
	ls->n = n;
	ls->wi = wi;
	ls->dist = dist;
	ls->tri = tri;
	ls->Le = emitter_emission(sc, tri, p);
	ls->pdf_w = p_emitters * pdf_a * dist2 / cos_light;
	return 1;
}

/* Next-event estimation from shading point x with normal n: the
 * environment with probability Params.env_pdf_select (through the portals
 * that show x the sky, weighed by n, env_portal.h), else an emitter by
 * power and a uniform point on it. Returns 0 when there is nothing to
 * sample or the sample cannot carry light (emitter seen from behind or
 * edge-on, zero distance, zero density); the caller then adds nothing. */
CALLED int light_sample(const SceneView *sc, V3 x, V3 n, float u_sel, float u1, float u2, LightSample *ls)
{
	float ps = sc->params->env_pdf_select;
	ls->is_env = 0;
	ls->tri = -1;
	ls->pdf_w = 0.0f;
	ls->Le = v3(0.0f, 0.0f, 0.0f);
	if (u_sel < ps) {
		float pdf_w;
		V3 wi;
		ls->Le = env_nee_sample(sc, x, n, u_sel / ps, u1, u2, &wi, &pdf_w);
		if (!(pdf_w > 0.0f))
			return 0;
		ls->is_env = 1;
		ls->wi = wi;
		ls->p = x;
		ls->n = v3_neg(wi);
		ls->dist = AJAR_INF;
		ls->pdf_w = ps * pdf_w;
		return 1;
	}
	/* u_sel in [ps, 1) stretched back to [0, 1) for the emitter choice. */
	return light_sample_emitter(sc, x, fmin((u_sel - ps) / (1.0f - ps), 0.99999994f), u1, u2, 1.0f - ps, ls);
}

/* Solid-angle density (selection included) with which light_sample from
 * x with normal n yields direction wi toward emitter triangle `tri` hit at distance
 * `dist` where the light's cosine with -wi is cos_light, or toward the
 * environment when tri < 0. For MIS on BSDF-sampled hits. */
INLINE float light_pdf_w(const SceneView *sc, V3 x, V3 n, V3 wi, int tri, float dist, float cos_light)
{
	float ps = sc->params->env_pdf_select;
	if (tri < 0)
		return ps * env_nee_pdf_w(sc, x, n, wi);
	float pdf_a = emitter_pdf_a(sc, tri, v3_add(x, v3_scale(wi, dist)));
	if (!(pdf_a > 0.0f) || !(cos_light > 0.0f))
		return 0.0f;
	return (1.0f - ps) * pdf_a * dist * dist / cos_light;
}

/* Picks a portal triangle by area (u_sel) and a uniform point on it:
 * *p, unit normal *n (p1 - p0) x (p2 - p0), *pdf_a including the
 * selection. Returns the portal triangle's index, or -1 if none. */
INLINE int portal_sample(const SceneView *sc, float u_sel, float u1, float u2, V3 *p, V3 *n,
			 float *pdf_a)
{
	float p_sel, u_rest;
	*pdf_a = 0.0f;
	*p = v3(0.0f, 0.0f, 0.0f);
	*n = v3(0.0f, 0.0f, 1.0f);
	int k = sample_cdf(sc->portal_cdf, sc->params->num_portals, u_sel, &p_sel, &u_rest);
	if (k < 0)
		return -1;
	GLOBAL const PortalTri *t = &sc->portals[k];
	sample_triangle_point(t->p0, t->p1, t->p2, u1, u2, p, n);
	*pdf_a = t->pdf_select / t->area;
	return k;
}

#endif
