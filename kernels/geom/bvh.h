/* bvh.h — ray queries against the flattened BVH (built by src/prepare/bvh_build.c) and
 * the small geometry helpers that go with them.
 *
 * Triangles are tested with the watertight algorithm of Woop, Benthin and
 * Wald (JCGT 2013), two-sided, so a ray through a shared edge or vertex
 * cannot slip between neighbours. Traversal of the eight-wide tree is
 * iterative with a fixed stack (the builder bounds its depth, src/prepare/bvh_build.c),
 * visits children nearest first, and widens box exits by 2 gamma(3) so the
 * box test never rejects a triangle hit the exact test accepts (Ize 2013,
 * "Robust BVH ray traversal"). */
#ifndef AJAR_KERNEL_BVH_H
#define AJAR_KERNEL_BVH_H
#include "material/texture.h"
#include "base/types.h"

/* Any traversal of one eight-wide tree pushes at most 7 entries a level
 * for 32 levels (src/prepare/bvh_build.c); with instances, a top-level
 * tree's and a mesh's. */
#ifdef AJAR_NO_INSTANCES
#define BVH_STACK_SIZE 224
#else
#define BVH_STACK_SIZE 448
#endif

typedef struct {
	float t;
	float u, v; /* barycentrics of p1 and p2 */
	int tri;
	int inst;   /* the Instance the triangle was hit in, -1 for world-space triangles */
} Hit;

/* The panes (TRI_PANE triangles) a shadow ray crosses, kept by the traversal
 * for their transmittance (geom/visibility.h) instead of ending it. A scene
 * without panes is built with AJAR_NO_PANES, and no traversal looks. */
#define PANE_HITS_MAX 8
typedef struct {
	int n; /* panes crossed; above PANE_HITS_MAX the list holds the first ones found */
	Hit hit[PANE_HITS_MAX];
} PaneHits;

/* Per-ray constants of the watertight test and of the slab test. */
typedef struct {
	V3 o;
	V3 inv_d;       /* 1/d; +inf for a zero component */
	int kx, ky, kz; /* kz: dominant axis of d; kx, ky keep the winding */
	float sx, sy, sz;
} RayPre;

INLINE RayPre ray_pre(V3 o, V3 d)
{
	RayPre r;
	r.o = o;
	/* A zero component gives +inf (never -inf: -0 becomes +0), which
	 * box_slab relies on; a finite stand-in would cut the slab short. */
	r.inv_d = v3(1.0f / (d.x == 0.0f ? 0.0f : d.x), 1.0f / (d.y == 0.0f ? 0.0f : d.y),
		     1.0f / (d.z == 0.0f ? 0.0f : d.z));
	float ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
	r.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
	r.kx = r.kz == 2 ? 0 : r.kz + 1;
	r.ky = r.kx == 2 ? 0 : r.kx + 1;
	float dz = v3_comp(d, r.kz);
	if (dz < 0.0f) {
		int k = r.kx;
		r.kx = r.ky;
		r.ky = k;
	}
	r.sx = v3_comp(d, r.kx) / dz;
	r.sy = v3_comp(d, r.ky) / dz;
	r.sz = 1.0f / dz;
	return r;
}

/* Watertight ray/triangle test. On a hit with 0 < t < tmax writes t and
 * the barycentrics of p1 (u) and p2 (v) and returns 1.
 *
 * No fused multiply-adds: two triangles sharing an edge compute its edge
 * function as cx by - cy bx and bx cy - by cx, exact negatives of each
 * other only when both products are rounded alike. OpenCL C contracts by
 * default (PoCL made the first product exact and rounded the second), which
 * lets a ray through the edge miss both; the host build never contracts
 * (-ffp-contract=off in the Makefile). */
HOT_INLINE int tri_intersect(const RayPre *r, GLOBAL const Tri *tri, float tmax, float *t, float *u,
			 float *v)
{
#ifdef AJAR_DEVICE
#pragma OPENCL FP_CONTRACT OFF
#endif
	V3 a = v3_sub(tri->p0, r->o), b = v3_sub(tri->p1, r->o), c = v3_sub(tri->p2, r->o);
	float az = v3_comp(a, r->kz), bz = v3_comp(b, r->kz), cz = v3_comp(c, r->kz);
	float ax = v3_comp(a, r->kx) - r->sx * az, ay = v3_comp(a, r->ky) - r->sy * az;
	float bx = v3_comp(b, r->kx) - r->sx * bz, by = v3_comp(b, r->ky) - r->sy * bz;
	float cx = v3_comp(c, r->kx) - r->sx * cz, cy = v3_comp(c, r->ky) - r->sy * cz;
	/* Edge functions: e0 weighs p0, e1 p1, e2 p2. Zero counts as inside,
	 * so a ray exactly through an edge hits both neighbours, never none. */
	float e0 = cx * by - cy * bx;
	float e1 = ax * cy - ay * cx;
	float e2 = bx * ay - by * ax;
	if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f))
		return 0;
	float det = e0 + e1 + e2;
	if (det == 0.0f)
		return 0;
	float tt = (e0 * az + e1 * bz + e2 * cz) * r->sz;
	if (det > 0.0f ? tt <= 0.0f : tt >= 0.0f) /* behind the origin: skip the divide */
		return 0;
	float inv = 1.0f / det;
	float th = tt * inv;
	if (!(th > 0.0f && th < tmax))
		return 0;
	*t = th;
	*u = e1 * inv;
	*v = e2 * inv;
	return 1;
}

/* One slab of the box test, narrowing [*tn, *tf]. Written with
 * comparisons, not fmin/fmax, so the NaN of 0 * inf (origin exactly on the
 * plane of a slab the ray runs parallel to) leaves the interval alone: the
 * ray is then inside that slab (pbrt's Bounds3::IntersectP). The far
 * distance grows by 1 + 2 gamma(3) against rounding (Ize 2013). */
HOT_INLINE void box_slab(float lo, float hi, float o, float inv_d, float *tn, float *tf)
{
	float a = (lo - o) * inv_d, b = (hi - o) * inv_d;
	if (a > b) {
		float t = a;
		a = b;
		b = t;
	}
	b *= 1.00000036f;
	*tn = a > *tn ? a : *tn;
	*tf = b < *tf ? b : *tf;
}

/* Leaf slots: triangles [first, first + count), 1 <= count <= 4. */
#define BVH_LEAF(first, count) (-1 - (4 * (first) + (count) - 1))
#define BVH_EMPTY (-2147483647 - 1)
/* A top-level slot holding Instance i: past every node index. */
#define BVH_INSTANCE_BASE 0x40000000
#define BVH_INSTANCE(i) (BVH_INSTANCE_BASE + (i))
#define BVH_LEAF_FIRST(c) ((-1 - (c)) >> 2)
#define BVH_LEAF_COUNT(c) (((-1 - (c)) & 3) + 1)

/* Enters the boxes of node n's BVH_WIDTH slots within [0, tlim]: returns
 * the mask of the slots entered (bit i: slot i) and their entry distances
 * in tn[]. An unused slot's box at +inf is never entered by a ray with
 * finite origin and direction (bvh_traverse refuses any other) within a
 * finite tlim.
 *
 * The slab tests are independent, so they run side by side in eight lanes.
 * Compiled for an x86 CPU with AVX (PoCL), the lanes are written out as
 * float8: the compiler then keeps them in one register and takes the mask
 * with one compare (a movmskps), where the loop below left it to spill the
 * lanes and gather their bits one by one: 1.03-1.05x the incoherent rays
 * per second on living-room and bathroom (make bench), 1.00-1.05x their
 * renders. Both give the same bits: the same operations in the same order,
 * and select() keeps box_slab's NaN behaviour. */
#if defined(AJAR_DEVICE) && defined(__AVX__) && defined(__clang__) && BVH_WIDTH == 8
HOT_INLINE void box_slab8(GLOBAL const float *lo, GLOBAL const float *hi, float o, float inv_d, float8 *tn,
			  float8 *tf)
{
	float8 a = (vload8(0, lo) - o) * inv_d, b = (vload8(0, hi) - o) * inv_d;
	int8 swap = a > b;
	float8 near = select(a, b, swap), far = select(b, a, swap) * 1.00000036f;
	*tn = select(*tn, near, near > *tn);
	*tf = select(*tf, far, far < *tf);
}

HOT_INLINE int bvh_node_enter(const RayPre *r, GLOBAL const BvhNode *n, float tlim, float tn[BVH_WIDTH])
{
	float8 near = (float8)(0.0f), far = (float8)(tlim);
	box_slab8(n->lo_x, n->hi_x, r->o.x, r->inv_d.x, &near, &far);
	box_slab8(n->lo_y, n->hi_y, r->o.y, r->inv_d.y, &near, &far);
	box_slab8(n->lo_z, n->hi_z, r->o.z, r->inv_d.z, &near, &far);
	vstore8(near, 0, tn);
	return __builtin_ia32_movmskps256(as_float8(near <= far));
}
#else
HOT_INLINE int bvh_node_enter(const RayPre *r, GLOBAL const BvhNode *n, float tlim, float tn[BVH_WIDTH])
{
	float tf[BVH_WIDTH];
	for (int i = 0; i < BVH_WIDTH; i++) {
		tn[i] = 0.0f;
		tf[i] = tlim;
		box_slab(n->lo_x[i], n->hi_x[i], r->o.x, r->inv_d.x, &tn[i], &tf[i]);
		box_slab(n->lo_y[i], n->hi_y[i], r->o.y, r->inv_d.y, &tn[i], &tf[i]);
		box_slab(n->lo_z[i], n->hi_z[i], r->o.z, r->inv_d.z, &tn[i], &tf[i]);
	}
	int m = 0;
	for (int i = 0; i < BVH_WIDTH; i++)
		m |= (tn[i] <= tf[i]) << i;
	return m;
}
#endif

/* Index of the lowest set bit of a nonzero mask. */
HOT_INLINE int bvh_lowest(int m) { return 31 - (int)clz((uint)(m & -m)); }

INLINE int v3_finite(V3 a)
{
	return fabs(a.x) <= AJAR_INF && fabs(a.y) <= AJAR_INF && fabs(a.z) <= AJAR_INF;
}

/* An affine transform's rows of 3x4 (Instance.xf, .inv) applied to a
 * point, and its 3x3 part to a vector. */
INLINE V3 xf_point(GLOBAL const float *m, V3 p)
{
	return v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
		  m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}
INLINE V3 xf_vector(GLOBAL const float *m, V3 v)
{
	return v3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
		  m[8] * v.x + m[9] * v.y + m[10] * v.z);
}
/* A normal by the transpose of inv's 3x3 part (inv^T n: the inverse
 * transpose of the object-to-world transform). */
INLINE V3 xf_normal(GLOBAL const float *inv, V3 n)
{
	return v3(inv[0] * n.x + inv[4] * n.y + inv[8] * n.z, inv[1] * n.x + inv[5] * n.y + inv[9] * n.z,
		  inv[2] * n.x + inv[6] * n.y + inv[10] * n.z);
}

/* Closest hit with 0 < t < tmax (any_hit = 0), or the first hit found
 * (any_hit = 1), where with `panes` a pane is no hit but goes on the list.
 * Shared by the queries so the kernel holds one copy.
 * Children are visited nearest first; a pushed child whose entry distance
 * lies beyond the closest hit found since is skipped when popped. The
 * limits are widened a little: the triangle test and the slab test round
 * differently, and a triangle whose computed distance lies a few ulps below
 * the current closest hit must still be visited, or coplanar and touching
 * triangles could return a hit a few ulps farther than the closest. */
INLINE int bvh_traverse(const SceneView *sc, V3 o, V3 d, float tmax, int any_hit, Hit *hit, PaneHits *panes)
{
	if (!v3_finite(o) || !v3_finite(d))
		return 0;
	RayPre r = ray_pre(o, d);
	int stack[BVH_STACK_SIZE];
	float stack_t[BVH_STACK_SIZE];
	int sp = 0;
	int found = 0;
	int entry = 0; /* the root: the top-level tree's with instances */
#ifdef AJAR_NO_INSTANCES
	const int inst = -1;
#else
	/* Inside an instance the ray is the object-space one, r; the world's
	 * comes back when the stack falls below inst_sp, where it stood on
	 * entering. d is transformed unnormalized, so t is the same on both
	 * sides. */
	int inst = -1, inst_sp = 0;
#endif
	for (;;) {
		if (entry >= 0) {
#ifndef AJAR_NO_INSTANCES
			if (entry >= BVH_INSTANCE_BASE) {
				inst = entry - BVH_INSTANCE_BASE;
				inst_sp = sp;
				GLOBAL const Instance *in = &sc->instances[inst];
				r = ray_pre(xf_point(in->inv, o), xf_vector(in->inv, d));
				entry = in->root;
				continue;
			}
#endif
			GLOBAL const BvhNode *n = &sc->nodes[entry];
			float tn[BVH_WIDTH];
			int mask = bvh_node_enter(&r, n, fmin(tmax * 1.00001f, AJAR_INF), tn);
			if (mask != 0) {
				int i = bvh_lowest(mask);
				mask &= mask - 1;
				if (mask == 0) { /* one child: no stack */
					entry = n->child[i];
					continue;
				}
				int j = bvh_lowest(mask);
				mask &= mask - 1;
				if (mask == 0) { /* two: the farther waits */
					int near_i = tn[i] <= tn[j];
					entry = n->child[near_i ? i : j];
					stack[sp] = n->child[near_i ? j : i];
					stack_t[sp++] = tn[near_i ? j : i];
					continue;
				}
				/* Three or more: push all, nearest on top, pop it. */
				int base = sp;
				stack[sp] = n->child[i];
				stack_t[sp++] = tn[i];
				stack[sp] = n->child[j];
				stack_t[sp++] = tn[j];
				while (mask != 0) {
					int k = bvh_lowest(mask);
					mask &= mask - 1;
					stack[sp] = n->child[k];
					stack_t[sp++] = tn[k];
				}
				for (int a = base + 1; a < sp; a++) {
					int c = stack[a];
					float t = stack_t[a];
					int b = a;
					for (; b > base && stack_t[b - 1] < t; b--) {
						stack[b] = stack[b - 1];
						stack_t[b] = stack_t[b - 1];
					}
					stack[b] = c;
					stack_t[b] = t;
				}
				entry = stack[--sp];
				continue;
			}
		} else {
			int first = BVH_LEAF_FIRST(entry), last = first + BVH_LEAF_COUNT(entry);
			for (int i = first; i < last; i++) {
				float t, u, v;
				/* Alpha-tested triangles (TRI_ALPHA) may let the ray pass;
				 * a scene without any is built with AJAR_NO_ALPHA
				 * (src/prepare/prepare.c, kernel_omit). */
				if (tri_intersect(&r, &sc->tris[i], tmax, &t, &u, &v)
#ifndef AJAR_NO_ALPHA
				    && (!(sc->tris[i].flags & TRI_ALPHA) || alpha_hit(sc, i, u, v, o, d))
#endif
				) {
#ifndef AJAR_NO_PANES
					if (panes && (sc->tris[i].flags & TRI_PANE)) {
						if (panes->n < PANE_HITS_MAX) {
							Hit *ph = &panes->hit[panes->n];
							ph->t = t;
							ph->u = u;
							ph->v = v;
							ph->tri = i;
							ph->inst = inst;
						}
						panes->n++;
						continue;
					}
#endif
					found = 1;
					tmax = t;
					hit->t = t;
					hit->u = u;
					hit->v = v;
					hit->tri = i;
					hit->inst = inst;
					if (any_hit)
						return 1;
				}
			}
		}
		do {
			if (sp == 0)
				return found;
			sp--;
		} while (stack_t[sp] > tmax * 1.00001f);
		entry = stack[sp];
#ifndef AJAR_NO_INSTANCES
		if (inst >= 0 && sp < inst_sp) { /* back out of the instance */
			inst = -1;
			r = ray_pre(o, d);
		}
#endif
	}
}

/* Closest hit with 0 < t < tmax; returns 1 if there is one. */
CALLED int bvh_intersect(const SceneView *sc, V3 o, V3 d, float tmax, Hit *hit)
{
	return bvh_traverse(sc, o, d, tmax, 0, hit, 0);
}

/* Whether anything lies on the ray with 0 < t < tmax. */
CALLED int bvh_occluded(const SceneView *sc, V3 o, V3 d, float tmax)
{
	Hit h;
	return bvh_traverse(sc, o, d, tmax, 1, &h, 0);
}

#ifndef AJAR_NO_PANES
/* Whether anything but panes lies on the ray; the panes go to *p. */
CALLED int bvh_occluded_panes(const SceneView *sc, V3 o, V3 d, float tmax, PaneHits *p)
{
	Hit h;
	p->n = 0;
	return bvh_traverse(sc, o, d, tmax, 1, &h, p);
}
#endif

/* Unnormalized geometric normal; its side is the CCW front face. */
INLINE V3 tri_normal(GLOBAL const Tri *t)
{
	return v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
}

/* The world-space geometric normal (any length, the front face's side) of
 * the triangle a hit found: through its instance's transform if any. */
INLINE V3 hit_normal(const SceneView *sc, const Hit *h)
{
#ifndef AJAR_NO_INSTANCES
	if (h->inst >= 0)
		return xf_normal(sc->instances[h->inst].inv, tri_normal(&sc->tris[h->tri]));
#endif
	return tri_normal(&sc->tris[h->tri]);
}

/* Spawn point for a ray leaving surface point p in direction d: p moved
 * off the surface along the geometric normal ng (any length), to d's side,
 * by a few ulps of p's coordinates, or by a fixed small distance near the
 * origin where ulps vanish (Waechter and Binder, Ray Tracing Gems ch. 6). */
INLINE V3 ray_offset(V3 p, V3 ng, V3 d)
{
	V3 n = v3_norm(v3_dot(ng, d) < 0.0f ? v3_neg(ng) : ng);
	const float origin = 1.0f / 32.0f, float_scale = 1.0f / 65536.0f, int_scale = 256.0f;
	int ox = (int)(int_scale * n.x), oy = (int)(int_scale * n.y), oz = (int)(int_scale * n.z);
	/* Adding to the bit pattern moves away from zero, so negative
	 * coordinates take the opposite offset. */
	float px = u2f(f2u(p.x) + (uint)(p.x < 0.0f ? -ox : ox));
	float py = u2f(f2u(p.y) + (uint)(p.y < 0.0f ? -oy : oy));
	float pz = u2f(f2u(p.z) + (uint)(p.z < 0.0f ? -oz : oz));
	return v3(fabs(p.x) < origin ? p.x + float_scale * n.x : px,
		  fabs(p.y) < origin ? p.y + float_scale * n.y : py,
		  fabs(p.z) < origin ? p.z + float_scale * n.z : pz);
}

#endif
