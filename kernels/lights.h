/* lights.h — evaluating and sampling what emits light: emissive triangles
 * (one-sided, front = CCW), the environment (a constant colour or an
 * equirectangular image), and the portal triangles where intermediate
 * subpaths start. Tables come from src/lights.c.
 *
 * Environment convention: a unit direction d pointing from the scene out
 * to the sky maps to u = 0.5 + atan2(d.x, -d.z) / (2 pi),
 * v = acos(d.y) / pi, row 0 at the top (+Y), so the image centre looks
 * down -Z. Radiance is piecewise constant per texel (nearest texel); a
 * texel is sampled uniformly in (u, v), so the solid-angle density is
 * p_row p_col W H / (2 pi^2 sin(theta)), and env_sample reports exactly
 * what env_pdf_w returns for the same direction. Every pdf names its measure: _a area, _w solid angle. */
#ifndef AJAR_KERNEL_LIGHTS_H
#define AJAR_KERNEL_LIGHTS_H
#include "types.h"
#include "sampling.h"
#include "bvh.h"

/* Direction of equirect coordinates (u, v) in [0,1]^2. */
INLINE V3 env_dir(float u, float v)
{
	float phi = 2.0f * AJAR_PI * (u - 0.5f), theta = AJAR_PI * v;
	float st = sin(theta);
	return v3(st * sin(phi), cos(theta), -st * cos(phi));
}

/* Texel (row, col) under unit direction d; returns sin(theta) of d. */
INLINE float env_texel(GLOBAL const Params *prm, V3 d, int *row, int *col)
{
	float y = fmin(fmax(d.y, -1.0f), 1.0f);
	float u = 0.5f + atan2(d.x, -d.z) * AJAR_INV_2PI;
	float v = acos(y) * AJAR_INV_PI;
	int w = prm->env_width, h = prm->env_height;
	int c = (int)(u * (float)w), r = (int)(v * (float)h);
	*col = c < 0 ? 0 : (c >= w ? w - 1 : c);
	*row = r < 0 ? 0 : (r >= h ? h - 1 : r);
	/* Not sqrt(1 - y^2): near the poles y rounds to 1 long before
	 * sin(theta) is negligible. */
	return sqrt(d.x * d.x + d.z * d.z);
}

INLINE V3 env_pixel(const SceneView *sc, int row, int col)
{
	int w = sc->params->env_width;
	GLOBAL const float *p = sc->env + ENV_PIXELS(w, sc->params->env_height) + 3 * (row * w + col);
	return v3(p[0], p[1], p[2]);
}

/* Solid-angle density of the image's own sampling at texel (row, col). */
INLINE float env_texel_pdf_w(const SceneView *sc, int row, int col, float sin_theta)
{
	int w = sc->params->env_width, h = sc->params->env_height;
	if (!(sin_theta > 0.0f))
		return 0.0f;
	GLOBAL const float *marg = sc->env + ENV_MARGINAL(w, h);
	GLOBAL const float *cond = sc->env + ENV_CONDITIONAL(w, h) + row * (w + 1);
	float p_uv = (marg[row + 1] - marg[row]) * (cond[col + 1] - cond[col]) * (float)(w * h);
	return p_uv / (2.0f * AJAR_PI * AJAR_PI * sin_theta);
}

/* Radiance arriving from the sky along -d (d points to the sky). */
INLINE V3 env_radiance(const SceneView *sc, V3 d)
{
	GLOBAL const Params *prm = sc->params;
	if (prm->env_type == ENV_COLOR)
		return prm->env_color;
	if (prm->env_type != ENV_IMAGE)
		return v3(0.0f, 0.0f, 0.0f);
	int row, col;
	env_texel(prm, d, &row, &col);
	return env_pixel(sc, row, col);
}

/* Samples a sky direction *d by the environment's own distribution and
 * returns its radiance; *pdf_w = 0 (and black) if there is none, or, very
 * rarely, if rounding carried the sample into a texel that has none. */
INLINE V3 env_sample(const SceneView *sc, float u1, float u2, V3 *d, float *pdf_w)
{
	GLOBAL const Params *prm = sc->params;
	*pdf_w = 0.0f;
	*d = v3(0.0f, 1.0f, 0.0f);
	if (prm->env_type == ENV_COLOR) {
		*d = sample_uniform_sphere(u1, u2);
		*pdf_w = pdf_uniform_sphere_w();
		return prm->env_color;
	}
	if (prm->env_type != ENV_IMAGE)
		return v3(0.0f, 0.0f, 0.0f);
	int w = prm->env_width, h = prm->env_height;
	float p_row, p_col, ur, uc;
	int row = sample_cdf(sc->env + ENV_MARGINAL(w, h), h, u1, &p_row, &ur);
	if (row < 0)
		return v3(0.0f, 0.0f, 0.0f);
	int col = sample_cdf(sc->env + ENV_CONDITIONAL(w, h) + row * (w + 1), w, u2, &p_col, &uc);
	if (col < 0)
		return v3(0.0f, 0.0f, 0.0f);
	*d = env_dir(((float)col + uc) / (float)w, ((float)row + ur) / (float)h);
	/* Density and radiance from d's own texel, exactly what env_pdf_w
	 * and env_radiance return for d, even where rounding put a sample on
	 * a texel edge into the neighbour. */
	float sin_theta = env_texel(prm, *d, &row, &col);
	*pdf_w = env_texel_pdf_w(sc, row, col, sin_theta);
	return *pdf_w > 0.0f ? env_pixel(sc, row, col) : v3(0.0f, 0.0f, 0.0f);
}

/* Solid-angle density with which env_sample returns direction d. */
INLINE float env_pdf_w(const SceneView *sc, V3 d)
{
	GLOBAL const Params *prm = sc->params;
	if (prm->env_type == ENV_COLOR)
		return pdf_uniform_sphere_w();
	if (prm->env_type != ENV_IMAGE)
		return 0.0f;
	int row, col;
	float sin_theta = env_texel(prm, d, &row, &col);
	return env_texel_pdf_w(sc, row, col, sin_theta);
}

/* Radiance leaving triangle `tri` in direction w (any length): the
 * material's emission on the front face, 0 behind it or if not emissive. */
INLINE V3 emitter_radiance(const SceneView *sc, int tri, V3 w)
{
	GLOBAL const Tri *t = &sc->tris[tri];
	if (t->emitter < 0 || !(v3_dot(tri_normal(t), w) > 0.0f))
		return v3(0.0f, 0.0f, 0.0f);
	return sc->materials[t->material].emission;
}

/* Area density (selection included) of sampling a point on `tri`. */
INLINE float emitter_pdf_a(const SceneView *sc, int tri)
{
	int e = sc->tris[tri].emitter;
	if (e < 0)
		return 0.0f;
	return sc->emitters[e].pdf_select / sc->emitters[e].area;
}

/* Picks an emitter by power (u_sel) and a uniform point on it (u1, u2):
 * position *p, unit front normal *n, *pdf_a including the selection.
 * Returns the triangle index, or -1 if there are no emitters. */
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
	sample_triangle_point(t->p0, t->p1, t->p2, u1, u2, p, n);
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

/* Next-event estimation from shading point x: the environment with
 * probability Params.env_pdf_select, else an emitter by power and a
 * uniform point on it. Returns 0 when there is nothing to sample or the
 * sample cannot carry light (emitter seen from behind or edge-on, zero
 * distance, zero density); the caller then adds nothing. */
INLINE int light_sample(const SceneView *sc, V3 x, float u_sel, float u1, float u2, LightSample *ls)
{
	float ps = sc->params->env_pdf_select;
	ls->is_env = 0;
	ls->tri = -1;
	ls->pdf_w = 0.0f;
	ls->Le = v3(0.0f, 0.0f, 0.0f);
	if (u_sel < ps) {
		float pdf_w;
		V3 wi;
		ls->Le = env_sample(sc, u1, u2, &wi, &pdf_w);
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
	float u = fmin((u_sel - ps) / (1.0f - ps), 0.99999994f);
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
	ls->p = p;
	ls->n = n;
	ls->wi = wi;
	ls->dist = dist;
	ls->tri = tri;
	ls->Le = sc->materials[sc->tris[tri].material].emission;
	ls->pdf_w = (1.0f - ps) * pdf_a * dist2 / cos_light;
	return 1;
}

/* Solid-angle density (selection included) with which light_sample from
 * x yields direction wi toward emitter triangle `tri` hit at distance
 * `dist` where the light's cosine with -wi is cos_light, or toward the
 * environment when tri < 0. For MIS on BSDF-sampled hits. */
INLINE float light_pdf_w(const SceneView *sc, V3 x, V3 wi, int tri, float dist, float cos_light)
{
	float ps = sc->params->env_pdf_select;
	if (tri < 0)
		return ps * env_pdf_w(sc, wi);
	float pdf_a = emitter_pdf_a(sc, tri);
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
