/* env_portal.h — next-event estimation of the environment through portals
 * (Cycles and pbrt-v4 sample windows the same way). From a shading point x
 * on the room side of a portal triangle (the side away from the sky, which
 * src/prepare/portal_flux.c finds), a triangle is picked in proportion to a cheap
 * stand-in for the solid angle it subtends, w_j = A_j cos_j / (d_j^2 +
 * A_j / 2 pi) from its centroid, and a direction is sampled uniformly
 * within its solid angle Omega_j (Arvo 1995). The exact Omega_j (an atan2
 * and three normalisations) is then only needed for the picked triangle
 * and for those a direction crosses, not for every triangle at every
 * sample and density evaluation, which cost a fifth of the render time.
 * Triangles that look tiny from x (Omega_j below PORTAL_SA_MIN sr, where
 * float spherical trigonometry loses its accuracy) are sampled by area
 * instead. The environment's own importance sampling is mixed in as a
 * defensive technique, for openings without portals and for a sun:
 *
 *   p_w(wi | x) = MIX sum_{j crossed by wi} (w_j / W) p_j(wi) + (1 - MIX) p_env(wi)
 *
 * with p_j = 1 / Omega_j (or d^2 / (A_j |cos|) by area), W the sum of the
 * w_j, and MIX = 0 where no portal shows x the sky. The density is a
 * function of x and wi alone, so every MIS weight that has the
 * environment as a next-event sample uses it (vertex_density.h). */
#ifndef AJAR_KERNEL_ENV_PORTAL_H
#define AJAR_KERNEL_ENV_PORTAL_H
#include "light/env.h"
#include "geom/portal_crossing.h"
#include "light/portal_sky.h"

/* The portals' share of next-event samples of the sky; -D overrides it
 * (AJAR_CL_OPTIONS) for experiments: sampling and densities read the same. */
#ifndef PORTAL_NEE_MIX
#define PORTAL_NEE_MIX 0.8f
#endif
/* The same share where the planes' sky tables sample an image
 * (sky_nee_sample): 0.9 lowered pt's variance per sample by 7% and 10% on
 * window-room-forest and -sunset and left living-room-forest's within 1%
 * (0.95: 11%, 13%, and 3% worse; kernels/light/README.md, "The portals' share of next-event samples"). The rest still finds a sun through an opening without
 * a portal. */
#ifndef PORTAL_SKY_NEE_MIX
#define PORTAL_SKY_NEE_MIX 0.9f
#endif
#define PORTAL_SA_MIN 1e-3f
#define PORTAL_COS_MIN 0.1f
#define PORTAL_W_KEPT 16

/* Solid angle of the triangle with unit corner directions a, b, c, seen
 * from their origin (Van Oosterom and Strackee 1983). */
INLINE float sph_tri_solid_angle(V3 a, V3 b, V3 c)
{
	float num = fabs(v3_dot(a, v3_cross(b, c)));
	float den = 1.0f + v3_dot(a, b) + v3_dot(b, c) + v3_dot(c, a);
	return 2.0f * fast_atan2(num, den);
}

/* A direction uniform within the spherical triangle (a, b, c) of solid
 * angle `omega` (after Arvo 1995): u1 picks the sub-triangle (a, b, c')
 * of solid angle u1 omega, u2 the point on the arc from b to c'. Written
 * with half-angle tangents and differences of nearby unit vectors rather
 * than Arvo's cosines, which lose the sub-triangle's corner c' in float
 * when it is thin (u1 near 0) or the arcs are short. The arc theta from
 * a to c' follows from the excess of a triangle with sides theta and
 * |ab| and angle alpha between them:
 *   tan(E / 2) = tan(theta / 2) tan(|ab| / 2) sin(alpha) / (1 + tan(theta / 2) tan(|ab| / 2) cos(alpha)),
 * solved for tan(theta / 2) with both sides multiplied by cos(E / 2): the
 * tangent itself passes infinity where a triangle seen from close by
 * covers more than pi sr (that skewed the directions and darkened the
 * living room by 0.5%), while sin(alpha - E / 2) stays positive, as
 * E < 2 alpha in every spherical triangle. */
INLINE V3 sph_tri_sample(V3 a, V3 b, V3 c, float omega, float u1, float u2)
{
	V3 nab = v3_cross(a, b), nac = v3_cross(a, c);
	float inv = 1.0f / sqrt(v3_len2(nab) * v3_len2(nac));
	float cos_alpha = v3_dot(nab, nac) * inv, sin_alpha = v3_len(v3_cross(nab, nac)) * inv;
	float k = v3_len(nab) / (1.0f + v3_dot(a, b)); /* tan(|ab| / 2) */
	float se, ce; /* of E / 2 in [0, pi] */
	fast_sincos(0.5f * u1 * omega, &se, &ce);
	float den = k * (ce * sin_alpha - se * cos_alpha); /* k sin(alpha - E / 2) > 0 */
	V3 cp = c;
	if (den > 0.0f) {
		float tt = se / den, tt2 = tt * tt; /* tan(theta / 2) */
		V3 ca = v3_sub(c, a);
		V3 c_perp = v3_norm(v3_add(ca, v3_scale(a, 0.5f * v3_len2(ca))));
		cp = v3_add(v3_scale(a, (1.0f - tt2) / (1.0f + tt2)), v3_scale(c_perp, 2.0f * tt / (1.0f + tt2)));
	}
	/* 1 - cos of the arc from b: u2 times that of c', |c' - b|^2 / 2. */
	V3 d = v3_sub(cp, b);
	float d2 = v3_len2(d), h = u2 * 0.5f * d2;
	V3 perp = v3_add(d, v3_scale(b, 0.5f * d2));
	float len = v3_len(perp);
	if (!(len > 0.0f))
		return b;
	return v3_add(v3_scale(b, 1.0f - h), v3_scale(perp, sqrt(fmax(0.0f, h * (2.0f - h))) / len));
}

/* Whether x lies on portal triangle pt's room side, with the sky behind it. */
INLINE int portal_env_facing(GLOBAL const PortalTri *pt, V3 x)
{
	return pt->env_side != 0 && (float)pt->env_side * v3_dot(v3_sub(x, pt->p0), pt->n) < 0.0f;
}

/* Solid angle of portal triangle pt seen from x when x lies on its room
 * side, else 0. */
INLINE float portal_env_solid_angle(GLOBAL const PortalTri *pt, V3 x)
{
	if (!portal_env_facing(pt, x))
		return 0.0f;
	V3 a = v3_norm(v3_sub(pt->p0, x)), b = v3_norm(v3_sub(pt->p1, x)), c = v3_norm(v3_sub(pt->p2, x));
	return sph_tri_solid_angle(a, b, c);
}

/* Selection weight w_j of portal triangle pt from x with normal n: its
 * projected area over the squared distance to its centroid, which is about
 * its solid angle, bounded by 2 pi cos as x comes close; 0 unless x is on
 * its room side (where the cosine is positive). Times the receiver's
 * cosine toward the centroid, max(0, n . c), floored at PORTAL_COS_MIN: a
 * window behind the surface at x is rarely worth a sample (on living-room
 * 30% of the samples fell below the horizon when the cosine was left out),
 * but the floor keeps it, and light through a translucent surface, within
 * reach. n is the shading normal turned toward where x is seen from
 * (vertex_nee_normal); n = 0 weighs every triangle by the floor alike,
 * which leaves the choice by solid angle alone. */
INLINE float portal_env_weight(GLOBAL const PortalTri *pt, V3 x, V3 n)
{
	if (!portal_env_facing(pt, x))
		return 0.0f;
	V3 d = v3_sub(v3_scale(v3_add(v3_add(pt->p0, pt->p1), pt->p2), 1.0f / 3.0f), x);
	float d2 = v3_len2(d), inv = 1.0f / sqrt(d2);
	float c = fabs(v3_dot(d, pt->n)) * inv;
	float cr = fmax(PORTAL_COS_MIN, v3_dot(d, n) * inv);
	return pt->area * c * cr / (d2 + pt->area * (1.0f / (2.0f * AJAR_PI)));
}

INLINE float env_portal_total(const SceneView *sc, V3 x, V3 n)
{
	float total = 0.0f;
	for (int j = 0; j < sc->params->num_portals; j++)
		total += portal_env_weight(&sc->portals[j], x, n);
	return total;
}

/* Triangle pt's term of the portal density toward unit wi, which crosses
 * it at distance t; p_sel is its selection probability w_j / W and omega
 * its solid angle from x. */
INLINE float env_portal_term(GLOBAL const PortalTri *pt, float p_sel, float omega, V3 wi, float t)
{
	if (omega >= PORTAL_SA_MIN)
		return p_sel / omega;
	float c = fabs(v3_dot(wi, pt->n));
	return c > 0.0f ? p_sel * t * t / (pt->area * c) : 0.0f;
}

/* The portal part of the density of wi from x: the sum over the portal
 * triangles the ray crosses, leaving out `skip` (-1 for none). */
CALLED float env_portal_pdf_w(const SceneView *sc, V3 x, V3 n, V3 wi, float total, int skip)
{
	float p = 0.0f;
	for (int j = 0; j < sc->params->num_portals; j++) {
		GLOBAL const PortalTri *pt = &sc->portals[j];
		float w, t;
		/* From the room side, only a ray toward the sky side meets the plane. */
		if (j == skip || !portal_env_facing(pt, x) || !((float)pt->env_side * v3_dot(wi, pt->n) > 0.0f) ||
		    !portal_tri_crossing(x, wi, AJAR_INF, pt->p0, pt->p1, pt->p2, &t) ||
		    !((w = portal_env_weight(pt, x, n)) > 0.0f))
			continue;
		p += env_portal_term(pt, w / total, portal_env_solid_angle(pt, x), wi, t);
	}
	return p;
}

/* ---- Sky images through planar portals (portal_sky.h) ----------------
 * Where the environment is an image, the host groups the portal triangles
 * into planar portals with tables of the sky behind them
 * (Params.num_portal_planes > 0), and the portal part of the density is
 *   sum_{P: wi in x's rectangle of P} (w_P / W) f_P(u, v) / (I_P dw/dudv)
 * with w_P = I_P max(PORTAL_COS_MIN, n . c_P): the sky's integral over the
 * rectangle x sees (not the portal's solid angle) times the receiver's
 * cosine toward the rectangle's centre c_P, floored as above. */

/* What x sees of plane P, apart from the receiver's normal: its
 * rectangle r, the sky's integral I_P over it (mass), the way d and
 * distance len to the rectangle's centre, and the rectangle's bounds in
 * tangents, (X0, X1) x (Y0, Y1) of X = w.t / w.n and Y = w.b / w.n
 * (sky_view_may_contain); ok = 0 where P shows x no sky (then its weight
 * is 0 and nothing else is read). */
typedef struct {
	SkyRect r;
	float mass, len;
	V3 d;
	float X0, X1, Y0, Y1;
	int ok;
} SkyPlaneView;

INLINE void sky_plane_view(const SceneView *sc, GLOBAL const PortalPlane *P, V3 x, SkyPlaneView *v)
{
	v->ok = 0;
	float xt, xb, h;
	if (!sky_rect_at(P, x, &v->r, &xt, &xb, &h))
		return;
	v->mass = sky_rect_integral(sc->portal_sky + P->table, &v->r);
	if (!(v->mass > 0.0f))
		return;
	v->d = v3_sub(sky_plane_centre(P), x);
	v->len = sqrt(v3_len2(v->d));
	float ih = 1.0f / h;
	v->X0 = (P->a0 - xt) * ih;
	v->X1 = (P->a1 - xt) * ih;
	v->Y0 = (P->b0 - xb) * ih;
	v->Y1 = (P->b1 - xb) * ih;
	v->ok = 1;
}

/* Plane P's selection weight from x with normal n, w_P = I_P max(
 * PORTAL_COS_MIN, n . d / |d|). */
INLINE float sky_view_weight(const SkyPlaneView *v, V3 n)
{
	if (!v->ok)
		return 0.0f;
	float cr = fmax(PORTAL_COS_MIN, v3_dot(v->d, n) / v->len);
	return v->mass * cr;
}

/* Whether unit wi (w.n > 0) may lie in v's rectangle: 0 only where
 * sky_pdf_uv would find (U, V) outside it. The test is in tangents, without
 * the two atan2 of sky_coords: X below X0 by more than SKY_TAN_MARGIN (1 +
 * max(X^2, X0^2)), which bounds the gap of their atans from below, puts U
 * below U0 by far more than fast_atan2's error (3e-7), sky_coord's
 * rounding (4e-7 rad at the far end) and the tangents' own (a few ulps,
 * by reciprocals): so the directions it drops are ones whose density term
 * was 0, and the sum is the same bits (test_lights,
 * test_sky_pdf_views, fails with a margin of 0). Infinite or NaN
 * tangents compare false and are kept. */
#define SKY_TAN_MARGIN 1e-5f
INLINE int sky_tan_outside(float X, float lo, float hi)
{
	float m = SKY_TAN_MARGIN * (1.0f + fmax(X * X, fmax(lo * lo, hi * hi)));
	return lo - X > m || X - hi > m;
}

INLINE int sky_view_may_contain(GLOBAL const PortalPlane *P, const SkyPlaneView *v, V3 wi)
{
	float iw = 1.0f / v3_dot(wi, P->n);
	float X = v3_dot(wi, P->t) * iw, Y = v3_dot(wi, P->b) * iw;
	return !(sky_tan_outside(X, v->X0, v->X1) || sky_tan_outside(Y, v->Y0, v->Y1));
}

/* The planes' views and weights from one x and n, computed once per
 * next-event sample or density: the first SKY_KEPT planes' views and
 * weights are kept, the rest computed again where needed; W is the sum of
 * the weights. */
#define SKY_KEPT 4
typedef struct {
	SkyPlaneView v[SKY_KEPT];
	float w[SKY_KEPT];
	float W;
} SkyWeights;

HOT_INLINE void sky_weights(const SceneView *sc, V3 x, V3 n, SkyWeights *sw)
{
	sw->W = 0.0f;
	for (int k = 0; k < sc->params->num_portal_planes; k++) {
		float w;
		if (k < SKY_KEPT) {
			sky_plane_view(sc, &sc->portal_planes[k], x, &sw->v[k]);
			w = sw->w[k] = sky_view_weight(&sw->v[k], n);
		} else {
			SkyPlaneView v;
			sky_plane_view(sc, &sc->portal_planes[k], x, &v);
			w = sky_view_weight(&v, n);
		}
		sw->W += w;
	}
}

/* Plane k's weight; *v points at its view (kept in sw, or computed into
 * *tmp). */
INLINE float sky_weight_of(const SceneView *sc, const SkyWeights *sw, int k, V3 x, V3 n, SkyPlaneView *tmp,
			   const SkyPlaneView **v)
{
	if (k >= SKY_KEPT) {
		*v = tmp;
		sky_plane_view(sc, &sc->portal_planes[k], x, tmp);
		return sky_view_weight(tmp, n);
	}
	*v = &sw->v[k];
	return sw->w[k];
}

/* The portal part of the density of unit wi from x (sw->W > 0); kn, if
 * not NULL, holds the knots of plane kn_plane's cell that wi was drawn
 * from (sky_nee_sample). */
INLINE float sky_portal_pdf_w_knots(const SceneView *sc, const SkyWeights *sw, V3 x, V3 n, V3 wi, int kn_plane,
				    const SkyKnots *kn)
{
	float p = 0.0f;
	for (int k = 0; k < sc->params->num_portal_planes; k++) {
		GLOBAL const PortalPlane *P = &sc->portal_planes[k];
		SkyPlaneView tmp;
		const SkyPlaneView *v;
		float U, V, jac;
		if (!(v3_dot(wi, P->n) > 0.0f))
			continue;
		float w = sky_weight_of(sc, sw, k, x, n, &tmp, &v);
		if (!(w > 0.0f) || !sky_view_may_contain(P, v, wi))
			continue;
		sky_coords(P, wi, &U, &V, &jac);
		float puv = sky_pdf_uv_knots(sc->portal_sky + P->table, &v->r, v->mass, U, V, k == kn_plane ? kn : 0);
		if (puv > 0.0f && jac > 0.0f)
			p += w / sw->W * puv / jac;
	}
	return p;
}

INLINE float sky_portal_pdf_w(const SceneView *sc, const SkyWeights *sw, V3 x, V3 n, V3 wi)
{
	return sky_portal_pdf_w_knots(sc, sw, x, n, wi, -1, 0);
}

/* The whole density of wi, given pe = env_pdf_w(sc, wi) (kn_plane, kn as
 * in sky_portal_pdf_w_knots). */
INLINE float sky_mix_pdf_w_knots(const SceneView *sc, const SkyWeights *sw, V3 x, V3 n, V3 wi, float pe,
				 int kn_plane, const SkyKnots *kn)
{
	if (!(sw->W > 0.0f))
		return pe;
	return PORTAL_SKY_NEE_MIX * sky_portal_pdf_w_knots(sc, sw, x, n, wi, kn_plane, kn) +
	       (1.0f - PORTAL_SKY_NEE_MIX) * pe;
}

INLINE float sky_mix_pdf_w(const SceneView *sc, const SkyWeights *sw, V3 x, V3 n, V3 wi, float pe)
{
	return sky_mix_pdf_w_knots(sc, sw, x, n, wi, pe, -1, 0);
}

INLINE float sky_nee_pdf_w(const SceneView *sc, V3 x, V3 n, V3 wi, float pe)
{
	SkyWeights sw;
	sky_weights(sc, x, n, &sw);
	return sky_mix_pdf_w(sc, &sw, x, n, wi, pe);
}

/* env_nee_sample where the planes have sky tables: the density is
 * recomputed from the direction (sky_mix_pdf_w), exactly what MIS reads. */
INLINE V3 sky_nee_sample(const SceneView *sc, V3 x, V3 n, float u_mix, float u1, float u2, V3 *wi, float *pdf_w)
{
	*pdf_w = 0.0f;
	SkyWeights sw;
	sky_weights(sc, x, n, &sw);
	if (u_mix >= PORTAL_SKY_NEE_MIX || !(sw.W > 0.0f)) {
		float pe;
		V3 Le = env_sample(sc, u1, u2, wi, &pe);
		if (!(pe > 0.0f))
			return v3(0.0f, 0.0f, 0.0f);
		*pdf_w = sky_mix_pdf_w(sc, &sw, x, n, *wi, pe); /* pe is env_pdf_w's (env.h) */
		return Le;
	}
	float target = u_mix / PORTAL_SKY_NEE_MIX * sw.W, cum = 0.0f;
	int pick = -1;
	SkyRect r;
	float mass = 0.0f;
	for (int k = 0; k < sc->params->num_portal_planes && cum <= target; k++) {
		SkyPlaneView tmp;
		const SkyPlaneView *v;
		float wk = sky_weight_of(sc, &sw, k, x, n, &tmp, &v);
		if (wk > 0.0f) { /* the last positive one if rounding leaves target >= the sum */
			pick = k;
			r = v->r;
			mass = v->mass;
			cum += wk;
		}
	}
	if (pick < 0)
		return v3(0.0f, 0.0f, 0.0f);
	GLOBAL const PortalPlane *P = &sc->portal_planes[pick];
	float U, V, jac;
	SkyKnots kn;
	if (!sky_sample_uv_knots(sc->portal_sky + P->table, &r, mass, u1, u2, &U, &V, &kn))
		return v3(0.0f, 0.0f, 0.0f);
	*wi = sky_dir(P, U, V, &jac);
	float pe;
	V3 Le = env_radiance_pdf(sc, *wi, &pe);
	/* The density from the final direction, with the drawn cell's knots
	 * where the direction's (U, V) falls back in that cell. */
	*pdf_w = sky_mix_pdf_w_knots(sc, &sw, x, n, *wi, pe, pick, &kn);
	return *pdf_w > 0.0f ? Le : v3(0.0f, 0.0f, 0.0f);
}

/* Solid-angle density with which env_nee_sample from x with normal n
 * returns wi, given pe = env_pdf_w(sc, wi) (env_radiance_pdf reads both
 * from one lookup). */
INLINE float env_nee_pdf_w_pe(const SceneView *sc, V3 x, V3 n, V3 wi, float pe)
{
	if (sc->params->num_portal_planes > 0)
		return sky_nee_pdf_w(sc, x, n, wi, pe);
	float total = env_portal_total(sc, x, n);
	if (!(total > 0.0f))
		return pe;
	return PORTAL_NEE_MIX * env_portal_pdf_w(sc, x, n, wi, total, -1) + (1.0f - PORTAL_NEE_MIX) * pe;
}

/* Solid-angle density with which env_nee_sample from x with normal n
 * returns wi. */
INLINE float env_nee_pdf_w(const SceneView *sc, V3 x, V3 n, V3 wi)
{
	return env_nee_pdf_w_pe(sc, x, n, wi, env_pdf_w(sc, wi));
}

/* Samples a sky direction *wi for shading point x with normal n (u_mix
 * picks the technique and the portal triangle, u1 and u2 the direction);
 * returns the radiance and *pdf_w, 0 and black when there is nothing to
 * sample. */
INLINE V3 env_nee_sample(const SceneView *sc, V3 x, V3 n, float u_mix, float u1, float u2, V3 *wi, float *pdf_w)
{
	if (sc->params->num_portal_planes > 0)
		return sky_nee_sample(sc, x, n, u_mix, u1, u2, wi, pdf_w);
	V3 black = v3(0.0f, 0.0f, 0.0f);
	float total = 0.0f, pe;
	*pdf_w = 0.0f;
	if (u_mix >= PORTAL_NEE_MIX) {
		total = env_portal_total(sc, x, n);
		if (!(total > 0.0f))
			return env_sample(sc, u1, u2, wi, pdf_w);
		V3 Le = env_sample(sc, u1, u2, wi, &pe);
		if (!(pe > 0.0f))
			return black;
		*pdf_w = PORTAL_NEE_MIX * env_portal_pdf_w(sc, x, n, *wi, total, -1) + (1.0f - PORTAL_NEE_MIX) * pe;
		return Le;
	}
	/* The triangle, by weight: the weights and their sum first (they are
	 * independent, so they pipeline), then a scan to u W. The first
	 * PORTAL_W_KEPT weights are kept for the scan, the rest computed again.
	 * (Picking in one pass, with the number rescaled at every step, chained
	 * two divisions per triangle and cost more than the weights.) */
	int np = sc->params->num_portals;
	float kept[PORTAL_W_KEPT];
	for (int k = 0; k < np; k++) {
		float wk = portal_env_weight(&sc->portals[k], x, n);
		if (k < PORTAL_W_KEPT)
			kept[k] = wk;
		total += wk;
	}
	float target = u_mix / PORTAL_NEE_MIX * total, cum = 0.0f, w = 0.0f;
	int j = -1;
	for (int k = 0; k < np && cum <= target; k++) {
		float wk = k < PORTAL_W_KEPT ? kept[k] : portal_env_weight(&sc->portals[k], x, n);
		if (wk > 0.0f) { /* the last positive one if rounding leaves target >= the sum */
			j = k;
			w = wk;
			cum += wk;
		}
	}
	if (j < 0) /* no portal shows x the sky */
		return env_sample(sc, u1, u2, wi, pdf_w);
	GLOBAL const PortalTri *pt = &sc->portals[j];
	/* x is on its room side (w > 0): the solid angle from the corners. */
	V3 a = v3_norm(v3_sub(pt->p0, x)), b = v3_norm(v3_sub(pt->p1, x)), c = v3_norm(v3_sub(pt->p2, x));
	float omega = sph_tri_solid_angle(a, b, c), own; /* own: the picked triangle's term */
	if (omega >= PORTAL_SA_MIN) {
		*wi = sph_tri_sample(a, b, c, omega, u1, u2);
		own = w / total / omega;
	} else {
		V3 p, n;
		sample_triangle_point(pt->p0, pt->p1, pt->p2, u1, u2, &p, &n);
		V3 d = v3_sub(p, x);
		float d2 = v3_len2(d);
		*wi = v3_scale(d, 1.0f / sqrt(d2));
		float cos_p = fabs(v3_dot(*wi, pt->n));
		if (!(cos_p > 0.0f) || !(d2 > 0.0f))
			return black;
		own = w / total * d2 / (pt->area * cos_p);
	}
	pe = env_pdf_w(sc, *wi);
	*pdf_w = PORTAL_NEE_MIX * (own + env_portal_pdf_w(sc, x, n, *wi, total, j)) + (1.0f - PORTAL_NEE_MIX) * pe;
	return env_radiance(sc, *wi);
}

#endif
