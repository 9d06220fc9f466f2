/* visibility.h — what a shadow ray or a connection carries between two
 * points: 0 where something opaque lies between them, else the product of
 * the transmittances of the panes it crosses (smooth thin-walled glass,
 * TRI_PANE: wg (1 - F) base_color, material/bsdf.h, bsdf_null_weight), and
 * Beer-Lambert absorption where the segment runs inside a solid
 * (MATERIAL_VOLUME). A pane is the note's pass-through vertex with a
 * transmittance: crossing it is a null event, so no density changes and
 * every strategy sees through it (kernels/integrator/README.md, "Glass").
 * Scenes without panes are built with AJAR_NO_PANES: then this is the
 * occlusion test it was, and its transmittance is exactly 1. */
#ifndef AJAR_VISIBILITY_H
#define AJAR_VISIBILITY_H
#include "base/fastmath.h"
#include "geom/bvh.h"
#include "geom/surface.h"

/* The transmittance of the pane at hit h, crossed along d: 0 where the
 * glass is rough there (a textured roughness), which scatters. */
INLINE V3 pane_transmittance(const SceneView *sc, const Hit *h, V3 d)
{
	Surface s;
	Bsdf bs;
	surface_from_hit(sc, h, &s);
	surface_bsdf(sc, &s, surface_base_color(sc, &s), &bs);
	return bsdf_null_weight(&bs, d);
}

/* The transmittance of the ray (o, d) over 0 < t < tmax. */
INLINE V3 ray_transmittance(const SceneView *sc, V3 o, V3 d, float tmax)
{
	V3 zero = v3(0.0f, 0.0f, 0.0f), T = v3(1.0f, 1.0f, 1.0f);
#ifdef AJAR_NO_PANES
	return bvh_occluded(sc, o, d, tmax) ? zero : T;
#else
	PaneHits ph;
	if (bvh_occluded_panes(sc, o, d, tmax, &ph))
		return zero;
	if (ph.n <= PANE_HITS_MAX) {
		for (int i = 0; i < ph.n && !v3_is_zero(T); i++)
			T = v3_mul(T, pane_transmittance(sc, &ph.hit[i], d));
		return T;
	}
	/* More panes than the list holds: nearest first, one query each. No
	 * opaque surface lies on the ray, but an alpha-tested one decided anew
	 * may: then the ray is blocked. */
	V3 p = o;
	float left = tmax;
	Hit h;
	while (left > 0.0f && !v3_is_zero(T) && bvh_intersect(sc, p, d, left, &h)) {
		if (!(sc->tris[h.tri].flags & TRI_PANE))
			return zero;
		T = v3_mul(T, pane_transmittance(sc, &h, d));
		V3 q = v3_add(p, v3_scale(d, h.t));
		p = ray_offset(q, tri_normal(&sc->tris[h.tri]), d);
		left = tmax - v3_len(v3_sub(p, o));
	}
	return T;
#endif
}

/* The transmittance between surface points a and b (geometric normals na,
 * nb, either side): both ends pushed off their surfaces first, the ray
 * stopping short of the far end by a relative margin, so neither end's
 * own triangle counts (segment_clear's rule). */
INLINE V3 segment_transmittance(const SceneView *sc, V3 a, V3 na, V3 b, V3 nb)
{
	V3 d = v3_sub(b, a);
	V3 o = ray_offset(a, na, d), q = ray_offset(b, nb, v3_neg(d));
	V3 od = v3_sub(q, o);
	float len = v3_len(od);
	if (!(len > 0.0f))
		return v3(0.0f, 0.0f, 0.0f);
	return ray_transmittance(sc, o, v3_scale(od, 1.0f / len), len * (1.0f - 1e-4f));
}

/* Whether a segment leaving a surface of `material` (geometric normal ng,
 * front outward) along d runs inside an absorbing solid: the material has
 * a volume that absorbs and d enters its back side. */
INLINE int volume_inside(const SceneView *sc, int material, V3 ng, V3 d)
{
	if (material < 0)
		return 0;
	GLOBAL const Material *m = &sc->materials[material];
	return (m->flags & MATERIAL_VOLUME) && !v3_is_zero(m->sigma) && v3_dot(d, ng) < 0.0f;
}

/* Beer-Lambert over such a segment of length `dist` (1 outside a solid). */
INLINE V3 volume_attenuation(const SceneView *sc, int material, V3 ng, V3 d, float dist)
{
	if (!volume_inside(sc, material, ng, d))
		return v3(1.0f, 1.0f, 1.0f);
	V3 s = sc->materials[material].sigma;
	return v3(fast_exp(-s.x * dist), fast_exp(-s.y * dist), fast_exp(-s.z * dist));
}
#endif
