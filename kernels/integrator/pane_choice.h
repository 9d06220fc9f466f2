/* pane_choice.h — where a radiance walk meets a pane, how likely it goes
 * straight through.
 *
 * bsdf_null_prob gives a clear pane's null event the probability 1 - F:
 * right for a room looking out at the sky, wrong for the strip of wall
 * between a pane and its opening, whose light is the sky mirrored in the
 * pane, F of it, which that choice follows 4% of the time. A walk may take
 * the null event with any probability that is positive wherever it
 * carries light: the choice enters no MIS density (vertex.h, vertex_trace).
 * So where the mirrored way leaves through a portal toward the sky and
 * the straight way does not, an eye walk takes the mirror with the odds
 * F : PANE_ROOM_SHARE (1 - F); elsewhere as the BSDF samples. Under
 * window-room-glazed's constant sky (sky_eff.py, portal, 64 x 64, 128 spp,
 * two seeds) variance per sample 0.280 -> 0.257 (portal) and 0.279 ->
 * 0.244 (pt); the sun-lit glazed rooms, whose light subpaths carry that
 * light, unchanged (0.574 -> 0.576, 3.71 -> 3.79: noise). A room seen
 * mirrored in a pane from the sky side keeps its odds F : 1 - F. */
#ifndef AJAR_PANE_CHOICE_H
#define AJAR_PANE_CHOICE_H
#include "geom/portal_crossing.h"

/* What a way into the room may bring against the sky's way: 0.01-0.1
 * gave the same figures above; rooms lit through their openings are a few
 * percent as bright as the sky seen through them. */
#define PANE_ROOM_SHARE 0.05f

/* Whether the ray (p, d) leaves through a portal toward its sky side. */
INLINE int pane_toward_sky(const SceneView *sc, V3 p, V3 d)
{
	for (int i = 0; i < sc->params->num_portals; i++) {
		GLOBAL const PortalTri *t = &sc->portals[i];
		if ((float)t->env_side * v3_dot(d, t->n) > 0.0f && portal_tri_crossed(p, d, AJAR_INF, t->p0, t->p1, t->p2))
			return 1;
	}
	return 0;
}

/* The probability with which an eye walk arriving along d at a pane point
 * p (normal n) takes the null event to which bsdf_null_prob gives pn. */
INLINE float pane_null_choice(const SceneView *sc, float pn, V3 p, V3 d, V3 n)
{
	if (!(pn > 0.0f) || sc->params->env_type == ENV_NONE || sc->params->num_portals == 0)
		return pn;
	if (pane_toward_sky(sc, p, d) || !pane_toward_sky(sc, p, v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n)))))
		return pn;
	return pn * PANE_ROOM_SHARE / (pn * PANE_ROOM_SHARE + 1.0f - pn);
}
#endif
