/* vertex.h — subpath vertices and the random walk that extends a subpath
 * (eye, light, and later the two halves of an intermediate subpath).
 *
 * Each vertex stores pf and pr in the global sense of design.md: pf is the
 * density of the vertex sampled from the light side, pr from the eye side,
 * both in area measure, except for a vertex at infinity (the environment),
 * whose density is the solid-angle density of its direction. A walk fills
 * one of them (the direction it walks in) and, when it samples the next
 * vertex, the other one of the vertex before it (pbrt's pdfRev). Densities
 * that involve a delta lobe are stored as 0 (see mis.h). */
#ifndef AJAR_VERTEX_H
#define AJAR_VERTEX_H
#include "material/bsdf.h"
#include "geom/bvh.h"
#include "light/lights.h"
#include "sample/rng.h"
#include "sample/roulette.h"
#include "geom/portal_crossing.h"
#include "geom/surface.h"
#include "geom/visibility.h"

/* Panes one walk segment may cross before it counts as lost (a guard
 * against a ray caught between coincident panes). */
#define VERTEX_PANES_MAX 64

#define VERTEX_CAMERA 0
#define VERTEX_LIGHT 1   /* the point where a light subpath starts on an emitter */
#define VERTEX_ENV 2     /* the environment: p holds the unit direction to the sky */
#define VERTEX_SURFACE 3
#define VERTEX_PUNCTUAL 4 /* a point or spot light: p its position, tri its index in sc->punctual */
#define VERTEX_SUN 5      /* a directional light: p the unit direction toward it, tri its index */

/* Maximum vertices of one subpath; bdpt needs max_depth + 1 eye vertices. */
#define SUBPATH_MAX 33

typedef struct {
	V3 p;     /* position, or direction to the sky for VERTEX_ENV */
	V3 ng;    /* unit geometric normal (front face); light: emitter normal */
	V3 ns;    /* unit shading normal */
	V3 wo;    /* unit direction to the previous vertex of this subpath */
	V3 beta;  /* subpath throughput up to and including this vertex's sampling */
	V3 base;  /* textured base colour, for rebuilding the BSDF */
	float pf, pr;
	int type;
	int delta;    /* scattered by a delta lobe */
	int material; /* -1 for camera, env */
	int tri;      /* hit triangle, -1 for camera, env */
	int cross;    /* portal integrator: portal crossings of the edge to the previous vertex of this subpath */
	V3 w0;        /* an intermediate subpath's first vertices: the portal point it started from */
	int w0_tri;   /* and the portal triangle it lies on */
	float tail;   /* bdpt's MIS: this subpath's terms beyond a connection two vertices on (bdpt_mis_tails) */
	Bsdf bs;      /* VERTEX_SURFACE hits: the BSDF, set up once by vertex_trace;
		       * connections and MIS densities read it many times per
		       * vertex (rebuilding it was 17% of door-ajar's portal time) */
} PathVertex;

/* ---- Where subpaths live (kernels/integrator/README.md, "Where subpaths live") ----
 *
 * By default the subpath arrays are private arrays of PathVertex (CPUs:
 * they stay in the core's caches). Built with -DAJAR_SUBPATH_SOA=C, they live
 * in a global scratch buffer for C work-items, structure of arrays by
 * work-item: 32-bit word f of vertex slot i of work-item w at
 * [(i * AJAR_SUBPATH_WORDS + f) * C + w], so neighbouring work-items read
 * neighbouring addresses. Code that walks or reads subpaths holds VRef
 * (VCRef: read only) and goes through these macros; in the private build
 * they are the plain pointer code (the same instructions as before).
 *   VAT(a, i)       vertex i of the subpath at a
 *   VTMP(t)         a private copy's storage (nothing in the private build)
 *   VLOAD(r, t)     a readable `const PathVertex *` of vertex r (a copy in t)
 *   VEDIT(r, t)     a writable copy of r (loaded), VCOMMIT(r, v) writes it back
 *   VNEW(r, t)      a writable vertex to fill whole, VCOMMIT(r, v) stores it
 *   VSTORE(r, v)    stores private vertex *v into r; VCOPY(dst, src) between refs
 *   VGETF/I/3(r, f), VSETF/I/3(r, f, x)  one float, int or V3 field
 *   VNEE(e, y)      a ref to the private next-event vertex y, for the MIS
 *                   weights (the SoA build keeps it in eye slot SUBPATH_MAX)
 * A copy is a snapshot: write through VSET or VCOMMIT, then load again. */
#define VERTEX_WORDS ((int)(sizeof(PathVertex) / 4))
#ifdef AJAR_SUBPATH_SOA
typedef GLOBAL uint *VRef;
typedef GLOBAL const uint *VCRef;
typedef union {
	PathVertex v;
	uint w[sizeof(PathVertex) / 4];
} VertexWords;
/* The host reserves AJAR_SUBPATH_WORDS words a vertex slot (src/device/device_plan.h). */
typedef char vertex_fits_slot[sizeof(PathVertex) <= 4 * (AJAR_SUBPATH_WORDS) ? 1 : -1];
#define VSTRIDE ((size_t)(AJAR_SUBPATH_SOA))
#define VOFF(f) ((size_t)(__builtin_offsetof(PathVertex, f) / 4) * VSTRIDE)
#define VAT(a, i) ((a) + (size_t)(i) * ((AJAR_SUBPATH_WORDS) * VSTRIDE))
#define VTMP(t) VertexWords t
INLINE PathVertex *vertex_load(VCRef r, VertexWords *t)
{
	for (int f = 0; f < VERTEX_WORDS; f++)
		t->w[f] = r[(size_t)f * VSTRIDE];
	return &t->v;
}
INLINE VRef vertex_store(VRef r, const PathVertex *v)
{
	VertexWords t;
	t.v = *v;
	for (int f = 0; f < VERTEX_WORDS; f++)
		r[(size_t)f * VSTRIDE] = t.w[f];
	return r;
}
INLINE void vertex_copy(VRef d, VCRef s)
{
	for (int f = 0; f < VERTEX_WORDS; f++)
		d[(size_t)f * VSTRIDE] = s[(size_t)f * VSTRIDE];
}
#define VLOAD(r, t) ((const PathVertex *)vertex_load((r), &(t)))
#define VEDIT(r, t) vertex_load((r), &(t))
#define VNEW(r, t) (&(t).v)
#define VCOMMIT(r, v) ((void)vertex_store((r), (v)))
#define VSTORE(r, v) ((void)vertex_store((r), (v)))
#define VCOPY(d, s) vertex_copy((d), (s))
#define VGETF(r, f) u2f((r)[VOFF(f)])
#define VGETI(r, f) ((int)(r)[VOFF(f)])
#define VGET3(r, f) v3(u2f((r)[VOFF(f.x)]), u2f((r)[VOFF(f.y)]), u2f((r)[VOFF(f.z)]))
#define VSETF(r, f, x) ((r)[VOFF(f)] = f2u(x))
#define VSETI(r, f, x) ((r)[VOFF(f)] = (uint)(x))
#define VSET3(r, f, val)                                 \
	do {                                             \
		V3 vset3_ = (val);                       \
		(r)[VOFF(f.x)] = f2u(vset3_.x);          \
		(r)[VOFF(f.y)] = f2u(vset3_.y);          \
		(r)[VOFF(f.z)] = f2u(vset3_.z);          \
	} while (0)
#define VNEE(e, y) ((VCRef)vertex_store(VAT((VRef)(e), SUBPATH_MAX), &(y)))
#else
typedef PathVertex *VRef;
typedef const PathVertex *VCRef;
#define VAT(a, i) (&(a)[i])
#define VTMP(t)
#define VLOAD(r, t) ((const PathVertex *)(r))
#define VEDIT(r, t) (r)
#define VNEW(r, t) (r)
#define VCOMMIT(r, v) ((void)0)
#define VSTORE(r, v) ((void)(*(r) = *(v)))
#define VCOPY(d, s) ((void)(*(d) = *(s)))
#define VGETF(r, f) ((r)->f)
#define VGETI(r, f) ((r)->f)
#define VGET3(r, f) ((r)->f)
#define VSETF(r, f, x) ((r)->f = (x))
#define VSETI(r, f, x) ((r)->f = (x))
#define VSET3(r, f, x) ((r)->f = (x))
#define VNEE(e, y) ((VCRef)&(y))
#endif
/* The slots of one work-item: light, eye (+ the next-event vertex), the
 * two halves of an intermediate subpath. */
#define SUBPATH_SLOTS (4 * SUBPATH_MAX + 1)

/* A vertex at infinity (p a direction): the environment or a directional light. */
INLINE int vertex_infinite(const PathVertex *v) { return v->type == VERTEX_ENV || v->type == VERTEX_SUN; }

/* A punctual light: no ray hits it (s = 0 is impossible), and it is never
 * a connection end but as the fixed end of next-event estimation. */
INLINE int vertex_delta_light(const PathVertex *v) { return v->type == VERTEX_PUNCTUAL || v->type == VERTEX_SUN; }

/* The same two tests of a stored vertex, reading its type alone. */
#define VREF_INFINITE(r) (VGETI(r, type) == VERTEX_ENV || VGETI(r, type) == VERTEX_SUN)
#define VREF_DELTA_LIGHT(r) (VGETI(r, type) == VERTEX_PUNCTUAL || VGETI(r, type) == VERTEX_SUN)

/* Area density at `to` of a direction sampled at `from` with solid-angle
 * density pdf_w; unchanged (solid angle) when `to` is at infinity. */
INLINE float vertex_density_a(const PathVertex *from, const PathVertex *to, float pdf_w)
{
	if (vertex_infinite(to))
		return pdf_w;
	V3 d = v3_sub(to->p, from->p);
	float d2 = v3_len2(d);
	if (!(d2 > 0.0f))
		return 0.0f;
	return pdf_w * fabs(v3_dot(to->ng, d)) / (d2 * sqrt(d2));
}

/* The shading normal of x turned toward `from`, its neighbour on the eye
 * side of the path: the normal that next-event samples from x are weighed
 * by (env_portal.h). Taken from the two positions, never from x's wo, so
 * that sampling and every MIS record of the same path agree bit for bit
 * whichever walk made x. */
INLINE int vertex_nee_side(const PathVertex *x, const PathVertex *from)
{
	V3 w = vertex_infinite(from) ? from->p : v3_sub(from->p, x->p);
	return v3_dot(x->ns, w) < 0.0f;
}

INLINE V3 vertex_nee_normal(const PathVertex *x, const PathVertex *from)
{
	return vertex_nee_side(x, from) ? v3_neg(x->ns) : x->ns;
}

/* pbrt's correction for shading normals in light transport (Veach 1997,
 * sec. 5.3): scattering toward wi at a light-subpath vertex whose previous
 * vertex lies along wo. */
INLINE float vertex_shading_correction(const PathVertex *v, V3 wo, V3 wi)
{
	float den = fabs(v3_dot(wo, v->ng)) * fabs(v3_dot(wi, v->ns));
	if (!(den > 0.0f))
		return 0.0f;
	return fabs(v3_dot(wo, v->ns)) * fabs(v3_dot(wi, v->ng)) / den;
}

/* Appends to path[n] the vertex that the ray (o, d) from path[n - 1]
 * hits, with throughput beta. `pdf_w` is the solid-angle density of d at
 * path[n - 1]; `parallel` says the ray is one of a parallel family (leaving
 * the environment's disk): then pdf_w is per unit perpendicular area and no
 * 1/d^2 applies. `light_side` says which density the walk fills (pf for
 * light subpaths and the portal's -> half). A ray that escapes becomes an
 * environment vertex if `escape_env` and the scene has one. Returns 1 if
 * a vertex was appended.
 *
 * A pane (TRI_PANE) the ray hits is crossed by the null event with
 * probability bsdf_null_prob, as bsdf_sample would pick it there: no
 * vertex, the ray goes on, beta times the transmittance over that
 * probability; the densities stay those of path[n - 1]'s sampling, over
 * the whole edge. Otherwise the pane becomes the vertex, its throughput
 * over the probability of that (what connections from it need), and its
 * scattering (vertex_scatter) samples the rest of its BSDF, times the
 * rest's share (what continuing needs). rng draws only
 * at panes. The edge also takes Beer-Lambert absorption where it runs
 * inside a solid. */
CALLED int vertex_trace(const SceneView *sc, VRef path, int n, V3 o, V3 d, V3 beta, float pdf_w, int parallel,
			int light_side, int escape_env, Rng *rng)
{
	VTMP(pt);
	VTMP(vt);
	const PathVertex *prev = VLOAD(VAT(path, n - 1), pt);
	PathVertex *v = VNEW(VAT(path, n), vt);
	Hit h = {0.0f, 0.0f, 0.0f, -1, -1}; /* gcc cannot see bvh_intersect set it */
	int portals = PARAMS_INTEGRATOR(sc->params) == INTEGRATOR_PORTAL;
	v->wo = v3_neg(d);
	v->delta = 0;
	v->pf = v->pr = 0.0f;
	v->cross = 0;
	int hit;
	Surface s;
	float exist = 1.0f; /* the probability that the walk has a vertex where it stopped */
	for (int panes = 0;; panes++) {
		hit = bvh_intersect(sc, o, d, AJAR_INF, &h);
		if (!hit)
			break;
		surface_from_hit(sc, &h, &s);
		v->base = surface_base_color(sc, &s);
		surface_bsdf(sc, &s, v->base, &v->bs);
		bsdf_cache_wo(&v->bs, v->wo); /* its lobes from wo: sampled and connected from there */
#ifndef AJAR_NO_PANES
		if (sc->tris[s.tri].flags & TRI_PANE) {
			float pn = bsdf_null_prob(&v->bs, v->wo);
			if (pn > 0.0f && rng_f(rng) < pn) {
				if (panes >= VERTEX_PANES_MAX)
					return 0;
				beta = v3_mul(beta, v3_scale(bsdf_null_weight(&v->bs, d), 1.0f / pn));
				o = ray_offset(s.p, s.ng, d);
				continue;
			}
			exist = 1.0f - pn;
		}
#endif
		break;
	}
	v->beta = v3_scale(beta, 1.0f / exist);
	if (!hit) {
		if (!escape_env || sc->params->env_type == ENV_NONE)
			return 0;
		v->type = VERTEX_ENV;
		v->p = d;
		v->ng = v->ns = v3_neg(d);
		v->base = v3(0.0f, 0.0f, 0.0f);
		v->material = v->tri = -1;
		if (light_side)
			v->pf = pdf_w;
		else
			v->pr = pdf_w;
		if (portals)
			v->cross = portal_crossings(sc, prev->p, d, 1);
		VCOMMIT(VAT(path, n), v);
		return 1;
	}
	v->type = VERTEX_SURFACE;
	v->p = s.p;
	v->ng = s.ng;
	v->ns = s.ns;
	v->material = s.material;
	v->tri = s.tri;
	if (prev->type == VERTEX_SURFACE)
		v->beta = v3_mul(v->beta, volume_attenuation(sc, prev->material, prev->ng, d, v3_len(v3_sub(s.p, prev->p))));
	float pa = parallel ? pdf_w * fabs(v3_dot(s.ng, d)) : vertex_density_a(prev, v, pdf_w);
	if (light_side)
		v->pf = pa;
	else
		v->pr = pa;
	if (portals) /* the edge to prev, or, from the sky, the ray back out */
		v->cross = vertex_infinite(prev) ? portal_crossings(sc, v->p, prev->p, 1)
						    : portal_crossings(sc, prev->p, v->p, 0);
	VCOMMIT(VAT(path, n), v);
	return 1;
}

/* Samples the BSDF at surface vertex path[n - 1] (its predecessor along
 * path[n - 1].wo is path[n - 2]): the next ray (*o, *d), its density *pdf_w
 * (0 after a delta lobe) and the new throughput *beta; sets the reverse
 * density of path[n - 2]. Russian roulette (roulette.h) at path[rr_depth] and
 * beyond, relative to beta_ref (none while beta_ref is 0). Returns 0 if the
 * subpath ends here. */
INLINE int vertex_scatter(const SceneView *sc, VRef path, int n, int light_side, float beta_ref, V3 *beta, V3 *o,
			  V3 *d, float *pdf_w, Rng *rng)
{
	VTMP(vt);
	VTMP(pt);
	BsdfSample bsm;
	if (VGETI(VAT(path, n - 1), type) != VERTEX_SURFACE)
		return 0;
	const PathVertex *v = VLOAD(VAT(path, n - 1), vt), *prev = VLOAD(VAT(path, n - 2), pt);
	float u0, u1, u2;
	rng_f3(rng, &u0, &u1, &u2);
#ifndef AJAR_NO_PANES
	/* vertex_trace decided against a pane's null event here: the rest of
	 * its BSDF, with the lobe probabilities it has (what MIS reads). */
	float rest = 1.0f; /* the share of the BSDF's sampling left to the vertex */
	if (sc->tris[v->tri].flags & TRI_PANE)
		rest = 1.0f - bsdf_null_prob(&v->bs, v->wo);
	u0 *= rest;
#endif
	if (!bsdf_sample(&v->bs, v->wo, u0, u1, u2, light_side ? BSDF_IMPORTANCE : BSDF_RADIANCE, &bsm) ||
	    !(bsm.pdf_w > 0.0f))
		return 0;
	if (bsm.delta == BSDF_NULL) /* smooth thin glass that is no pane (emissive): a delta vertex */
		bsm.delta = 1;
	float k = fabs(v3_dot(v->ns, bsm.wi)) / bsm.pdf_w;
#ifndef AJAR_NO_PANES
	k *= rest; /* v->beta counts the vertex's own probability (vertex_trace) */
#endif
	if (light_side)
		k *= vertex_shading_correction(v, v->wo, bsm.wi);
	*beta = v3_mul(v->beta, v3_scale(bsm.f, k));
	VSETI(VAT(path, n - 1), delta, bsm.delta);
	*pdf_w = bsm.delta ? 0.0f : bsm.pdf_w;
	float rev_a = bsm.delta ? 0.0f : vertex_density_a(v, prev, bsm.pdf_rev_w);
	if (light_side)
		VSETF(VAT(path, n - 2), pr, rev_a);
	else
		VSETF(VAT(path, n - 2), pf, rev_a);
	float boost = sc->params->light_paths ? RR_BOOST_CONNECTED : RR_BOOST;
	if (n - 1 >= sc->params->rr_depth && beta_ref > 0.0f && !rr_survive(beta, beta_ref, boost, rng))
		return 0;
	if (v3_is_zero(*beta))
		return 0;
	*o = ray_offset(v->p, v->ng, bsm.wi);
	*d = bsm.wi;
	return 1;
}

/* Extends a subpath from its last vertex path[n - 1] by BSDF sampling
 * until max_verts vertices, a miss, or Russian roulette. beta_ref is the
 * roulette's reference throughput; 0 takes the throughput after the first
 * scattering (camera walks, roulette.h). Returns the new vertex count. */
CALLED int vertex_extend(const SceneView *sc, VRef path, int n, int max_verts, int light_side,
			 int escape_env, float beta_ref, Rng *rng)
{
	V3 o, d, beta;
	float pdf_w;
	while (n < max_verts && vertex_scatter(sc, path, n, light_side, beta_ref, &beta, &o, &d, &pdf_w, rng)) {
		if (!(beta_ref > 0.0f))
			beta_ref = fmax(v3_maxc(beta), 1e-30f);
		if (!vertex_trace(sc, path, n, o, d, beta, pdf_w, 0, light_side, escape_env, rng))
			break;
		n++;
	}
	return n;
}

/* A subpath from path[n - 1] along the ray (o, d): the first hit, then
 * BSDF sampling (vertex_trace and vertex_extend). The roulette of a light
 * walk is relative to its starting throughput, that of a camera walk to the
 * throughput after its first scattering. */
CALLED int vertex_walk(const SceneView *sc, VRef path, int n, int max_verts, V3 o, V3 d, V3 beta,
		       float pdf_w, int parallel, int light_side, int escape_env, Rng *rng)
{
	if (n >= max_verts || !vertex_trace(sc, path, n, o, d, beta, pdf_w, parallel, light_side, escape_env, rng))
		return n;
	float beta_ref = light_side ? fmax(v3_maxc(beta), 1e-30f) : 0.0f;
	return vertex_extend(sc, path, n + 1, max_verts, light_side, escape_env, beta_ref, rng);
}
#endif
