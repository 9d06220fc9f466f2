/* portal_groups.c — portal triangles grouped into openings, by union-find:
 * the sky tables (sky_tables.c) build a planar portal per group that shows
 * the sky, the slide (portal_slide.c) moves each group as one. */
#include "prepare/portal_groups.h"

#include <math.h>

static uint32_t find(uint32_t *root, uint32_t a)
{
	while (root[a] != a)
		a = root[a] = root[root[a]];
	return a;
}

/* Whether a and b lie in one plane (normals na, nb) and share a corner
 * (eps: a length tolerance). */
static int joined(const PortalTri *a, V3 na, const PortalTri *b, V3 nb, float eps)
{
	if (!(v3_dot(na, nb) > 1.0f - 1e-4f) || !(fabsf(v3_dot(na, v3_sub(b->p0, a->p0))) < eps))
		return 0;
	const V3 pa[3] = {a->p0, a->p1, a->p2}, pb[3] = {b->p0, b->p1, b->p2};
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			if (v3_len(v3_sub(pa[i], pb[j])) < eps)
				return 1;
	return 0;
}

void portal_groups(const PortalTri *p, uint32_t n, int sky, uint32_t *root)
{
	if (n == 0)
		return;
	V3 lo = p[0].p0, hi = p[0].p0;
	for (uint32_t k = 0; k < n; k++) {
		root[k] = k;
		lo = v3_min(lo, v3_min(p[k].p0, v3_min(p[k].p1, p[k].p2)));
		hi = v3_max(hi, v3_max(p[k].p0, v3_max(p[k].p1, p[k].p2)));
	}
	float eps = 10.0f * (1e-5f * fmaxf(v3_len(v3_sub(hi, lo)), 1e-6f)); /* as the sky tables always took it */
	for (uint32_t a = 0; a < n; a++)
		for (uint32_t b = a + 1; b < n; b++) {
			if (sky && (p[a].env_side == 0 || p[b].env_side == 0))
				continue;
			/* Facing the sky alike, or either way. */
			V3 na = v3_scale(p[a].n, sky ? (float)p[a].env_side : 1.0f);
			V3 nb = v3_scale(p[b].n, sky ? (float)p[b].env_side : (v3_dot(p[a].n, p[b].n) < 0.0f ? -1.0f : 1.0f));
			if (joined(&p[a], na, &p[b], nb, eps)) {
				uint32_t ra = find(root, a), rb = find(root, b);
				if (ra != rb)
					root[ra > rb ? ra : rb] = ra > rb ? rb : ra;
			}
		}
	for (uint32_t k = 0; k < n; k++)
		root[k] = find(root, k);
}

float portal_group_rect(const PortalTri *p, const uint32_t *root, uint32_t n, uint32_t g, V3 nrm, V3 o, V3 *t,
			V3 *b, float ext[4])
{
	float best = INFINITY;
	for (uint32_t e = 0; e < n; e++) {
		if (root[e] != g)
			continue;
		const V3 ce[3] = {p[e].p0, p[e].p1, p[e].p2};
		for (int m = 0; m < 3; m++) {
			V3 d = v3_sub(ce[(m + 1) % 3], ce[m]);
			d = v3_madd(d, nrm, -v3_dot(d, nrm));
			if (!(v3_len2(d) > 0.0f))
				continue;
			V3 tt = v3_norm(d), bb = v3_cross(nrm, tt);
			float r[4] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
			for (uint32_t k = 0; k < n; k++) {
				if (root[k] != g)
					continue;
				const V3 c[3] = {p[k].p0, p[k].p1, p[k].p2};
				for (int x = 0; x < 3; x++) {
					float ca = v3_dot(v3_sub(c[x], o), tt), cb = v3_dot(v3_sub(c[x], o), bb);
					r[0] = fminf(r[0], ca), r[1] = fmaxf(r[1], ca), r[2] = fminf(r[2], cb), r[3] = fmaxf(r[3], cb);
				}
			}
			float area = (r[1] - r[0]) * (r[3] - r[2]);
			if (area < best) {
				best = area;
				*t = tt;
				*b = bb;
				for (int i = 0; i < 4; i++)
					ext[i] = r[i];
			}
		}
	}
	return best > 0.0f && best < INFINITY ? best : 0.0f;
}
