/* lights.h — evaluating and sampling what emits light: emissive triangles
 * (one-sided, front = CCW), punctual lights (KHR_lights_punctual: point,
 * spot, directional) and the environment (env.h, env_portal.h), for
 * next-event estimation and light subpaths, and the portal triangles where
 * intermediate subpaths start. Tables come from src/prepare/light_tables.c and src/prepare/portal_flux.c.
 * Every pdf names its measure: _a area, _w solid angle. */
#ifndef AJAR_KERNEL_LIGHTS_H
#define AJAR_KERNEL_LIGHTS_H
#include "base/types.h"
#include "sample/sampling.h"
#include "geom/bvh.h"
#include "light/env_portal.h"
#include "geom/surface.h"
#include "geom/portal_crossing.h"

/* Emitted radiance of emitter triangle `tri` at its point p, front face:
 * the material's emission times its emissive texture (sRGB colour) and,
 * on alpha-tested triangles, its coverage (texture.h). */
INLINE V3 emitter_emission(const SceneView *sc, int tri, V3 p)
{
	GLOBAL const Tri *t = &sc->tris[tri];
	GLOBAL const Material *m = &sc->materials[t->material];
#if defined(AJAR_NO_TEXTURES) && defined(AJAR_NO_ALPHA)
	return m->emission; /* a specialised program (src/prepare/prepare.c, kernel_omit) */
#endif
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

/* The cells of an emitter at level L (src/prepare/light_tables.c): the triangle's
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

/* Index in emitter_cdf chosen by u_sel: an emitter below num_emitters,
 * a punctual light from there on; -1 if the table is empty. */
INLINE int light_pick(const SceneView *sc, float u_sel)
{
	float p_sel, u_rest;
	return sample_cdf(sc->emitter_cdf, sc->params->num_emitters + sc->params->num_lights, u_sel, &p_sel, &u_rest);
}

/* A uniform point on emitter (or emitter cell) k (see emitter_sample);
 * returns its triangle. */
INLINE int emitter_point(const SceneView *sc, int k, float u1, float u2, V3 *p, V3 *n, float *pdf_a)
{
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

/* Picks an emitter by power (u_sel) and a uniform point on it (u1, u2):
 * position *p, unit front normal *n, *pdf_a including the selection.
 * Returns the triangle index, or -1 if there are no emitters or the choice
 * fell on a punctual light (which shares the table, after the emitters:
 * callers that do not take punctual lights lose that share, which their
 * densities, summing over emitter points only, already leave out). */
INLINE int emitter_sample(const SceneView *sc, float u_sel, float u1, float u2, V3 *p, V3 *n,
			  float *pdf_a)
{
	*pdf_a = 0.0f;
	*p = v3(0.0f, 0.0f, 0.0f);
	*n = v3(0.0f, 0.0f, 1.0f);
	int k = light_pick(sc, u_sel);
	if (k < 0 || k >= sc->params->num_emitters)
		return -1;
	return emitter_point(sc, k, u1, u2, p, n, pdf_a);
}

/* Radiant intensity (W/sr) of point or spot light `l` toward unit w at
 * distance d, with the spec's windows (KHR_lights_punctual): a spot's
 * t^2, t = clamp((cos - cos outer) / (cos inner - cos outer), 0, 1), and
 * `range`'s clamp(1 - (d / range)^4, 0, 1). */
INLINE V3 punctual_intensity(GLOBAL const PunctualLight *l, V3 w, float d)
{
	float k = 1.0f;
	if (l->type == LIGHT_SPOT) {
		float t = fmin(fmax((v3_dot(w, l->dir) - l->cos_outer) * l->cone_scale, 0.0f), 1.0f);
		k = t * t;
	}
	if (l->range > 0.0f) {
		float r = d / l->range, r2 = r * r;
		k *= fmin(fmax(1.0f - r2 * r2, 0.0f), 1.0f);
	}
	return v3_scale(l->intensity, k);
}

/* What punctual light `l` sends to point x: *wi (unit, from x toward the
 * light), *dist (AJAR_INF for a directional light) and the irradiance it
 * gives a surface perpendicular to wi: I(-wi) / d^2, or E. */
INLINE V3 punctual_arrive(GLOBAL const PunctualLight *l, V3 x, V3 *wi, float *dist)
{
	if (l->type == LIGHT_DIRECTIONAL) {
		*wi = v3_neg(l->dir);
		*dist = AJAR_INF;
		return l->intensity;
	}
	V3 to = v3_sub(l->pos, x);
	float d2 = v3_len2(to);
	*dist = sqrt(d2);
	*wi = v3(0.0f, 0.0f, 1.0f);
	if (!(d2 > 0.0f))
		return v3(0.0f, 0.0f, 0.0f);
	*wi = v3_scale(to, 1.0f / *dist);
	return v3_scale(punctual_intensity(l, v3_neg(*wi), *dist), 1.0f / d2);
}

/* Solid-angle density with which a light subpath leaves point or spot
 * light `l` in unit direction w: uniform on the sphere, or uniform in the
 * spot's outer cone (its light is zero outside). */
INLINE float punctual_dir_pdf(GLOBAL const PunctualLight *l, V3 w)
{
	if (l->type != LIGHT_SPOT)
		return pdf_uniform_sphere_w();
	if (!(v3_dot(w, l->dir) >= l->cos_outer))
		return 0.0f;
	return pdf_uniform_cone_w(l->cos_outer);
}

/* A light subpath's direction from point or spot light `l` (density
 * punctual_dir_pdf). */
INLINE V3 punctual_dir_sample(GLOBAL const PunctualLight *l, float u1, float u2)
{
	if (l->type != LIGHT_SPOT)
		return sample_uniform_sphere(u1, u2);
	V3 t, b;
	v3_basis(l->dir, &t, &b);
	return v3_from_local(sample_uniform_cone(u1, u2, l->cos_outer), t, b, l->dir);
}

/* Light subpaths from a light at infinity (a directional light, or the
 * environment in a sampled direction) are parallel rays along a unit
 * travel direction w. Without portals their lines cross a disk of radius R
 * (the scene's) perpendicular to w uniformly. With portals, all but
 * SUN_DISK_SHARE of them pass through a point on a portal triangle, the
 * triangle picked in proportion to its area projected toward w, A_j |n_j.w|
 * (a scan: portals are few), the point uniform on it, so that light
 * subpaths go where an opening lets the light in; the share on the disk
 * keeps every line the light sends into the scene at a positive density (a
 * sunlit outside wall, an opening without a portal), so a zero density
 * always means a zero contribution, as the MIS weights assume. The density
 * per unit area perpendicular to w of the line through x: SUN_DISK_SHARE /
 * (pi R^2) within the disk (all of it without portals, or if every portal
 * is edge-on to w), plus (1 - SUN_DISK_SHARE) times the number of portal
 * triangles (with |n.w| > 0) the whole line crosses over S = sum_k A_k
 * |n_k.w| (each crossed triangle j contributes A_j |n_j.w| / S for its
 * choice times 1 / (A_j |n_j.w|) per perpendicular area). The same
 * function at sampling and in every MIS record (vertex_density.h,
 * bdpt_emission_pdf; kernels/light/README.md, "Punctual lights" (why 10% on the disk)). */
#define SUN_DISK_SHARE 0.1f

/* Whether an environment's light subpaths take these lines through the
 * portals: a sky image's (its sun finds the way in); a constant sky keeps
 * the disk, where its next-event estimation through the portals already
 * takes the direct light and the light subpaths that come in only added
 * variance and time (kernels/light/README.md, "Punctual lights" (why 10% on the disk)). */
INLINE int env_lines_through_portals(const SceneView *sc)
{
	return sc->params->env_type == ENV_IMAGE && sc->params->num_portals > 0;
}

/* S = sum_k A_k |n_k.w| over the portal triangles. */
INLINE float line_portal_area(const SceneView *sc, V3 w)
{
	float s = 0.0f;
	for (int i = 0; i < sc->params->num_portals; i++)
		s += sc->portals[i].area * fabs(v3_dot(sc->portals[i].n, w));
	return s;
}

INLINE float line_pdf_perp(const SceneView *sc, V3 w, float R, V3 x)
{
	int np = sc->params->num_portals;
	float r = sc->params->scene_radius, t;
	V3 q = v3_sub(x, sc->params->scene_center);
	V3 perp = v3_sub(q, v3_scale(w, v3_dot(q, w)));
	float disk = v3_len2(perp) <= R * R ? 1.0f / (AJAR_PI * R * R) : 0.0f;
	float s = np > 0 ? line_portal_area(sc, w) : 0.0f;
	if (!(s > 0.0f))
		return disk;
	/* The line from behind the scene's bounding sphere, as a segment. */
	V3 o = v3_sub(x, v3_scale(w, v3_dot(q, w) + 2.0f * r));
	V3 d = v3_scale(w, 4.0f * r);
	int n = 0;
	for (int i = 0; i < np; i++) {
		GLOBAL const PortalTri *pt = &sc->portals[i];
		if (pt->area * fabs(v3_dot(pt->n, w)) > 0.0f &&
		    portal_tri_crossing(o, d, 1.0f, pt->p0, pt->p1, pt->p2, &t))
			n++;
	}
	return SUN_DISK_SHARE * disk + (1.0f - SUN_DISK_SHARE) * (float)n / s;
}

/* Samples a line along w (u_sel: disk or portal, and which triangle; u1,
 * u2: the point): *o, a point on it behind the scene's bounding sphere (the
 * ray o + t w, t > 0, meets everything the light reaches along it), and its
 * density *pdf_perp (line_pdf_perp). Returns 0 if there is none. */
INLINE int line_sample(const SceneView *sc, V3 w, float R, float u_sel, float u1, float u2, V3 *o, float *pdf_perp)
{
	GLOBAL const Params *prm = sc->params;
	int np = prm->num_portals;
	float r = prm->scene_radius;
	float s = np > 0 && u_sel >= SUN_DISK_SHARE ? line_portal_area(sc, w) : 0.0f;
	V3 x;
	if (!(s > 0.0f)) {
		float dx, dy;
		V3 t, b;
		v3_basis(w, &t, &b);
		sample_concentric_disk(u1, u2, &dx, &dy);
		x = v3_add(prm->scene_center, v3_add(v3_scale(t, dx * R), v3_scale(b, dy * R)));
	} else {
		float target = (u_sel - SUN_DISK_SHARE) / (1.0f - SUN_DISK_SHARE) * s, acc = 0.0f;
		int k = -1;
		for (int i = 0; i < np; i++) {
			float a = sc->portals[i].area * fabs(v3_dot(sc->portals[i].n, w));
			if (!(a > 0.0f))
				continue;
			k = i; /* the last one with a projected area, if rounding runs past the end */
			acc += a;
			if (target < acc)
				break;
		}
		GLOBAL const PortalTri *pt = &sc->portals[k];
		V3 n;
		sample_triangle_point(pt->p0, pt->p1, pt->p2, u1, u2, &x, &n);
	}
	*pdf_perp = line_pdf_perp(sc, w, R, x);
	*o = v3_sub(x, v3_scale(w, v3_dot(v3_sub(x, prm->scene_center), w) + 1.001f * r));
	return *pdf_perp > 0.0f;
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
	int light;   /* the punctual light, -1 for others */
	int delta;   /* a punctual light: Le is irradiance (W/m^2 perpendicular to wi),
		      * pdf_w the probability of the choice; no other strategy samples it */
} LightSample;

/* The emitter half of light_sample: an emitter or a punctual light by
 * power (u), a uniform point on an emitter (u1, u2), chosen in all with
 * probability p_emitters. */
INLINE int light_sample_emitter(const SceneView *sc, V3 x, float u, float u1, float u2, float p_emitters,
				LightSample *ls)
{
	float pdf_a;
	V3 p, n;
	ls->light = -1;
	ls->delta = 0;
	int k = light_pick(sc, u);
	if (k < 0)
		return 0;
	if (k >= sc->params->num_emitters) {
		/* A punctual light: its position or direction is fixed. */
		GLOBAL const PunctualLight *l = &sc->punctual[k - sc->params->num_emitters];
		ls->Le = punctual_arrive(l, x, &ls->wi, &ls->dist);
		if (!(l->pdf_select > 0.0f) || v3_is_zero(ls->Le))
			return 0;
		ls->is_env = 0;
		ls->tri = -1;
		ls->light = k - sc->params->num_emitters;
		ls->delta = 1;
		ls->p = l->type == LIGHT_DIRECTIONAL ? x : l->pos;
		ls->n = v3_neg(ls->wi);
		ls->pdf_w = p_emitters * l->pdf_select;
		return 1;
	}
	int tri = emitter_point(sc, k, u1, u2, &p, &n, &pdf_a);
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
 * that show x the sky, weighed by n, env_portal.h), else an emitter or a
 * punctual light by power (a uniform point on an emitter; a punctual
 * light's own position or direction, ls->delta). Returns 0 when there is nothing to
 * sample or the sample cannot carry light (emitter seen from behind or
 * edge-on, zero distance, zero density); the caller then adds nothing. */
CALLED int light_sample(const SceneView *sc, V3 x, V3 n, float u_sel, float u1, float u2, LightSample *ls)
{
	float ps = sc->params->env_pdf_select;
	ls->is_env = 0;
	ls->tri = -1;
	ls->light = -1;
	ls->delta = 0;
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

/* light_pdf_w toward the environment, given pe = env_pdf_w(sc, wi)
 * (env_radiance_pdf). */
INLINE float light_env_pdf_w(const SceneView *sc, V3 x, V3 n, V3 wi, float pe)
{
	return sc->params->env_pdf_select * env_nee_pdf_w_pe(sc, x, n, wi, pe);
}

/* The guided <- direction of an intermediate subpath (portal.h) aims at
 * the environment or at an emitter point, never at a punctual light (a
 * delta direction no other strategy samples): it chooses between the two
 * by the light choice's shares with the punctual lights' share taken out,
 * so that none of its samples is lost to them (with a sun lamp taking a
 * quarter of the choice, a quarter of the guided samples were). Returns
 * the environment's probability; *ce is the emitters' part of
 * emitter_cdf, by which their pdf_select is divided (1 without punctual
 * lights, where the choice is the light choice itself). */
INLINE float guided_env_share(const SceneView *sc, float *ce)
{
	GLOBAL const Params *prm = sc->params;
	float ps = prm->env_pdf_select;
	*ce = 1.0f;
	if (prm->num_lights == 0)
		return ps;
	*ce = sc->emitter_cdf[prm->num_emitters];
	float rest = (1.0f - ps) * *ce;
	return ps + rest > 0.0f ? ps / (ps + rest) : 0.0f;
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
