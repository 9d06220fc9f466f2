/* portal_crossing.h — where paths cross portals. Portal triangles are in
 * no BVH (no ray ever hits them); the portal integrator's MIS needs, for
 * every path edge, how many portal triangles it crosses, since each
 * crossing is a way an intermediate subpath could have produced the edge.
 * Scenes have few portal triangles, so a loop over them is enough. */
#ifndef AJAR_PORTAL_GEOMETRY_H
#define AJAR_PORTAL_GEOMETRY_H
#include "base/types.h"

/* Whether the ray o + t d (t in (0, tmax)) crosses triangle (p0, p1, p2),
 * by Moeller-Trumbore; a ray in the triangle's plane does not cross it.
 * *t_hit gets the crossing's t. */
INLINE int portal_tri_crossing(V3 o, V3 d, float tmax, V3 p0, V3 p1, V3 p2, float *t_hit)
{
	V3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
	V3 pv = v3_cross(d, e2);
	float det = v3_dot(e1, pv);
	if (det == 0.0f)
		return 0;
	float inv = 1.0f / det;
	V3 tv = v3_sub(o, p0);
	float u = v3_dot(tv, pv) * inv;
	if (u < 0.0f || u > 1.0f)
		return 0;
	V3 qv = v3_cross(tv, e1);
	float v = v3_dot(d, qv) * inv;
	if (v < 0.0f || u + v > 1.0f)
		return 0;
	float t = v3_dot(e2, qv) * inv;
	*t_hit = t;
	return t > 0.0f && t < tmax;
}

INLINE int portal_tri_crossed(V3 o, V3 d, float tmax, V3 p0, V3 p1, V3 p2)
{
	float t;
	return portal_tri_crossing(o, d, tmax, p0, p1, p2, &t);
}

/* Portal triangles crossed by the segment a -> b, or, if `to_infinity`,
 * by the ray from a in direction b. */
INLINE int portal_crossings(const SceneView *sc, V3 a, V3 b, int to_infinity)
{
	int n = 0, np = sc->params->num_portals;
	V3 d = to_infinity ? b : v3_sub(b, a);
	float tmax = to_infinity ? AJAR_INF : 1.0f;
	for (int i = 0; i < np; i++) {
		GLOBAL const PortalTri *t = &sc->portals[i];
		n += portal_tri_crossed(a, d, tmax, t->p0, t->p1, t->p2);
	}
	return n;
}
#endif
