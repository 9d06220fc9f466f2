/* test_bvh.c — the BVH build (src/prepare/bvh_build.c) and traversal (kernels/geom/bvh.h):
 * structure invariants, closest hits identical to brute force over every
 * triangle on random soups (uniform, clustered, coplanar, degenerate and
 * sliver triangles, one triangle, all-identical triangles, a depth-hostile
 * geometric progression) and on the shipped scenes, and any-hit agreeing
 * with closest hit. Brute force uses the same triangle test, so hit
 * distances must match exactly. */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "prepare/bvh_build.h"
#include "scene/gltf.h"
#include "scene/scene.h"
#include "geom/bvh.h"

static uint64_t rng_state;

static uint32_t rnd_u32(void)
{
	/* PCG32 (O'Neill), fixed seed per test. */
	uint64_t old = rng_state;
	rng_state = old * 6364136223846793005ULL + 1442695040888963407ULL;
	uint32_t xs = (uint32_t)(((old >> 18) ^ old) >> 27), rot = (uint32_t)(old >> 59);
	return (xs >> rot) | (xs << ((-rot) & 31));
}

static float rnd(void) { return (float)(rnd_u32() >> 8) * (1.0f / 16777216.0f); }
static float rnd_range(float a, float b) { return a + (b - a) * rnd(); }

/* Uniform in the box [lo, hi] (components drawn in a fixed order). */
static V3 rnd_v3(V3 lo, V3 hi)
{
	V3 r;
	r.x = rnd_range(lo.x, hi.x);
	r.y = rnd_range(lo.y, hi.y);
	r.z = rnd_range(lo.z, hi.z);
	return r;
}

static V3 rnd_dir(void)
{
	float z = 1.0f - 2.0f * rnd(), phi = 2.0f * AJAR_PI * rnd();
	float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
	return v3(r * cosf(phi), r * sinf(phi), z);
}

static Tri make_tri(V3 a, V3 b, V3 c)
{
	Tri t;
	memset(&t, 0, sizeof(t));
	t.p0 = a;
	t.p1 = b;
	t.p2 = c;
	t.emitter = -1;
	return t;
}

/* Vertices within distance s of c (drawn in a fixed order). */
static Tri rnd_tri_around(V3 c, float s)
{
	V3 a = v3_madd(c, rnd_dir(), s);
	V3 b = v3_madd(c, rnd_dir(), s);
	return make_tri(a, b, v3_madd(c, rnd_dir(), s));
}

/* A built BVH with the triangles reordered as the device would see them. */
typedef struct {
	Bvh bvh;
	Tri *tris;
	SceneView sc;
	V3 lo, hi;
} Built;

static void built_make(const Tri *tris, uint32_t n, Built *b)
{
	memset(b, 0, sizeof(*b));
	assert_int_equal(bvh_build(tris, n, &b->bvh), AJAR_OK);
	b->tris = malloc(sizeof(Tri) * n);
	assert_non_null(b->tris);
	for (uint32_t i = 0; i < n; i++)
		b->tris[i] = tris[b->bvh.order[i]];
	b->sc.nodes = b->bvh.nodes;
	b->sc.tris = b->tris;
	b->lo = v3(INFINITY, INFINITY, INFINITY);
	b->hi = v3(-INFINITY, -INFINITY, -INFINITY);
	const BvhNode *root = &b->bvh.nodes[0];
	for (int k = 0; k < BVH_WIDTH; k++)
		if (root->child[k] != BVH_EMPTY) {
			b->lo = v3_min(b->lo, v3(root->lo_x[k], root->lo_y[k], root->lo_z[k]));
			b->hi = v3_max(b->hi, v3(root->hi_x[k], root->hi_y[k], root->hi_z[k]));
		}
}

static void built_free(Built *b)
{
	bvh_free(&b->bvh);
	free(b->tris);
}

static V3 slot_lo(const BvhNode *n, int k) { return v3(n->lo_x[k], n->lo_y[k], n->lo_z[k]); }
static V3 slot_hi(const BvhNode *n, int k) { return v3(n->hi_x[k], n->hi_y[k], n->hi_z[k]); }

static int box_contains(V3 olo, V3 ohi, V3 lo, V3 hi)
{
	return olo.x <= lo.x && olo.y <= lo.y && olo.z <= lo.z && ohi.x >= hi.x && ohi.y >= hi.y &&
	       ohi.z >= hi.z;
}

/* Every triangle in exactly one leaf slot of at most 4, every node but the
 * root the child of exactly one slot, children after their parent, boxes
 * nested, unused slots at (+inf, +inf, +inf), depth bounded. */
static void check_structure(const Built *b, uint32_t n)
{
	const Bvh *bvh = &b->bvh;
	assert_true(bvh->nnodes >= 1 && bvh->nnodes <= n);
	assert_true(bvh->depth >= 1 && bvh->depth <= BVH_MAX_DEPTH);
	assert_true(bvh->wide_depth >= 1 && bvh->wide_depth <= BVH_MAX_DEPTH / 2);
	assert_true(bvh->wide_depth <= (bvh->depth + 1) / 2 || bvh->depth == 1);
	assert_int_equal(bvh_memory(bvh), bvh->nnodes * sizeof(BvhNode) + n * sizeof(uint32_t));
	char *seen = calloc(n, 1);
	uint32_t *covered = calloc(n, sizeof(uint32_t));
	uint32_t *parents = calloc(bvh->nnodes, sizeof(uint32_t));
	assert_non_null(seen);
	assert_non_null(covered);
	assert_non_null(parents);
	for (uint32_t i = 0; i < n; i++) {
		assert_true(bvh->order[i] < n);
		assert_false(seen[bvh->order[i]]);
		seen[bvh->order[i]] = 1;
	}
	for (uint32_t i = 0; i < bvh->nnodes; i++) {
		const BvhNode *nd = &bvh->nodes[i];
		int used = 0;
		for (int k = 0; k < BVH_WIDTH; k++) {
			int c = nd->child[k];
			V3 lo = slot_lo(nd, k), hi = slot_hi(nd, k);
			if (c == BVH_EMPTY) {
				assert_true(lo.x == INFINITY && lo.y == INFINITY && lo.z == INFINITY);
				assert_true(hi.x == INFINITY && hi.y == INFINITY && hi.z == INFINITY);
				continue;
			}
			used++;
			if (c < 0) {
				int first = BVH_LEAF_FIRST(c), count = BVH_LEAF_COUNT(c);
				assert_true(c == BVH_LEAF(first, count));
				assert_true(count >= 1 && count <= 4);
				assert_true(first >= 0 && (uint32_t)(first + count) <= n);
				for (int t = first; t < first + count; t++) {
					const Tri *tr = &b->tris[t];
					assert_true(box_contains(lo, hi, v3_min(tr->p0, v3_min(tr->p1, tr->p2)),
								 v3_max(tr->p0, v3_max(tr->p1, tr->p2))));
					covered[t]++;
				}
			} else {
				assert_true((uint32_t)c > i && (uint32_t)c < bvh->nnodes);
				parents[c]++;
				const BvhNode *ch = &bvh->nodes[c];
				for (int j = 0; j < BVH_WIDTH; j++)
					if (ch->child[j] != BVH_EMPTY)
						assert_true(box_contains(lo, hi, slot_lo(ch, j), slot_hi(ch, j)));
			}
		}
		/* Only a root over at most 4 triangles has a single slot. */
		assert_true(used >= 2 || (i == 0 && bvh->nnodes == 1 && used == 1));
	}
	assert_int_equal(parents[0], 0);
	for (uint32_t i = 1; i < bvh->nnodes; i++)
		assert_int_equal(parents[i], 1);
	for (uint32_t i = 0; i < n; i++)
		assert_int_equal(covered[i], 1);
	free(seen);
	free(covered);
	free(parents);
}

static int brute_closest(const Built *b, uint32_t n, V3 o, V3 d, float tmax, Hit *hit)
{
	RayPre r = ray_pre(o, d);
	int found = 0;
	for (uint32_t i = 0; i < n; i++) {
		float t, u, v;
		if (tri_intersect(&r, &b->tris[i], tmax, &t, &u, &v)) {
			tmax = t;
			hit->t = t;
			hit->u = u;
			hit->v = v;
			hit->tri = (int)i;
			found = 1;
		}
	}
	return found;
}

/* A random ray: from inside or around the bounds, aimed at a random point
 * of a random triangle half the time (so most rays hit something), and
 * along a coordinate axis now and then (zero direction components). */
static void random_ray(const Built *b, uint32_t n, V3 *o, V3 *d)
{
	V3 ext = v3_sub(b->hi, b->lo);
	V3 lo = v3_sub(b->lo, v3_scale(ext, 0.25f));
	*o = rnd_v3(lo, v3_madd(lo, ext, 1.5f));
	uint32_t kind = rnd_u32() % 8;
	if (kind < 4) {
		const Tri *t = &b->tris[rnd_u32() % n];
		float b1 = rnd(), b2 = rnd();
		if (b1 + b2 > 1.0f) {
			b1 = 1.0f - b1;
			b2 = 1.0f - b2;
		}
		V3 p = v3_add(t->p0, v3_add(v3_scale(v3_sub(t->p1, t->p0), b1),
					   v3_scale(v3_sub(t->p2, t->p0), b2)));
		V3 dd = v3_sub(p, *o);
		*d = v3_len2(dd) > 0.0f ? v3_norm(dd) : rnd_dir();
	} else if (kind == 4) {
		int axis = (int)(rnd_u32() % 3);
		float s = (rnd_u32() & 1) ? 1.0f : -1.0f;
		*d = v3(axis == 0 ? s : 0.0f, axis == 1 ? s : 0.0f, axis == 2 ? s : 0.0f);
	} else {
		*d = rnd_dir();
	}
}

/* Whether a hit's point lies on its triangle's bounds, give or take float
 * noise. A triangle seen nearly edge-on from far away (relative to its
 * size) gets edge functions and a distance that are pure rounding noise: a
 * "hit" far off the triangle that no traversal can be asked to reproduce
 * (its box test rightly rejects that point). */
static int hit_is_sound(const Built *b, V3 o, V3 d, const Hit *h)
{
	const Tri *t = &b->tris[h->tri];
	V3 p = v3_madd(o, d, h->t);
	V3 lo = v3_min(t->p0, v3_min(t->p1, t->p2)), hi = v3_max(t->p0, v3_max(t->p1, t->p2));
	/* about 100 ulps of the largest coordinate involved */
	float tol = 1e-5f * (v3_maxc(v3_max(v3_max(o, v3_neg(o)), v3_max(hi, v3_neg(lo)))) + h->t);
	return p.x >= lo.x - tol && p.y >= lo.y - tol && p.z >= lo.z - tol && p.x <= hi.x + tol &&
	       p.y <= hi.y + tol && p.z <= hi.z + tol;
}

/* Compares BVH and brute force on `nrays` rays; returns the hit count. */
static uint32_t check_rays(const Built *b, uint32_t n, uint32_t nrays)
{
	uint32_t hits = 0, unsound = 0;
	for (uint32_t k = 0; k < nrays; k++) {
		V3 o, d;
		random_ray(b, n, &o, &d);
		Hit hb = {0}, hf = {0};
		int fb = brute_closest(b, n, o, d, AJAR_INF, &hb);
		if (fb && !hit_is_sound(b, o, d, &hb)) {
			unsound++;
			continue;
		}
		int ff = bvh_intersect(&b->sc, o, d, AJAR_INF, &hf);
		if (fb != ff || (fb && (hb.t != hf.t))) {
			fprintf(stderr, "ray %u: o (%g %g %g) d (%g %g %g): brute %d t %.9g tri %d, bvh %d t %.9g tri %d\n",
				k, o.x, o.y, o.z, d.x, d.y, d.z, fb, hb.t, hb.tri, ff, hf.t, hf.tri);
			fail();
		}
		/* Same triangle, or another one at exactly the same distance. */
		if (fb && hb.tri != hf.tri) {
			assert_true(hb.t == hf.t);
		} else if (fb) {
			assert_true(hb.u == hf.u && hb.v == hf.v);
		}
		hits += (uint32_t)fb;
		/* Any-hit: occluded below the closest hit's distance iff hit. */
		if (fb) {
			assert_true(bvh_occluded(&b->sc, o, d, hb.t * 1.5f + 1e-3f));
			assert_false(bvh_occluded(&b->sc, o, d, hb.t * 0.5f));
			assert_int_equal(bvh_occluded(&b->sc, o, d, hb.t), 0);
		} else {
			assert_false(bvh_occluded(&b->sc, o, d, AJAR_INF));
		}
		/* A shorter tmax must return the closest hit below it, which is
		 * brute force's closest hit if that lies below tmax, else none
		 * (the triangle test's t does not depend on tmax). */
		float tmax = fb ? hb.t * rnd_range(0.5f, 2.0f) : rnd_range(0.1f, 10.0f);
		Hit hf2 = {0};
		int fb2 = fb && hb.t < tmax;
		int ff2 = bvh_intersect(&b->sc, o, d, tmax, &hf2);
		assert_int_equal(fb2, ff2);
		if (fb2)
			assert_true(hb.t == hf2.t);
	}
	/* Noise hits are rare; many would mean the soup tests nothing. */
	if (unsound)
		printf("  (%u rays skipped: closest hit is rounding noise)\n", unsound);
	assert_true(unsound <= nrays / 50);
	return hits;
}

static void run_soup(const Tri *tris, uint32_t n, uint32_t nrays, const char *name)
{
	Built b;
	built_make(tris, n, &b);
	check_structure(&b, n);
	uint32_t hits = check_rays(&b, n, nrays);
	printf("  %-12s %6u tris %6u nodes depth %2u (wide %2u): %u/%u rays hit\n", name, n, b.bvh.nnodes,
	       b.bvh.depth, b.bvh.wide_depth, hits, nrays);
	/* The soups are built so a good share of rays hits; a BVH that
	 * missed everything would agree with a broken brute force. */
	if (n > 1)
		assert_true(hits > nrays / 4);
	built_free(&b);
}

static void test_uniform_soup(void **state)
{
	rng_state = 1;
	uint32_t n = 1000;
	Tri *t = malloc(sizeof(Tri) * n);
	for (uint32_t i = 0; i < n; i++) {
		V3 c = rnd_v3(v3(0, 0, 0), v3(1, 1, 1));
		t[i] = rnd_tri_around(c, rnd_range(0.01f, 0.2f));
	}
	run_soup(t, n, 20000, "uniform");
	free(t);
}

static void test_clustered_soup(void **state)
{
	rng_state = 2;
	uint32_t n = 1000;
	Tri *t = malloc(sizeof(Tri) * n);
	/* Few tight clusters at very different scales, far apart (but each
	 * triangle still hundreds of ulps wide where it lies: smaller ones have
	 * no meaningful hit distance in float, for any traversal). */
	V3 centers[4] = {v3(0, 0, 0), v3(100, 3, -7), v3(100.01f, 3, -7), v3(-50, 80, 20)};
	float scales[4] = {1.0f, 1e-2f, 1e-3f, 10.0f};
	for (uint32_t i = 0; i < n; i++) {
		int k = (int)(rnd_u32() % 4);
		V3 dir = rnd_dir();
		V3 c = v3_madd(centers[k], dir, scales[k] * rnd());
		t[i] = rnd_tri_around(c, scales[k] * rnd_range(0.05f, 0.5f));
	}
	run_soup(t, n, 20000, "clustered");
	free(t);
}

/* A grid of coplanar squares sharing edges (watertightness: rays through
 * edges and vertices), with zero-area and sliver triangles mixed in. */
static void test_coplanar_degenerate_soup(void **state)
{
	rng_state = 3;
	uint32_t g = 16, n = 0;
	Tri *t = malloc(sizeof(Tri) * (2 * g * g + 400));
	for (uint32_t y = 0; y < g; y++)
		for (uint32_t x = 0; x < g; x++) {
			V3 a = v3((float)x, (float)y, 0), bb = v3((float)x + 1, (float)y, 0);
			V3 c = v3((float)x + 1, (float)y + 1, 0), d = v3((float)x, (float)y + 1, 0);
			t[n++] = make_tri(a, bb, c);
			t[n++] = make_tri(a, c, d);
		}
	for (uint32_t i = 0; i < 400; i++) {
		V3 a = rnd_v3(v3(0, 0, -2), v3(16, 16, 2));
		V3 e = rnd_dir();
		switch (i % 4) {
		case 0: /* a point */
			t[n++] = make_tri(a, a, a);
			break;
		case 1: /* collinear */
			t[n++] = make_tri(a, v3_madd(a, e, 1.0f), v3_madd(a, e, 2.5f));
			break;
		case 2: /* long sliver */
			t[n++] = make_tri(a, v3_madd(a, e, 8.0f), v3_madd(v3_madd(a, e, 4.0f), rnd_dir(), 1e-4f));
			break;
		default: /* coplanar with the grid, overlapping it */
			a.z = 0.0f;
			t[n++] = make_tri(a, v3(a.x + 1, a.y, 0), v3(a.x, a.y + 0.5f, 0));
			break;
		}
	}
	run_soup(t, n, 20000, "coplanar");
	free(t);
}

static void test_single_triangle(void **state)
{
	rng_state = 4;
	Tri t = make_tri(v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0));
	Built b;
	built_make(&t, 1, &b);
	assert_int_equal(b.bvh.nnodes, 1);
	assert_int_equal(b.bvh.nodes[0].child[0], BVH_LEAF(0, 1));
	for (int k = 1; k < BVH_WIDTH; k++)
		assert_int_equal(b.bvh.nodes[0].child[k], BVH_EMPTY);
	check_structure(&b, 1);
	check_rays(&b, 1, 20000);
	/* Known hit, both faces (no culling), barycentrics of p1 and p2. */
	Hit h;
	assert_true(bvh_intersect(&b.sc, v3(0.25f, 0.5f, 1), v3(0, 0, -1), AJAR_INF, &h));
	assert_float_equal(h.t, 1.0f, 1e-6f);
	assert_float_equal(h.u, 0.25f, 1e-6f);
	assert_float_equal(h.v, 0.5f, 1e-6f);
	assert_int_equal(h.tri, 0);
	assert_true(bvh_intersect(&b.sc, v3(0.25f, 0.5f, -2), v3(0, 0, 1), AJAR_INF, &h));
	assert_float_equal(h.t, 2.0f, 1e-6f);
	assert_false(bvh_intersect(&b.sc, v3(0.25f, 0.5f, -2), v3(0, 0, 1), 1.5f, &h));
	assert_false(bvh_intersect(&b.sc, v3(0.75f, 0.5f, 1), v3(0, 0, -1), AJAR_INF, &h));
	/* Rays with a non-finite origin or direction hit nothing (and never
	 * enter an unused slot, whose box lies at +inf). */
	assert_false(bvh_intersect(&b.sc, v3(0.25f, 0.5f, NAN), v3(0, 0, -1), AJAR_INF, &h));
	assert_false(bvh_intersect(&b.sc, v3(0.25f, 0.5f, 1), v3(0, NAN, -1), AJAR_INF, &h));
	assert_false(bvh_occluded(&b.sc, v3(0.25f, 0.5f, 1), v3(0, 0, -INFINITY), AJAR_INF));
	/* The front face is CCW seen from +Z. */
	V3 ng = tri_normal(&b.tris[0]);
	assert_true(ng.z > 0.0f && ng.x == 0.0f && ng.y == 0.0f);
	built_free(&b);
}

static void test_identical_triangles(void **state)
{
	rng_state = 5;
	uint32_t n = 5000;
	Tri *t = malloc(sizeof(Tri) * n);
	for (uint32_t i = 0; i < n; i++)
		t[i] = make_tri(v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0));
	Built b;
	built_make(t, n, &b);
	check_structure(&b, n);
	Hit h;
	assert_true(bvh_intersect(&b.sc, v3(0.2f, 0.2f, 1), v3(0, 0, -1), AJAR_INF, &h));
	assert_float_equal(h.t, 1.0f, 1e-6f);
	check_rays(&b, n, 500);
	built_free(&b);
	free(t);
}

/* Centroids at ±32^i along each axis, i = -25..24, every triangle a unit
 * square's half across the other two axes (so those axes cannot separate
 * them): in every node all but the outermost centroid share one bin, SAH
 * can only peel one triangle per level (depth 58 uncapped), and only the
 * median cap keeps the tree shallow. Coordinates span 2^-125..2^120, so
 * random rays mean nothing here; each triangle is probed by a ray aimed
 * straight at it instead. */
static void test_depth_bounded(void **state)
{
	uint32_t n = 0;
	Tri *t = malloc(sizeof(Tri) * 300);
	for (int axis = 0; axis < 3; axis++)
		for (int sign = -1; sign <= 1; sign += 2)
			for (int i = -25; i < 25; i++) {
				V3 ea = v3(axis == 0, axis == 1, axis == 2);
				V3 eb = v3(axis == 1, axis == 2, axis == 0);
				V3 ec = v3(axis == 2, axis == 0, axis == 1);
				V3 c = v3_scale(ea, (float)sign * ldexpf(1.0f, 5 * i));
				t[n++] = make_tri(c, v3_add(c, eb), v3_add(c, ec));
			}
	Built b;
	built_make(t, n, &b);
	check_structure(&b, n);
	printf("  hostile      %6u tris %6u nodes depth %2u (wide %2u)\n", n, b.bvh.nnodes, b.bvh.depth,
	       b.bvh.wide_depth);
	assert_true(b.bvh.depth > BVH_MAX_DEPTH - 32); /* the cap was needed */
	for (uint32_t i = 0; i < n; i++) {
		const Tri *tri = &b.tris[i];
		V3 e1 = v3_sub(tri->p1, tri->p0), e2 = v3_sub(tri->p2, tri->p0);
		V3 ng = v3_norm(tri_normal(tri));
		V3 target = v3_madd(v3_madd(tri->p0, e1, 0.2f), e2, 0.2f);
		V3 o = v3_madd(target, ng, 1.0f + v3_maxc(v3_max(tri->p0, v3_neg(tri->p0))));
		Hit hb, hf;
		assert_true(brute_closest(&b, n, o, v3_neg(ng), AJAR_INF, &hb));
		assert_true(bvh_intersect(&b.sc, o, v3_neg(ng), AJAR_INF, &hf));
		assert_true(hb.t == hf.t);
		assert_true(hb.tri == hf.tri || b.tris[hb.tri].p0.x == b.tris[hf.tri].p0.x);
		assert_true(bvh_occluded(&b.sc, o, v3_neg(ng), AJAR_INF));
	}
	built_free(&b);
	free(t);
}

/* Small spawn offsets: a ray leaving a hit point through ray_offset must
 * not hit the same triangle again, on either side. */
static void test_ray_offset(void **state)
{
	rng_state = 7;
	for (int k = 0; k < 20000; k++) {
		float s = powf(10.0f, rnd_range(-3.0f, 4.0f));
		V3 c = v3_scale(rnd_v3(v3(-1, -1, -1), v3(1, 1, 1)), s);
		Tri t = rnd_tri_around(c, s * 0.1f);
		V3 ng = tri_normal(&t);
		if (v3_len2(ng) == 0.0f)
			continue;
		float b1 = rnd() * 0.5f, b2 = rnd() * 0.5f;
		V3 p = v3_add(t.p0, v3_add(v3_scale(v3_sub(t.p1, t.p0), b1), v3_scale(v3_sub(t.p2, t.p0), b2)));
		V3 d = rnd_dir();
		V3 o = ray_offset(p, ng, d);
		RayPre r = ray_pre(o, d);
		float th, u, v;
		assert_false(tri_intersect(&r, &t, AJAR_INF, &th, &u, &v));
		/* and the offset is tiny relative to the scale */
		assert_true(v3_len(v3_sub(o, p)) < 1e-3f * fmaxf(1.0f, s));
	}
}

static double now_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A shipped scene against brute force; rays scaled down with the
 * triangle count so brute force stays around a second. */
static void check_scene(const char *path)
{
	rng_state = 8;
	Scene *s = NULL;
	ajar_status st = gltf_load(path, &s);
	if (st != AJAR_OK)
		fprintf(stderr, "%s: %s\n", path, ajar_last_error());
	assert_int_equal(st, AJAR_OK);
	uint32_t n = s->ntris;
	double t0 = now_seconds();
	Built b;
	built_make(s->tris, n, &b);
	double secs = now_seconds() - t0;
	check_structure(&b, n);
	uint32_t nrays = (uint32_t)(1e8 / n);
	nrays = nrays > 2000 ? 2000 : (nrays < 150 ? 150 : nrays);
	uint32_t hits = check_rays(&b, n, nrays);
	printf("  %-40s %6u tris %6u nodes depth %2u (wide %2u), %.3f s, %.1f MB: %u/%u rays hit\n", path,
	       n, b.bvh.nnodes, b.bvh.depth, b.bvh.wide_depth, secs, bvh_memory(&b.bvh) / 1048576.0, hits,
	       nrays);
	assert_true(hits > nrays / 4);
	built_free(&b);
	scene_free(s);
}

static void test_scene_cornell(void **state) { check_scene(SCENE("cornell/cornell.gltf")); }
static void test_scene_window_room(void **state) { check_scene(SCENE("window-room/window-room.gltf")); }
static void test_scene_living_room(void **state) { check_scene(SCENE("living-room/living-room.gltf")); }
static void test_scene_bathroom(void **state) { check_scene(SCENE("bathroom/bathroom.gltf")); }

/* The build on 1, 2, 3 and 8 threads, and twice on one: the same node
 * and order arrays, bit for bit (bvh_build.c). tris has n triangles. */
static void check_threads(const Tri *tris, uint32_t n, const char *name)
{
	Bvh ref;
	double t0 = now_seconds();
	assert_int_equal(bvh_build_threads(tris, n, 1, &ref), AJAR_OK);
	double secs = now_seconds() - t0;
	static const int threads[] = {1, 2, 3, 8};
	for (size_t k = 0; k < sizeof threads / sizeof threads[0]; k++) {
		Bvh b;
		assert_int_equal(bvh_build_threads(tris, n, threads[k], &b), AJAR_OK);
		assert_int_equal(b.nnodes, ref.nnodes);
		assert_int_equal(b.depth, ref.depth);
		assert_int_equal(b.wide_depth, ref.wide_depth);
		assert_memory_equal(b.nodes, ref.nodes, sizeof(BvhNode) * ref.nnodes);
		assert_memory_equal(b.order, ref.order, sizeof(uint32_t) * n);
		bvh_free(&b);
	}
	printf("  %-12s %6u tris %6u nodes: the same on 1, 2, 3, 8 threads (%.3f s on one)\n", name, n, ref.nnodes, secs);
	bvh_free(&ref);
}

/* Soups big enough that the top nodes are binned on several threads: one
 * uniform, one of clusters with many equal coordinates, zeros of both
 * signs among them (min and max must keep the first of equals whatever
 * thread saw it), and the shipped bathroom. Each tree also passes
 * check_structure. */
static void test_threads_same_tree(void **state)
{
	uint32_t n = 150000;
	Tri *t = malloc(sizeof(Tri) * n);
	assert_non_null(t);
	rng_state = 11;
	for (uint32_t i = 0; i < n; i++)
		t[i] = rnd_tri_around(rnd_v3(v3(0, 0, 0), v3(10, 1, 10)), rnd_range(0.001f, 0.1f));
	check_threads(t, n, "uniform");
	rng_state = 12;
	for (uint32_t i = 0; i < n; i++) {
		V3 c = v3((float)(rnd_u32() % 64), (float)(rnd_u32() % 4), (float)(rnd_u32() % 64));
		Tri tr = rnd_tri_around(c, 0.3f);
		float *f = &tr.p0.x;
		for (int k = 0; k < 9; k++)
			if (rnd_u32() % 4 == 0)
				f[k] = (rnd_u32() & 1) ? -0.0f : 0.0f;
		t[i] = tr;
	}
	check_threads(t, n, "zeros");
	Built b;
	built_make(t, n, &b);
	check_structure(&b, n);
	built_free(&b);
	free(t);
	Scene *s = NULL;
	assert_int_equal(gltf_load(SCENE("bathroom/bathroom.gltf"), &s), AJAR_OK);
	check_threads(s->tris, s->ntris, "bathroom");
	scene_free(s);
}

/* Alpha in ray queries: a unit quad at z = 0 (UVs = xy) with an 8 x 8
 * checker whose alpha is 0 or 1 (MASK, cutoff 0.5, nearest) lets a ray
 * through exactly where its texel is clear, for closest-hit and occlusion
 * queries alike (half the rays over its inner 6 x 6 texels); a BLEND quad of alpha 0.3
 * stops 30% of them (binomial, 4 sigma); an opaque quad's triangles get no
 * alpha flag. */
static void add_quad(Scene *s, float z, uint32_t mat)
{
	float pos[] = {0, 0, z, 1, 0, z, 1, 1, z, 0, 1, z};
	float uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_triangles(s, "quad", pos, NULL, uv, 4, idx, 2, mat), AJAR_OK);
}

static uint32_t add_alpha_material(Scene *s, int flags, float alpha, int tex)
{
	Material m;
	memset(&m, 0, sizeof m);
	m.base_color = v3(1, 1, 1);
	m.base_alpha = alpha;
	m.base_tex = tex;
	m.alpha_cutoff = 0.5f;
	m.roughness = 1.0f;
	m.ior = 1.5f;
	m.flags = flags;
	uint32_t id;
	assert_int_equal(scene_add_material(s, &m, &id), AJAR_OK);
	return id;
}

static void test_alpha(void **state)
{
	(void)state;
	rng_state = 23;
	Scene *s;
	assert_int_equal(scene_new("<test>", &s), AJAR_OK);
	uint8_t rgba[8 * 8 * 4];
	for (int i = 0; i < 64; i++) {
		rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = 200;
		rgba[4 * i + 3] = ((i % 8) + (i / 8)) % 2 ? 255 : 0;
	}
	uint32_t img, tex;
	assert_int_equal(scene_add_texture(s, 8, 8, rgba, &img), AJAR_OK);
	const float xf[6] = {1, 0, 0, 0, 1, 0};
	assert_int_equal(scene_add_texture_use(s, img, TEX_NEAREST, xf, &tex), AJAR_OK);
	uint32_t mask = add_alpha_material(s, MATERIAL_ALPHA_MASK, 1.0f, (int)tex);
	uint32_t blend = add_alpha_material(s, MATERIAL_ALPHA_BLEND, 0.3f, -1);
	uint32_t opaque = add_alpha_material(s, MATERIAL_ALPHA_BLEND, 1.0f, -1);
	add_quad(s, 0.0f, mask);
	add_quad(s, 5.0f, blend);
	add_quad(s, 9.0f, opaque);
	assert_true(s->tris[0].flags & TRI_ALPHA);
	assert_true(s->tris[2].flags & TRI_ALPHA);
	assert_false(s->tris[4].flags & TRI_ALPHA);
	Built b;
	built_make(s->tris, s->ntris, &b);
	TriShade shade[6];
	for (int i = 0; i < 6; i++)
		shade[i] = s->shade[b.bvh.order[i]];
	b.sc.shade = shade;
	b.sc.materials = s->materials;
	b.sc.textures = s->textures;
	b.sc.texels = s->texels;
	enum { N = 20000 };
	int through = 0, stopped_blend = 0;
	for (int k = 0; k < N; k++) {
		/* Rays up from below the mask, slightly tilted, crossing z = 0 at (x, y). */
		float x = rnd_range(0.125f, 0.875f), y = rnd_range(0.125f, 0.875f); /* whole texels */
		V3 d = v3_norm(v3(rnd_range(-0.01f, 0.01f), rnd_range(-0.01f, 0.01f), 1.0f));
		V3 o = v3_madd(v3(x, y, 0.0f), d, -1.0f / d.z);
		int ix = (int)fminf(x * 8, 7), iy = (int)fminf(y * 8, 7);
		int clear = (ix + iy) % 2 == 0;
		if (fabsf(x * 8 - roundf(x * 8)) < 1e-3f || fabsf(y * 8 - roundf(y * 8)) < 1e-3f) {
			k--; /* on a texel edge: either side is right */
			continue;
		}
		Hit h;
		int hit = bvh_intersect(&b.sc, o, d, 4.0f, &h);
		assert_int_equal(hit, !clear);
		assert_int_equal(bvh_occluded(&b.sc, o, d, 4.0f), !clear);
		if (hit)
			assert_float_equal(h.t, 1.0f / d.z, 1e-5f);
		through += clear;
		/* On through the BLEND quad (z = 5), stopped by the opaque one. */
		V3 o2 = v3_madd(v3(x, y, 4.0f), d, 0.0f);
		int hb = bvh_intersect(&b.sc, o2, d, AJAR_INF, &h);
		assert_true(hb);
		int at_blend = fabsf(o2.z + h.t * d.z - 5.0f) < 1e-3f;
		assert_int_equal(bvh_occluded(&b.sc, o2, d, 2.0f), at_blend);
		stopped_blend += at_blend;
	}
	printf("  mask: %d of %d through; blend: %d of %d stopped\n", through, N, stopped_blend, N);
	assert_true(fabs(through - 0.5 * N) < 4.0 * sqrt(0.25 * N));
	assert_true(fabs(stopped_blend - 0.3 * N) < 4.0 * sqrt(0.21 * N));
	built_free(&b);
	scene_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_single_triangle),
		cmocka_unit_test(test_uniform_soup),
		cmocka_unit_test(test_clustered_soup),
		cmocka_unit_test(test_coplanar_degenerate_soup),
		cmocka_unit_test(test_identical_triangles),
		cmocka_unit_test(test_depth_bounded),
		cmocka_unit_test(test_ray_offset),
		cmocka_unit_test(test_scene_cornell),
		cmocka_unit_test(test_scene_window_room),
		cmocka_unit_test(test_scene_living_room),
		cmocka_unit_test(test_scene_bathroom),
		cmocka_unit_test(test_alpha),
		cmocka_unit_test(test_threads_same_tree),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
