/* pane_mirror.h — next-event estimation of the sky that a pane mirrors.
 *
 * A point on the sky side of a pane (the wall strip between a pane and
 * its opening, a terrace before a glazed door) sees the sky twice: straight
 * and mirrored in the pane. Only BSDF sampling found the mirrored sky: a
 * direction onto the pane, its reflection picked, then the sky. Mirrored
 * in the pane's plane the point x becomes x', and the mirrored sky is the
 * sky seen from x' through the portals: the ordinary next-event sample
 * from x', its direction w' crossing the plane at h, gives from x the
 * direction to h, the same solid angle and density, and the path x -> h
 * -> sky along w' with the pane's Fresnel reflectance F at h.
 *
 * That sample replaces the eye walk's own for these paths: a path whose
 * eye walk went from a surface vertex x, scattered by a non-delta lobe, on
 * the sky side of a listed plane, to a pane of that plane that reflects as
 * a clean mirror (pane_mirror_plane) and from there, passing panes, to the
 * sky, counts only by this sample (pane_mirror_family), as the walk's hit
 * of the sky would have: with its MIS weight (bdpt.h) or 1 (pt). The next-
 * event sample's density covers every direction (its defensive share), so
 * nothing is lost. Emitters seen in a pane stay with the walk. */
#ifndef AJAR_PANE_MIRROR_H
#define AJAR_PANE_MIRROR_H
#include "geom/bvh.h"
#include "geom/surface.h"
#include "geom/visibility.h"
#include "light/lights.h"
#include "material/bsdf.h"

/* The listed plane in which the surface s (BSDF bs) reflects as a clean
 * mirror: a pane of clear thin glass without layers whose shading normal
 * is the plane's; -1 if none. */
INLINE int pane_mirror_plane(const SceneView *sc, int tri, V3 p, V3 ng, const Bsdf *bs)
{
	GLOBAL const Params *prm = sc->params;
	if (!(sc->tris[tri].flags & TRI_PANE) || !bsdf_has_null(bs) || bsdf_w_glass(bs) < 1.0f ||
	    BSDF_IS_LAYERED(bs))
		return -1;
	float tol = PANE_PLANE_TOL * prm->scene_radius;
	for (int i = 0; i < prm->num_pane_planes; i++) {
		V3 n = prm->pane_n[i];
		if (fabs(v3_dot(ng, n)) > PANE_PLANE_COS && fabs(v3_dot(bs->n, n)) > 1.0f - 1e-6f &&
		    fabs(v3_dot(n, p) - prm->pane_d[i]) < tol)
			return i;
	}
	return -1;
}

/* Whether x lies on the sky side of listed plane i. */
INLINE int pane_sky_side(const SceneView *sc, int i, V3 x)
{
	GLOBAL const Params *prm = sc->params;
	return v3_dot(prm->pane_n[i], x) - prm->pane_d[i] > PANE_PLANE_TOL * prm->scene_radius;
}

/* The mirrored sky's sample from surface point x (geometric normal ng,
 * next-event normal n_nee) in listed plane i: the direction *wx from x to
 * the pane point, whose surface and BSDF (from -*wx) land in *h and *hb,
 * the sky's direction *wsky beyond it, and the solid-angle density *pdf_w;
 * returns what arrives at x along -*wx (F, the panes passed on both legs,
 * the sky's radiance) over *pdf_w, or 0. */
INLINE V3 pane_mirror_sample(const SceneView *sc, int i, V3 x, V3 ng, V3 n_nee, float u0, float u1, float u2,
			     V3 *wx, V3 *wsky, float *pdf_w, Surface *h, Bsdf *hb)
{
	GLOBAL const Params *prm = sc->params;
	V3 zero = v3(0.0f, 0.0f, 0.0f), n = prm->pane_n[i];
	float hx = v3_dot(n, x) - prm->pane_d[i];
	V3 xm = v3_madd(x, n, -2.0f * hx), nm = v3_madd(n_nee, n, -2.0f * v3_dot(n, n_nee));
	LightSample ls;
	if (!light_sample(sc, xm, nm, u0, u1, u2, &ls) || !ls.is_env || !(ls.pdf_w > 0.0f) || v3_is_zero(ls.Le))
		return zero;
	float c = v3_dot(n, ls.wi);
	if (!(c > 0.0f)) /* x' sees that sky without crossing the plane */
		return zero;
	V3 w = v3_madd(ls.wi, n, -2.0f * c);
	float dist = hx / c, left = dist * 1.001f + PANE_PLANE_TOL * prm->scene_radius;
	V3 o = ray_offset(x, ng, w), T = v3(1.0f, 1.0f, 1.0f);
	Hit hit;
	int found = 0;
	for (int k = 0; k < PANE_HITS_MAX && !found; k++) {
		if (!bvh_intersect(sc, o, w, left, &hit) || !(sc->tris[hit.tri].flags & TRI_PANE))
			return zero;
		surface_from_hit(sc, &hit, h);
		surface_bsdf(sc, h, surface_base_color(sc, h), hb);
		bsdf_cache_wo(hb, v3_neg(w));
		found = pane_mirror_plane(sc, h->tri, h->p, h->ng, hb) == i;
		if (!found) { /* another pane on the way: passed by its transmittance */
			T = v3_mul(T, bsdf_null_weight(hb, w));
			V3 q = ray_offset(h->p, h->ng, w);
			left -= v3_len(v3_sub(q, o));
			o = q;
		}
	}
	if (!found || v3_is_zero(T))
		return zero;
	T = v3_scale(T, bsdf_w_glass(hb) * bsdf_thin_fresnel(hb, w));
	T = v3_mul(T, ray_transmittance(sc, ray_offset(h->p, h->ng, ls.wi), ls.wi, AJAR_INF));
	if (v3_is_zero(T))
		return zero;
	*wx = w;
	*wsky = ls.wi;
	*pdf_w = ls.pdf_w;
	return v3_scale(v3_mul(T, ls.Le), 1.0f / ls.pdf_w);
}
#endif
