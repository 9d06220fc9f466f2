/* vertex_density.h — what light vertices emit, and the densities with which
 * each way of sampling produces a vertex (design.md): a light subpath's
 * origin (pf_0) and first vertex (pf_1), and BSDF sampling from a vertex,
 * converted to area measure at the receiving vertex. Shared by the MIS
 * bookkeeping of bdpt and of the portal integrator. */
#ifndef AJAR_DENSITIES_H
#define AJAR_DENSITIES_H
#include "mis/mis.h"
#include "integrator/vertex.h"

/* Emitted radiance and light-origin densities of a light vertex `l`
 * (VERTEX_LIGHT on an emitter's front face, or VERTEX_ENV) toward w. */
INLINE V3 bdpt_emitted(const SceneView *sc, const PathVertex *l, V3 w)
{
	if (vertex_delta_light(l)) /* never seen: no strategy connects to its position */
		return v3(0.0f, 0.0f, 0.0f);
	if (l->type == VERTEX_ENV)
		return env_radiance(sc, l->p);
	return emitter_radiance(sc, l->tri, l->p, w);
}

/* Density of the light vertex as a light subpath's origin (pf_0). */
INLINE float bdpt_origin_pdf(const SceneView *sc, const PathVertex *l)
{
	float ps = sc->params->env_pdf_select;
	if (l->type == VERTEX_ENV)
		return ps * env_light_pdf_w(sc, l->p);
	if (vertex_delta_light(l)) /* the probability of the choice; its delta cancels */
		return (1.0f - ps) * sc->punctual[l->tri].pdf_select;
	return (1.0f - ps) * emitter_pdf_a(sc, l->tri, l->p);
}

/* Density of the light vertex as a next-event sample from vertex x, seen
 * from `from` (pn_0, the s = 1 strategy; lights.h, light_sample). */
INLINE float bdpt_nee_pdf(const SceneView *sc, const PathVertex *l, const PathVertex *x, const PathVertex *from)
{
	float ps = sc->params->env_pdf_select;
	if (l->type == VERTEX_ENV)
		return ps * env_nee_pdf_w(sc, x->p, vertex_nee_normal(x, from), l->p);
	if (vertex_delta_light(l)) /* as the light subpath's origin: pn_0 = pf_0 */
		return (1.0f - ps) * sc->punctual[l->tri].pdf_select;
	return (1.0f - ps) * emitter_pdf_a(sc, l->tri, l->p);
}

/* x_0's two densities in a path's MIS records: as the light subpath's
 * origin (pf) and as a next-event sample from x_1 (pn), seen from x_2
 * (read only when k >= 3). */
INLINE void bdpt_light_records(const SceneView *sc, MisVertex *mv, const PathVertex *x0, const PathVertex *x1,
			       const PathVertex *x2, int k)
{
	mv[0].pf = bdpt_origin_pdf(sc, x0);
	mv[0].pn = k >= 3 ? bdpt_nee_pdf(sc, x0, x1, x2) : mv[0].pf;
}

/* Density with which the light vertex's emission sampling produces `to`
 * (pf_1): cosine-weighted directions from emitters; for a directional
 * light and a sky image seen through portals, parallel lines on a disk of
 * radius R or through the portals (lights.h, line_pdf_perp: per perpendicular
 * area), for a constant sky (or none) on the disk alone; a point or spot
 * light's directions. */
INLINE float bdpt_emission_pdf(const SceneView *sc, const PathVertex *l, const PathVertex *to)
{
	if (l->type == VERTEX_SUN) { /* parallel lines, per perpendicular area (lights.h) */
		GLOBAL const PunctualLight *pl = &sc->punctual[l->tri];
		return line_pdf_perp(sc, pl->dir, pl->disk_radius, to->p) * fabs(v3_dot(to->ng, l->p));
	}
	if (l->type == VERTEX_PUNCTUAL) {
		V3 d = v3_sub(to->p, l->p);
		return vertex_density_a(l, to, punctual_dir_pdf(&sc->punctual[l->tri], v3_norm(d)));
	}
	if (l->type == VERTEX_ENV) {
		if (env_lines_through_portals(sc)) /* a sky image: the same lines along -l->p */
			return line_pdf_perp(sc, v3_neg(l->p), sc->params->scene_radius, to->p) * fabs(v3_dot(to->ng, l->p));
		float r = sc->params->scene_radius;
		return fabs(v3_dot(to->ng, l->p)) / (AJAR_PI * r * r);
	}
	V3 d = v3_sub(to->p, l->p);
	float cos_l = v3_dot(l->ng, d) / v3_len(d);
	if (!(cos_l > 0.0f))
		return 0.0f;
	return vertex_density_a(l, to, cos_l * AJAR_INV_PI);
}

/* Solid-angle density of `v`'s BSDF sampling `to`, given the vertex `from`
 * on its other side (wo), for the mode of the subpath v belongs to. */
INLINE float bdpt_bsdf_pdf_w(const PathVertex *v, const PathVertex *from, const PathVertex *to, int mode)
{
	V3 wo = vertex_infinite(from) ? from->p : v3_norm(v3_sub(from->p, v->p));
	V3 wi = vertex_infinite(to) ? to->p : v3_norm(v3_sub(to->p, v->p));
	return bsdf_pdf_w(&v->bs, wo, wi); /* densities do not depend on the transport mode */
}

/* Densities of `to` sampled from `v` when the path's other neighbour of v
 * is `from` (used on both sides of a connection). Camera and light origins
 * are handled by the callers. */
INLINE float bdpt_pdf_a(const SceneView *sc, const PathVertex *v, const PathVertex *from, const PathVertex *to,
			int mode)
{
	return vertex_density_a(v, to, bdpt_bsdf_pdf_w(v, from, to, mode));
}

#endif
