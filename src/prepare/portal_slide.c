/* portal_slide.c — portals moved out through the tunnel they lie in.
 *
 * A user marks a window where the room sees it: on the wall's face. In a
 * thick wall or a roof slab the opening is a tunnel, and a portal at its
 * room end frames directions that the tunnel's sides then block, so next-
 * event samples through it are lost: marked at the ceiling, a 1 x 1 m
 * skylight in a 30 cm slab rendered 16 times the error of the same portal
 * at the roof (tests/data/layouts/skylight.gltf, `portal`, equal time), a
 * window in a 25 cm reveal 6 times. A portal only aims samples, so moving
 * it changes no image's expectation. Found portals come here too, after the
 * search's own slide (portal_find_cells.c, slide_out), which stops where
 * its sampled tests first fail: at a window's frame, 10 cm short of the
 * far face on living-room-forest (1.27 times the marked portals' error per
 * sample there, 1.08 after this).
 *
 * Each group of triangles that share corners (one opening) moves
 * along its plane's normal, away from the camera's side, by steps of
 * SLIDE_STEP of its size, while the way back to where it was stays clear
 * inside it (16 points; panes pass) and its rim, points just outside its
 * edges, lies in solid matter along three edges at least (7 of an edge's
 * 9 points meet an opaque surface within SLIDE_SOLID of its size both ways
 * along the normal): still in the tunnel, not yet out in the open. */
#include "prepare/portal_slide.h"
#include "prepare/portal_groups.h"

#include <math.h>
#include <stdlib.h>

#include "geom/visibility.h"

#define SLIDE_STEP 0.01f  /* x the opening's size */
#define SLIDE_STEPS 100   /* at most its size deep */
#define SLIDE_SOLID 0.5f  /* x its size */
#define SLIDE_RIM 0.03f   /* x its size: the rim's points lie this far out */

static int blocked(const SceneView *v, V3 o, V3 d, float tmax)
{
	return v3_is_zero(ray_transmittance(v, o, d, tmax));
}

/* How many steps the rectangle [a0, a1] x [b0, b1] about o in frame (t, b)
 * can move along `out` (a unit normal) and stay in its tunnel. */
static int steps_out(const SceneView *v, V3 o, V3 t, V3 b, V3 out, float a0, float a1, float b0, float b1)
{
	float wa = a1 - a0, wb = b1 - b0, size = fmaxf(wa, wb), step = SLIDE_STEP * size;
	float rim = SLIDE_RIM * size, reach = SLIDE_SOLID * size;
	int good = 0;
	for (int k = 1; k <= SLIDE_STEPS; k++) {
		float off = (float)k * step;
		int clear = 1, solid[4] = {0, 0, 0, 0};
		for (int q = 0; q < 16 && clear; q++) {
			float fa = ((float)(q % 4) + 0.5f) / 4.0f, fb = ((float)(q / 4) + 0.5f) / 4.0f;
			V3 p = v3_add(o, v3_add(v3_scale(t, a0 + (0.1f + 0.8f * fa) * wa), v3_scale(b, b0 + (0.1f + 0.8f * fb) * wb)));
			clear = !blocked(v, p, out, off);
		}
		if (!clear)
			break;
		for (int q = 0; q < 36; q++) {
			float f = ((float)(q / 4) + 0.5f) / 9.0f, pa, pb;
			switch (q % 4) {
			case 0: pa = a0 - rim, pb = b0 + f * wb; break;
			case 1: pa = a1 + rim, pb = b0 + f * wb; break;
			case 2: pa = a0 + f * wa, pb = b0 - rim; break;
			default: pa = a0 + f * wa, pb = b1 + rim; break;
			}
			V3 p = v3_madd(v3_add(o, v3_add(v3_scale(t, pa), v3_scale(b, pb))), out, off);
			solid[q % 4] += blocked(v, p, out, reach) && blocked(v, p, v3_neg(out), reach);
		}
		if ((solid[0] >= 7) + (solid[1] >= 7) + (solid[2] >= 7) + (solid[3] >= 7) < 3)
			break;
		good = k;
	}
	return good;
}

uint32_t portal_slide(const SceneView *v, PortalTri *p, uint32_t n, V3 camera)
{
	uint32_t *parent = malloc(sizeof *parent * (n ? n : 1)), moved = 0;
	if (!parent)
		return 0; /* a sampling aid: left where the user put it */
	portal_groups(p, n, 0, parent);
	for (uint32_t g = 0; g < n; g++) {
		if (parent[g] != g)
			continue;
		/* The group's frame: its first triangle's normal, turned away
		 * from the camera's side, and its smallest rectangle. */
		V3 out = p[g].n;
		if (v3_dot(out, v3_sub(camera, p[g].p0)) > 0.0f)
			out = v3_neg(out);
		V3 o = p[g].p0, t, b;
		float r[4];
		if (!(portal_group_rect(p, parent, n, g, out, o, &t, &b, r) > 0.0f))
			continue;
		float a0 = r[0], a1 = r[1], b0 = r[2], b1 = r[3];
		int k = steps_out(v, o, t, b, out, a0, a1, b0, b1);
		if (k == 0)
			continue;
		/* Half a step back: not in the plane of the far face, whose
		 * points by the opening would lie in the portal's plane. */
		V3 shift = v3_scale(out, ((float)k - 0.5f) * SLIDE_STEP * fmaxf(a1 - a0, b1 - b0));
		for (uint32_t q = 0; q < n; q++)
			if (parent[q] == g) {
				p[q].p0 = v3_add(p[q].p0, shift);
				p[q].p1 = v3_add(p[q].p1, shift);
				p[q].p2 = v3_add(p[q].p2, shift);
				moved++;
			}
	}
	free(parent);
	return moved;
}
