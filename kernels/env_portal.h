/* env_portal.h — next-event estimation of the environment through portals
 * (Cycles and pbrt-v4 sample windows the same way). From a shading point x
 * on the room side of a portal triangle (the side away from the sky, which
 * src/portal_flux.c finds), the triangle is picked by the solid angle it
 * subtends and a direction is sampled uniformly within that solid angle
 * (Arvo 1995). Triangles that look tiny from x (below PORTAL_SA_MIN sr,
 * where float spherical trigonometry loses its accuracy) are sampled by
 * area instead. The environment's own importance sampling is mixed in as a
 * defensive technique, for openings without portals and for a sun:
 *
 *   p_w(wi | x) = MIX sum_{j crossed by wi} (Omega_j / Omega) p_j(wi) + (1 - MIX) p_env(wi)
 *
 * with p_j = 1 / Omega_j (or d^2 / (A_j |cos|) by area), Omega the sum of
 * the Omega_j, and MIX = 0 where no portal shows x the sky. The density is
 * a function of x and wi alone, so every MIS weight that has the
 * environment as a next-event sample uses it (densities.h). */
#ifndef AJAR_KERNEL_ENV_PORTAL_H
#define AJAR_KERNEL_ENV_PORTAL_H
#include "env.h"
#include "portal_geometry.h"

#define PORTAL_NEE_MIX 0.8f
#define PORTAL_SA_MIN 1e-3f

/* Solid angle of the triangle with unit corner directions a, b, c, seen
 * from their origin (Van Oosterom and Strackee 1983). */
INLINE float sph_tri_solid_angle(V3 a, V3 b, V3 c)
{
	float num = fabs(v3_dot(a, v3_cross(b, c)));
	float den = 1.0f + v3_dot(a, b) + v3_dot(b, c) + v3_dot(c, a);
	return 2.0f * atan2(num, den);
}

/* A direction uniform within the spherical triangle (a, b, c) of solid
 * angle `omega` (after Arvo 1995): u1 picks the sub-triangle (a, b, c')
 * of solid angle u1 omega, u2 the point on the arc from b to c'. Written
 * with half-angle tangents and differences of nearby unit vectors rather
 * than Arvo's cosines, which lose the sub-triangle's corner c' in float
 * when it is thin (u1 near 0) or the arcs are short. The arc theta from
 * a to c' follows from the excess of a triangle with sides theta and
 * |ab| and angle alpha between them:
 *   tan(E / 2) = tan(theta / 2) tan(|ab| / 2) sin(alpha) / (1 + tan(theta / 2) tan(|ab| / 2) cos(alpha)). */
INLINE V3 sph_tri_sample(V3 a, V3 b, V3 c, float omega, float u1, float u2)
{
	V3 nab = v3_cross(a, b), nac = v3_cross(a, c);
	float inv = 1.0f / sqrt(v3_len2(nab) * v3_len2(nac));
	float cos_alpha = v3_dot(nab, nac) * inv, sin_alpha = v3_len(v3_cross(nab, nac)) * inv;
	float k = v3_len(nab) / (1.0f + v3_dot(a, b)); /* tan(|ab| / 2) */
	float te = tan(0.5f * u1 * omega);
	float den = k * (sin_alpha - te * cos_alpha);
	V3 cp = c;
	if (den > 0.0f) {
		float tt = te / den, tt2 = tt * tt; /* tan(theta / 2) */
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

/* Solid angle of portal triangle pt seen from x when x lies on its room
 * side (the sky behind it), else 0. */
INLINE float portal_env_solid_angle(GLOBAL const PortalTri *pt, V3 x)
{
	if (pt->env_side == 0 || !((float)pt->env_side * v3_dot(v3_sub(x, pt->p0), pt->n) < 0.0f))
		return 0.0f;
	V3 a = v3_norm(v3_sub(pt->p0, x)), b = v3_norm(v3_sub(pt->p1, x)), c = v3_norm(v3_sub(pt->p2, x));
	return sph_tri_solid_angle(a, b, c);
}

INLINE float env_portal_total(const SceneView *sc, V3 x)
{
	float total = 0.0f;
	for (int j = 0; j < sc->params->num_portals; j++)
		total += portal_env_solid_angle(&sc->portals[j], x);
	return total;
}

/* Triangle pt's term of the portal density toward unit wi, which crosses
 * it at distance t; omega is its solid angle from x, total the sum. */
INLINE float env_portal_term(GLOBAL const PortalTri *pt, float omega, float total, V3 wi, float t)
{
	if (omega >= PORTAL_SA_MIN)
		return 1.0f / total;
	float c = fabs(v3_dot(wi, pt->n));
	return c > 0.0f ? omega / total * t * t / (pt->area * c) : 0.0f;
}

/* The portal part of the density of wi from x: the sum over the portal
 * triangles the ray crosses, leaving out `skip` (-1 for none). */
INLINE float env_portal_pdf_w(const SceneView *sc, V3 x, V3 wi, float total, int skip)
{
	float p = 0.0f;
	for (int j = 0; j < sc->params->num_portals; j++) {
		GLOBAL const PortalTri *pt = &sc->portals[j];
		float omega, t;
		if (j == skip || !((omega = portal_env_solid_angle(pt, x)) > 0.0f) ||
		    !portal_tri_crossing(x, wi, AJAR_INF, pt->p0, pt->p1, pt->p2, &t))
			continue;
		p += env_portal_term(pt, omega, total, wi, t);
	}
	return p;
}

/* Solid-angle density with which env_nee_sample from x returns wi. */
INLINE float env_nee_pdf_w(const SceneView *sc, V3 x, V3 wi)
{
	float total = env_portal_total(sc, x), pe = env_pdf_w(sc, wi);
	if (!(total > 0.0f))
		return pe;
	return PORTAL_NEE_MIX * env_portal_pdf_w(sc, x, wi, total, -1) + (1.0f - PORTAL_NEE_MIX) * pe;
}

/* Samples a sky direction *wi for shading point x (u_mix picks the
 * technique and the portal triangle, u1 and u2 the direction); returns
 * the radiance and *pdf_w, 0 and black when there is nothing to sample. */
INLINE V3 env_nee_sample(const SceneView *sc, V3 x, float u_mix, float u1, float u2, V3 *wi, float *pdf_w)
{
	V3 black = v3(0.0f, 0.0f, 0.0f);
	float total = env_portal_total(sc, x), pe;
	*pdf_w = 0.0f;
	if (!(total > 0.0f))
		return env_sample(sc, u1, u2, wi, pdf_w);
	if (u_mix >= PORTAL_NEE_MIX) {
		V3 Le = env_sample(sc, u1, u2, wi, &pe);
		if (!(pe > 0.0f))
			return black;
		*pdf_w = PORTAL_NEE_MIX * env_portal_pdf_w(sc, x, *wi, total, -1) + (1.0f - PORTAL_NEE_MIX) * pe;
		return Le;
	}
	/* The triangle, by solid angle. */
	float target = u_mix / PORTAL_NEE_MIX * total, acc = 0.0f, omega = 0.0f;
	int j = -1;
	for (int k = 0; k < sc->params->num_portals; k++) {
		float om = portal_env_solid_angle(&sc->portals[k], x);
		if (!(om > 0.0f))
			continue;
		j = k;
		omega = om;
		acc += om;
		if (target < acc)
			break;
	}
	if (j < 0)
		return black;
	GLOBAL const PortalTri *pt = &sc->portals[j];
	float own; /* the picked triangle's term, whatever the crossing test finds */
	if (omega >= PORTAL_SA_MIN) {
		V3 a = v3_norm(v3_sub(pt->p0, x)), b = v3_norm(v3_sub(pt->p1, x)), c = v3_norm(v3_sub(pt->p2, x));
		*wi = sph_tri_sample(a, b, c, omega, u1, u2);
		own = 1.0f / total;
	} else {
		V3 p, n;
		sample_triangle_point(pt->p0, pt->p1, pt->p2, u1, u2, &p, &n);
		V3 d = v3_sub(p, x);
		float d2 = v3_len2(d);
		*wi = v3_scale(d, 1.0f / sqrt(d2));
		float cos_p = fabs(v3_dot(*wi, pt->n));
		if (!(cos_p > 0.0f) || !(d2 > 0.0f))
			return black;
		own = omega / total * d2 / (pt->area * cos_p);
	}
	pe = env_pdf_w(sc, *wi);
	*pdf_w = PORTAL_NEE_MIX * (own + env_portal_pdf_w(sc, x, *wi, total, j)) + (1.0f - PORTAL_NEE_MIX) * pe;
	return env_radiance(sc, *wi);
}

#endif
