/* pane_planes.c — the planes of a scene's panes, for next-event estimation
 * of the sky they mirror (kernels/integrator/pane_mirror.h).
 *
 * The triangles of one window's panes share a plane; rooms have few such
 * planes. Triangles are grouped by plane (normals within PANE_PLANE_COS,
 * offsets within PANE_PLANE_TOL of the scene's radius: the kernels' own
 * test), the planes kept by area, and each faces the sky side of the
 * portal nearest its panes: the side whose points may see the sky in it. */
#include "prepare/pane_planes.h"

#include <math.h>
#include <string.h>

#define PLANES_SEEN 64 /* planes told apart; panes on more planes than that: the first ones */

typedef struct {
	double n[3], d, area, c[3]; /* unit normal, offset, area, area-weighted centroid sum */
} Plane;

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The plane of triangle t, its normal and offset, and twice its area. */
static double tri_plane(const Tri *t, double n[3], double *d)
{
	double e1[3] = {t->p1.x - t->p0.x, t->p1.y - t->p0.y, t->p1.z - t->p0.z};
	double e2[3] = {t->p2.x - t->p0.x, t->p2.y - t->p0.y, t->p2.z - t->p0.z};
	n[0] = e1[1] * e2[2] - e1[2] * e2[1];
	n[1] = e1[2] * e2[0] - e1[0] * e2[2];
	n[2] = e1[0] * e2[1] - e1[1] * e2[0];
	double a2 = sqrt(dot3(n, n));
	if (!(a2 > 0.0))
		return 0.0;
	for (int k = 0; k < 3; k++)
		n[k] /= a2;
	double p0[3] = {t->p0.x, t->p0.y, t->p0.z};
	*d = dot3(n, p0);
	return a2;
}

void pane_planes_build(const Tri *tris, uint32_t n, const PortalTri *portals, uint32_t n_portals, float radius,
		       Params *p)
{
	Plane pl[PLANES_SEEN];
	int np = 0;
	double tol = PANE_PLANE_TOL * radius;
	p->num_pane_planes = 0;
	for (uint32_t i = 0; i < n; i++) {
		if (!(tris[i].flags & TRI_PANE))
			continue;
		double tn[3], td, a2 = tri_plane(&tris[i], tn, &td);
		if (!(a2 > 0.0))
			continue;
		int j = 0;
		for (; j < np; j++) {
			double c = dot3(tn, pl[j].n);
			if (fabs(c) > PANE_PLANE_COS && fabs((c < 0.0 ? -td : td) - pl[j].d) < tol)
				break;
		}
		if (j == np) {
			if (np == PLANES_SEEN)
				continue;
			memcpy(pl[j].n, tn, sizeof tn);
			pl[j].d = td;
			pl[j].area = 0.0;
			pl[j].c[0] = pl[j].c[1] = pl[j].c[2] = 0.0;
			np++;
		}
		pl[j].area += 0.5 * a2;
		pl[j].c[0] += 0.5 * a2 * (tris[i].p0.x + tris[i].p1.x + tris[i].p2.x) / 3.0;
		pl[j].c[1] += 0.5 * a2 * (tris[i].p0.y + tris[i].p1.y + tris[i].p2.y) / 3.0;
		pl[j].c[2] += 0.5 * a2 * (tris[i].p0.z + tris[i].p1.z + tris[i].p2.z) / 3.0;
	}
	/* The largest first; equal areas keep the triangles' order. */
	for (int a = 1; a < np; a++)
		for (int b = a; b > 0 && pl[b].area > pl[b - 1].area; b--) {
			Plane t = pl[b];
			pl[b] = pl[b - 1];
			pl[b - 1] = t;
		}
	for (int j = 0; j < np && p->num_pane_planes < PANE_PLANES_MAX; j++) {
		double c[3] = {pl[j].c[0] / pl[j].area, pl[j].c[1] / pl[j].area, pl[j].c[2] / pl[j].area};
		double best = INFINITY, sky = 0.0;
		for (uint32_t k = 0; k < n_portals; k++) {
			const PortalTri *t = &portals[k];
			if (t->env_side == 0)
				continue;
			double q[3] = {(t->p0.x + t->p1.x + t->p2.x) / 3.0 - c[0], (t->p0.y + t->p1.y + t->p2.y) / 3.0 - c[1],
				       (t->p0.z + t->p1.z + t->p2.z) / 3.0 - c[2]};
			double pn[3] = {t->n.x, t->n.y, t->n.z};
			if (dot3(q, q) < best) {
				best = dot3(q, q);
				sky = t->env_side * dot3(pn, pl[j].n);
			}
		}
		if (sky == 0.0)
			continue;
		double s = sky > 0.0 ? 1.0 : -1.0;
		int m = p->num_pane_planes++;
		p->pane_n[m] = v3((float)(s * pl[j].n[0]), (float)(s * pl[j].n[1]), (float)(s * pl[j].n[2]));
		p->pane_d[m] = (float)(s * pl[j].d);
	}
}
