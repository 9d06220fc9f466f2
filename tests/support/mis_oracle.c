/* mis_oracle.c — see mis_oracle.h. Written from design.md's definitions,
 * independently of the kernels' bookkeeping (it uses only their BSDF,
 * light and camera densities, which have chi-square tests of their own). */
#include "mis_oracle.h"

#include <math.h>


static int at_infinity(const PathVertex *v) { return v->type == VERTEX_ENV || v->type == VERTEX_SUN; }
static int punctual(const PathVertex *v) { return v->type == VERTEX_PUNCTUAL || v->type == VERTEX_SUN; }

static int crosses(const double *o, const double *d, double tmax, V3 a, V3 b, V3 c, double *th);

/* pf_1 of a light at infinity (a directional light, or the environment in
 * its direction) whose parallel lines travel along unit w toward x1: lines
 * uniform on the disk of radius R, or through a uniform point of a portal
 * triangle chosen by its area projected toward w, A_j |n_j.w| / S, which
 * over the cosine is 1 / S for each triangle the line crosses. */
static double line_pf1(const SceneView *sc, const double *w, double R, const PathVertex *x1)
{
	double c1 = fabs(x1->ng.x * w[0] + x1->ng.y * w[1] + x1->ng.z * w[2]);
	/* Scene points lie within the disk. */
	double disk = 1 / (M_PI * R * R), S = 0;
	for (int i = 0; i < sc->params->num_portals; i++) {
		GLOBAL const PortalTri *t = &sc->portals[i];
		S += t->area * fabs(t->n.x * w[0] + t->n.y * w[1] + t->n.z * w[2]);
	}
	if (!(S > 0))
		return c1 * disk;
	double o[3] = {x1->p.x - 1e3 * w[0], x1->p.y - 1e3 * w[1], x1->p.z - 1e3 * w[2]}, th;
	int n = 0;
	for (int i = 0; i < sc->params->num_portals; i++) {
		GLOBAL const PortalTri *t = &sc->portals[i];
		double c = fabs(t->n.x * w[0] + t->n.y * w[1] + t->n.z * w[2]);
		if (c * t->area > 0 && crosses(o, w, 2e3, t->p0, t->p1, t->p2, &th))
			n++;
	}
	return (SUN_DISK_SHARE * disk + (1 - SUN_DISK_SHARE) * n / S) * c1;
}

/* pf_1 of a punctual light x0 toward x1, from the light's definition:
 * directions uniform on the sphere or in the spot's outer cone; lines of a
 * directional light as line_pf1's. */
static double punctual_pf1(const SceneView *sc, const PathVertex *x0, const PathVertex *x1)
{
	GLOBAL const PunctualLight *l = &sc->punctual[x0->tri];
	double dir[3] = {l->dir.x, l->dir.y, l->dir.z};
	if (x0->type == VERTEX_SUN)
		return line_pf1(sc, dir, l->disk_radius, x1);
	double d[3] = {x1->p.x - x0->p.x, x1->p.y - x0->p.y, x1->p.z - x0->p.z};
	double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
	double pw = 1 / (4 * M_PI);
	if (l->type == LIGHT_SPOT) {
		double c = (d[0] * dir[0] + d[1] * dir[1] + d[2] * dir[2]) / len;
		pw = c >= l->cos_outer ? 1 / (2 * M_PI * (1 - (double)l->cos_outer)) : 0;
	}
	return oracle_convert(x0, x1, (float)pw);
}

float oracle_convert(const PathVertex *from, const PathVertex *to, float pdf_w)
{
	if (at_infinity(to))
		return pdf_w;
	double dx = to->p.x - from->p.x, dy = to->p.y - from->p.y, dz = to->p.z - from->p.z;
	double d2 = dx * dx + dy * dy + dz * dz, d = sqrt(d2);
	double c = fabs(to->ng.x * dx + to->ng.y * dy + to->ng.z * dz) / d;
	return (float)(pdf_w * c / d2);
}

V3 oracle_dir(const PathVertex *from, const PathVertex *to)
{
	return at_infinity(to) ? to->p : v3_norm(v3_sub(to->p, from->p));
}

/* Solid-angle density that v's BSDF samples toward `to` given `from`. */
float oracle_bsdf(const SceneView *sc, const PathVertex *v, const PathVertex *from, const PathVertex *to)
{
	Bsdf bs;
	float pdf, rev;
	bsdf_setup(&bs, &sc->materials[v->material], v->base, v->ns, v->ng);
	bsdf_eval(&bs, oracle_dir(v, from), oracle_dir(v, to), BSDF_RADIANCE, &pdf, &rev);
	return pdf;
}

/* x[0] light (emitter point or environment), x[k-1] camera; delta[i] says
 * x[i] scattered through a delta lobe on this path. */
void oracle(const SceneView *sc, const PathVertex *x, const int *delta, int k, MisVertex *mv)
{
	GLOBAL const Params *prm = sc->params;
	float ps = prm->env_pdf_select;
	for (int i = 0; i < k; i++) {
		mv[i].delta = delta[i] || (i == 0 && punctual(&x[0]));
		mv[i].infinite = at_infinity(&x[i]);
		/* pf */
		if (i == k - 1)
			mv[i].pf = 0;
		else if (i == 0 && punctual(&x[0]))
			mv[i].pf = (1 - ps) * sc->punctual[x[0].tri].pdf_select;
		else if (i == 1 && punctual(&x[0]))
			mv[i].pf = (float)punctual_pf1(sc, &x[0], &x[1]);
		else if (i == 0)
			/* A sky image's light subpaths through the portals take their
			 * directions from its table of the light through them
			 * (test_lights checks that table against its density). */
			mv[i].pf = x[0].type == VERTEX_ENV ? ps * env_light_pdf_w(sc, x[0].p)
							   : (1 - ps) * emitter_pdf_a(sc, x[0].tri, x[0].p);
		else if (i == 1 && x[0].type == VERTEX_ENV)
			/* A sky image's lines come through the portals, a constant sky's
			 * cross the disk alone. */
			mv[i].pf = prm->env_type == ENV_IMAGE && prm->num_portals > 0
					   ? (float)line_pf1(sc, (const double[3]){-x[0].p.x, -x[0].p.y, -x[0].p.z},
							     prm->scene_radius, &x[1])
					   : fabs(v3_dot(x[1].ng, x[0].p)) / (AJAR_PI * prm->scene_radius * prm->scene_radius);
		else if (i == 1) {
			V3 d = v3_norm(v3_sub(x[1].p, x[0].p));
			float c = v3_dot(v3_norm(tri_normal(&sc->tris[x[0].tri])), d);
			mv[i].pf = c > 0 ? oracle_convert(&x[0], &x[1], c / AJAR_PI) : 0;
		} else
			mv[i].pf = delta[i - 1] ? 0 : oracle_convert(&x[i - 1], &x[i], oracle_bsdf(sc, &x[i - 1], &x[i - 2], &x[i]));
		/* pn: x_0 as a next-event sample from x_1 */
		if (i == 0)
			mv[0].pn = k < 3 || punctual(&x[0]) ? mv[0].pf
					 : x[0].type == VERTEX_ENV ? ps * env_nee_pdf_w(sc, x[1].p, vertex_nee_normal(&x[1], &x[2]), x[0].p)
								    : (1 - ps) * emitter_pdf_a(sc, x[0].tri, x[0].p);
		/* pr */
		if (i == k - 1)
			mv[i].pr = 1;
		else if (i == k - 2) {
			GLOBAL const Camera *cam = &prm->camera;
			V3 d = oracle_dir(&x[k - 1], &x[i]);
			mv[i].pr = oracle_convert(&x[k - 1], &x[i], camera_pdf_w(cam, v3_dot(d, cam->forward)));
		} else
			mv[i].pr = delta[i + 1] ? 0 : oracle_convert(&x[i + 1], &x[i], oracle_bsdf(sc, &x[i + 1], &x[i + 2], &x[i]));
	}
}

/* Whether an edge that the densities of vertex i depend on is shorter
 * than 1% of the scene radius: there the ray offset (a few hundred ulps),
 * seen at a grazing angle, is a sizeable fraction of the edge. */
int near_contact(const PathVertex *x, int k, int i, float radius)
{
	for (int j = i - 2; j < i + 2; j++) {
		if (j < 0 || j + 1 >= k || at_infinity(&x[j]) || at_infinity(&x[j + 1]))
			continue;
		if (v3_len(v3_sub(x[j + 1].p, x[j].p)) < 1e-2f * radius)
			return 1;
	}
	return 0;
}

int strategy_valid(const MisVertex *v, int k, int s)
{
	/* x_0's delta flag: a punctual light, which no ray hits and the camera
	 * does not see; next-event estimation (s = 1) reaches it. */
	if (s == 0)
		return !v[0].delta;
	if ((s >= 2 && v[s - 1].delta) || v[s].delta)
		return 0;
	return !((v[s - 1].infinite || (s == 1 && v[0].delta)) && s == k - 1);
}

/* Relative difference of two densities. The walk converts the density of
 * the direction it sampled; the oracle that of the direction between the
 * vertices, which differs by the ray origin's offset: at grazing angles or
 * for vertices a few ulps-offsets apart (corners) that reaches percents.
 * A wrong conversion, vertex or BSDF mode is off on most paths, so the
 * test allows 1% of records beyond 1% and none beyond 10%. */
double rel_diff(float a, float b)
{
	if (a == b)
		return 0;
	return fabs(a - b) / fmax(fabs(a), fabs(b));
}


/* Moeller-Trumbore in double precision, written again on purpose; *th
 * gets the crossing's parameter. */
static int crosses(const double *o, const double *d, double tmax, V3 a, V3 b, V3 c, double *th)
{
	double e1[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, e2[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
	double pv[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
	double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
	if (det == 0)
		return 0;
	double tv[3] = {o[0] - a.x, o[1] - a.y, o[2] - a.z};
	double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) / det;
	if (u < 0 || u > 1)
		return 0;
	double qv[3] = {tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2], tv[0] * e1[1] - tv[1] * e1[0]};
	double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
	if (v < 0 || u + v > 1)
		return 0;
	*th = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
	return *th > 0 && *th < tmax;
}

/* The emitter triangle that point p lies on, found by geometry (not from
 * the vertex's own bookkeeping), or -1. */
static int emitter_at(const SceneView *sc, V3 p)
{
	for (int e = 0; e < sc->params->num_emitters; e++) {
		GLOBAL const Tri *t = &sc->tris[sc->emitters[e].tri];
		V3 n = tri_normal(t);
		double n2 = v3_len2(n);
		if (fabs(v3_dot(n, v3_sub(p, t->p0))) > 1e-4 * sqrt(n2))
			continue; /* off the plane */
		V3 c0 = v3_cross(v3_sub(t->p1, t->p0), v3_sub(p, t->p0)), c1 = v3_cross(v3_sub(t->p2, t->p1), v3_sub(p, t->p1)),
		   c2 = v3_cross(v3_sub(t->p0, t->p2), v3_sub(p, t->p2));
		double tol = -1e-6 * n2;
		if (v3_dot(c0, n) >= tol && v3_dot(c1, n) >= tol && v3_dot(c2, n) >= tol)
			return sc->emitters[e].tri;
	}
	return -1;
}

/* Density per projected solid angle of the portal direction toward a
 * (x_m) from point w of portal triangle pt (design of kernels/integrator/portal.h):
 * half a side (+n with probability side_plus) and a cosine direction on
 * it; half a light sample from w that reached a, environment directions
 * folded onto the portal's sky side. */
static double direction_psa(const SceneView *sc, GLOBAL const PortalTri *pt, const PathVertex *a, const double *w)
{
	double to[3], guided = 0, n[3] = {pt->n.x, pt->n.y, pt->n.z};
	/* The guided choice leaves the punctual lights' share out. */
	double ps = sc->params->env_pdf_select, ce = 1;
	if (sc->params->num_lights > 0) {
		ce = sc->emitter_cdf[sc->params->num_emitters];
		ps = ps + (1 - ps) * ce > 0 ? ps / (ps + (1 - ps) * ce) : 0;
	}
	if (a->type == VERTEX_SUN) { /* the guided half never aims at a punctual light */
		to[0] = a->p.x, to[1] = a->p.y, to[2] = a->p.z;
	} else if (a->type == VERTEX_ENV) {
		to[0] = a->p.x, to[1] = a->p.y, to[2] = a->p.z;
		double pe = env_pdf_w(sc, a->p);
		if (pt->env_side != 0) {
			double dn = to[0] * n[0] + to[1] * n[1] + to[2] * n[2];
			V3 mirror = v3((float)(to[0] - 2 * dn * n[0]), (float)(to[1] - 2 * dn * n[1]), (float)(to[2] - 2 * dn * n[2]));
			pe = dn * pt->env_side > 0 ? pe + env_pdf_w(sc, mirror) : 0;
		}
		guided = ps * pe;
	} else {
		double d[3] = {a->p.x - w[0], a->p.y - w[1], a->p.z - w[2]};
		double dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
		for (int c = 0; c < 3; c++)
			to[c] = d[c] / dist;
		int tri = a->type == VERTEX_PUNCTUAL ? -1 : emitter_at(sc, a->p);
		if (tri >= 0) {
			V3 fn = v3_norm(tri_normal(&sc->tris[tri]));
			double cos_l = -(fn.x * to[0] + fn.y * to[1] + fn.z * to[2]);
			if (cos_l > 0 && ce > 0)
				guided = (1 - ps) * emitter_pdf_a(sc, tri, a->p) / ce * dist * dist / cos_l;
		}
	}
	double cn = to[0] * n[0] + to[1] * n[1] + to[2] * n[2], c = fabs(cn);
	double side = cn > 0 ? pt->side_plus : 1 - pt->side_plus;
	return 0.5 * side / M_PI + (c > 0 ? 0.5 * guided / c : 0);
}

int oracle_pair_logs(const SceneView *sc, const PathVertex *a, const PathVertex *b, double *lp, double (*pts)[3],
		     int max)
{
	double o[3], d[3], tmax = 1;
	const PathVertex *p = at_infinity(a) ? b : a;
	if (at_infinity(a) || at_infinity(b)) {
		const PathVertex *env = at_infinity(a) ? a : b;
		o[0] = p->p.x, o[1] = p->p.y, o[2] = p->p.z;
		d[0] = env->p.x, d[1] = env->p.y, d[2] = env->p.z;
		tmax = 1e30;
	} else {
		o[0] = a->p.x, o[1] = a->p.y, o[2] = a->p.z;
		d[0] = b->p.x - a->p.x, d[1] = b->p.y - a->p.y, d[2] = b->p.z - a->p.z;
	}
	double g;
	if (at_infinity(a)) {
		g = fabs(v3_dot(b->ng, a->p));
	} else {
		double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
		g = fabs(a->ng.x * d[0] + a->ng.y * d[1] + a->ng.z * d[2]) *
		    fabs(b->ng.x * d[0] + b->ng.y * d[1] + b->ng.z * d[2]) / (d2 * d2);
	}
	int n = 0;
	for (int i = 0; i < sc->params->num_portals; i++) {
		GLOBAL const PortalTri *t = &sc->portals[i];
		double th;
		if (!crosses(o, d, tmax, t->p0, t->p1, t->p2, &th))
			continue;
		double w[3] = {o[0] + th * d[0], o[1] + th * d[1], o[2] + th * d[2]};
		if (n < max) {
			lp[n] = log(direction_psa(sc, t, a, w) * g * t->pdf_select / t->area);
			if (pts)
				for (int c = 0; c < 3; c++)
					pts[n][c] = w[c];
		}
		n++;
	}
	return n;
}
