/* test_instances.c — instances against their flattened copies, on the host
 * with the kernels' own traversal and surface code (kernels/geom/):
 * tests/support/instance_scenes.c's room (non-uniform scale, mirroring,
 * nested nodes, EXT_mesh_gpu_instancing TRS, an emitting lamp mesh) and
 * the Khronos NormalTangentMirrorTest turned, scaled and mirrored (normal
 * maps: tangents and the bitangent's sign), each loaded with every mesh
 * kept as instances and with every copy flattened: the same hits at the
 * same distances, the same points, normals, shading normals and texture
 * coordinates; the two-level BVH's invariants; the same tree on any number
 * of threads; the loader's counts and its rule; malformed
 * EXT_mesh_gpu_instancing refused. */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/surface.h"
#include "instance_scenes.h"
#include "prepare/prepare.h"
#include "scene/gltf.h"

static Scene *load(const char *path, int instancing, int outside)
{
	Scene *s = NULL;
	if (gltf_load_instancing(path, outside, instancing, &s) != AJAR_OK)
		fail_msg("%s: %s", path, ajar_last_error());
	return s;
}

static void prepare(Scene *s, SceneData *d, SceneView *v)
{
	ajar_options o;
	ajar_options_default(&o);
	o.max_depth = 8;
	if (prepare_scene(s, &o, 16, 16, NULL, d) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
#define VIEW(type, name) v->name = d->name;
	AJAR_SCENE_BUFFERS(VIEW)
#undef VIEW
}

static uint64_t rng = 1;
static float rnd(void)
{
	rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
	return (float)(rng >> 40) * (1.0f / 16777216.0f);
}

static int close3(V3 a, V3 b, float tol)
{
	return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

/* Rays from random points of [lo, hi], in random directions or, every
 * other one, at a random point of a random triangle of b (flattened:
 * world space, ntris of them), through both scenes: hits and misses agree, distances within 1e-4 relative, and the
 * surfaces found match; a few rays grazing an edge may find a neighbour
 * (float rounding differs between a transformed ray and transformed
 * vertices), at most 0.5%. */
static void same_surfaces(const char *what, const SceneView *a, const SceneView *b, uint32_t ntris, V3 lo, V3 hi,
			  int nrays)
{
	int differ = 0, hits = 0;
	double worst_ns = 1.0;
	for (int k = 0; k < nrays; k++) {
		V3 o = v3(lo.x + (hi.x - lo.x) * rnd(), lo.y + (hi.y - lo.y) * rnd(), lo.z + (hi.z - lo.z) * rnd());
		float z = 1 - 2 * rnd(), phi = 6.2831853f * rnd(), r = sqrtf(fmaxf(0.0f, 1 - z * z));
		V3 d = v3(r * cosf(phi), r * sinf(phi), z);
		if (k & 1) {
			const Tri *t = &b->tris[(uint32_t)(rnd() * (float)ntris) % ntris];
			float b1 = rnd(), b2 = rnd();
			if (b1 + b2 > 1.0f) {
				b1 = 1.0f - b1;
				b2 = 1.0f - b2;
			}
			V3 q = v3_add(t->p0, v3_add(v3_scale(v3_sub(t->p1, t->p0), b1), v3_scale(v3_sub(t->p2, t->p0), b2)));
			if (v3_len2(v3_sub(q, o)) > 0.0f)
				d = v3_norm(v3_sub(q, o));
		}
		Hit ha, hb;
		int fa = bvh_intersect(a, o, d, AJAR_INF, &ha), fb = bvh_intersect(b, o, d, AJAR_INF, &hb);
		if (fa != fb || (fa && fabsf(ha.t - hb.t) > 1e-4f * (1.0f + ha.t))) {
			differ++;
			continue;
		}
		if (!fa)
			continue;
		hits++;
		Surface sa, sb;
		surface_from_hit(a, &ha, &sa);
		surface_from_hit(b, &hb, &sb);
		float tol = 1e-4f * (1.0f + ha.t);
		if (!close3(sa.p, sb.p, tol) || v3_dot(sa.ng, sb.ng) < 0.9999f || fabsf(sa.tu - sb.tu) > 1e-3f ||
		    fabsf(sa.tv - sb.tv) > 1e-3f || sa.material != sb.material) {
			differ++;
			continue;
		}
		worst_ns = fmin(worst_ns, v3_dot(sa.ns, sb.ns));
		if (v3_dot(sa.ns, sb.ns) < 0.999f)
			differ++;
#if !defined(AJAR_NO_LAYERS) || !defined(AJAR_NO_ANISOTROPY)
		/* The tangent frame anisotropy and the clear coat's map read. */
		else if (sa.tsign != sb.tsign || (sa.tsign != 0.0f && v3_dot(sa.tan, sb.tan) < 0.999f))
			differ++;
#endif
		/* The same occlusion a little before the hit and past it. */
		assert_int_equal(bvh_occluded(a, o, d, ha.t * 0.99f), bvh_occluded(b, o, d, ha.t * 0.99f));
	}
	printf("  %-28s %d rays, %d hit, %d differ; worst shading-normal cosine %.6f\n", what, nrays, hits, differ,
	       worst_ns);
	assert_true(hits > nrays / 2);
	assert_true(differ <= nrays / 200);
}

static void test_room(void **state)
{
	write_instance_scene(test_dir, "room");
	char *path = test_path(test_dir, "room.gltf");
	Scene *si = load(path, GLTF_INSTANCING_ALL, 0), *sf = load(path, GLTF_INSTANCING_NONE, 0);
	SceneData di, df;
	SceneView vi, vf;
	prepare(si, &di, &vi);
	prepare(sf, &df, &vf);
	assert_true(si->ninstances == 11 && sf->ninstances == 0);
	assert_true(!(di.kernel_omit & KERNEL_OMIT_INSTANCES) && (df.kernel_omit & KERNEL_OMIT_INSTANCES));
	/* The same lights: the lamps' emitting quads are world-space copies. */
	assert_int_equal(di.n_emitters, df.n_emitters);
	assert_int_equal(di.lights.nemitters, 4);
	assert_true(fabsf(di.params->emitter_power - df.params->emitter_power) <= 1e-5f * df.params->emitter_power);
	same_surfaces("room", &vi, &vf, (uint32_t)df.n_tris, v3(0.05f, 0.05f, 0.05f), v3(3.95f, 2.95f, 3.95f), 40000);
	prepare_free(&di);
	prepare_free(&df);
	scene_free(si);
	scene_free(sf);
	free(path);
}

/* NormalTangentMirrorTest under a turned, non-uniformly scaled, mirroring
 * node (a copy of its glTF with absolute URIs, read with outside files
 * allowed). */
static void test_normal_maps(void **state)
{
	const char *dir = SCENE("khronos/NormalTangentMirrorTest");
	char src[512], *abs = NULL;
	snprintf(src, sizeof src, "%s/NormalTangentMirrorTest.gltf", dir);
	FILE *f = fopen(src, "rb");
	assert_non_null(f);
	static char text[1 << 16], out[1 << 16];
	size_t n = fread(text, 1, sizeof text - 1, f);
	fclose(f);
	text[n] = '\0';
	abs = realpath(dir, NULL);
	assert_non_null(abs);
	char *o = out;
	for (const char *p = text; *p;) {
		if (!strncmp(p, "\"uri\" : \"", 9)) {
			o += sprintf(o, "\"uri\" : \"%s/", abs);
			p += 9;
		} else if (!strncmp(p, "\"mesh\" : 0,", 11)) {
			o += sprintf(o, "\"mesh\" : 0, \"scale\" : [-1.2, 0.8, 1.5], \"rotation\" : [0.2, 0.3, 0.1, 0.92736],");
			p += 11;
		} else {
			*o++ = *p++;
		}
	}
	*o = '\0';
	free(abs);
	char *path = test_path(test_dir, "ntm.gltf");
	f = fopen(path, "wb");
	fputs(out, f);
	fclose(f);
	Scene *si = load(path, GLTF_INSTANCING_ALL, 1), *sf = load(path, GLTF_INSTANCING_NONE, 1);
	assert_int_equal(si->ninstances, 1);
	SceneData di, df;
	SceneView vi, vf;
	prepare(si, &di, &vi);
	prepare(sf, &df, &vf);
	assert_true(!(df.kernel_omit & KERNEL_OMIT_BENT_NORMALS)); /* normal-mapped */
	same_surfaces("NormalTangentMirrorTest", &vi, &vf, (uint32_t)df.n_tris, df.bmin, df.bmax, 20000);
	prepare_free(&di);
	prepare_free(&df);
	scene_free(si);
	scene_free(sf);
	free(path);
}

static int box_in(const BvhNode *n, int k, V3 lo, V3 hi)
{
	return n->lo_x[k] <= lo.x && n->lo_y[k] <= lo.y && n->lo_z[k] <= lo.z && n->hi_x[k] >= hi.x &&
	       n->hi_y[k] >= hi.y && n->hi_z[k] >= hi.z;
}

/* Walks the tree under node `root`: leaves' triangles inside their boxes
 * and counted in seen[], instance slots counted in iseen[] (their boxes
 * bounding the instance's world bounds), children's boxes inside their
 * slot's. */
static void walk(const SceneData *d, const Scene *s, int root, uint32_t *seen, uint32_t *iseen)
{
	int stack[256], sp = 0;
	stack[sp++] = root;
	while (sp > 0) {
		const BvhNode *n = &d->nodes[stack[--sp]];
		for (int k = 0; k < BVH_WIDTH; k++) {
			int c = n->child[k];
			if (c == BVH_EMPTY)
				continue;
			if (c >= BVH_INSTANCE_BASE) {
				uint32_t j = (uint32_t)(c - BVH_INSTANCE_BASE);
				assert_true(iseen && j < s->ninstances);
				iseen[j]++;
				V3 mlo, mhi, lo, hi;
				scene_mesh_bounds(s, s->instances[j].mesh, &mlo, &mhi);
				scene_instance_bounds(&s->instances[j], mlo, mhi, &lo, &hi);
				assert_true(box_in(n, k, lo, hi));
			} else if (c < 0) {
				for (int t = BVH_LEAF_FIRST(c); t < BVH_LEAF_FIRST(c) + BVH_LEAF_COUNT(c); t++) {
					const Tri *tr = &d->tris[t];
					assert_true(box_in(n, k, v3_min(tr->p0, v3_min(tr->p1, tr->p2)),
							   v3_max(tr->p0, v3_max(tr->p1, tr->p2))));
					seen[t]++;
				}
			} else {
				const BvhNode *ch = &d->nodes[c];
				for (int q = 0; q < BVH_WIDTH; q++)
					if (ch->child[q] != BVH_EMPTY)
						assert_true(box_in(n, k, v3(ch->lo_x[q], ch->lo_y[q], ch->lo_z[q]),
								   v3(ch->hi_x[q], ch->hi_y[q], ch->hi_z[q])));
				assert_true(sp < 256);
				stack[sp++] = c;
			}
		}
	}
}

/* The two-level BVH: the flat triangles first, each in one top-level
 * leaf; every instance in one top-level slot, its Instance's root its
 * mesh's tree, in which each of the mesh's triangles lies in one leaf;
 * boxes nested. Two loads build the same arrays, bit for bit. */
static void test_two_level_structure(void **state)
{
	write_instance_scene(test_dir, "room");
	char *path = test_path(test_dir, "room.gltf");
	Scene *s = load(path, GLTF_INSTANCING_ALL, 0), *s2 = load(path, GLTF_INSTANCING_ALL, 0);
	SceneData d, d2;
	SceneView v, v2;
	prepare(s, &d, &v);
	prepare(s2, &d2, &v2);
	uint32_t nflat = scene_flat_triangles(s);
	uint32_t *seen = calloc(s->ntris, sizeof *seen), *iseen = calloc(s->ninstances, sizeof *iseen);
	walk(&d, s, 0, seen, iseen);
	for (uint32_t t = 0; t < s->ntris; t++)
		assert_int_equal(seen[t], t < nflat);
	for (uint32_t j = 0; j < s->ninstances; j++) {
		assert_int_equal(iseen[j], 1);
		assert_int_equal(d.instances[j].root, d.share->mesh_root[s->instances[j].mesh]);
	}
	for (uint32_t m = 0; m < s->nmeshes; m++) {
		const SceneMesh *mesh = &s->meshes[m];
		assert_true(mesh->first >= nflat);
		memset(seen, 0, sizeof *seen * s->ntris);
		walk(&d, s, d.share->mesh_root[m], seen, NULL);
		for (uint32_t t = 0; t < s->ntris; t++)
			assert_int_equal(seen[t], t >= mesh->first && t < mesh->first + mesh->count);
	}
	assert_int_equal(d.n_nodes, d2.n_nodes);
	assert_memory_equal(d.nodes, d2.nodes, sizeof *d.nodes * d.n_nodes);
	assert_memory_equal(d.tris, d2.tris, sizeof *d.tris * d.n_tris);
	assert_memory_equal(d.instances, d2.instances, sizeof *d.instances * d.n_instances);
	free(seen);
	free(iseen);
	prepare_free(&d);
	prepare_free(&d2);
	scene_free(s);
	scene_free(s2);
	free(path);
}

/* A random top level's invariants: every triangle in one leaf (its box
 * inside the slot's), every instance in one slot of its own (its box
 * inside), children's boxes inside their slot's. */
static void check_top_level(const Bvh *b, const Tri *t, uint32_t nt, const V3 *lo, const V3 *hi, uint32_t ni)
{
	uint32_t *seen = calloc(nt, sizeof *seen), *iseen = calloc(ni, sizeof *iseen);
	for (uint32_t i = 0; i < b->nnodes; i++) {
		const BvhNode *n = &b->nodes[i];
		for (int k = 0; k < BVH_WIDTH; k++) {
			int c = n->child[k];
			if (c == BVH_EMPTY)
				continue;
			if (c >= BVH_INSTANCE_BASE) {
				uint32_t j = (uint32_t)(c - BVH_INSTANCE_BASE);
				assert_true(j < ni);
				iseen[j]++;
				assert_true(box_in(n, k, lo[j], hi[j]));
			} else if (c < 0) {
				for (int q = BVH_LEAF_FIRST(c); q < BVH_LEAF_FIRST(c) + BVH_LEAF_COUNT(c); q++) {
					assert_true((uint32_t)q < nt);
					const Tri *tr = &t[b->order[q]];
					assert_true(box_in(n, k, v3_min(tr->p0, v3_min(tr->p1, tr->p2)),
							   v3_max(tr->p0, v3_max(tr->p1, tr->p2))));
					seen[b->order[q]]++;
				}
			} else {
				assert_true((uint32_t)c > i && (uint32_t)c < b->nnodes);
				const BvhNode *ch = &b->nodes[c];
				for (int q = 0; q < BVH_WIDTH; q++)
					if (ch->child[q] != BVH_EMPTY)
						assert_true(box_in(n, k, v3(ch->lo_x[q], ch->lo_y[q], ch->lo_z[q]),
								   v3(ch->hi_x[q], ch->hi_y[q], ch->hi_z[q])));
			}
		}
	}
	for (uint32_t i = 0; i < nt; i++)
		assert_int_equal(seen[i], 1);
	for (uint32_t j = 0; j < ni; j++)
		assert_int_equal(iseen[j], 1);
	free(seen);
	free(iseen);
}

/* A top level of 60,000 triangles and 2,000 instance boxes: its
 * invariants, and the same nodes and order on 1, 2, 3 and 8 threads. */
static void test_threads_with_instances(void **state)
{
	uint32_t nt = 60000, ni = 2000;
	Tri *t = calloc(nt, sizeof *t);
	V3 *lo = malloc(sizeof *lo * ni), *hi = malloc(sizeof *hi * ni);
	rng = 5;
	for (uint32_t i = 0; i < nt; i++) {
		V3 c = v3(10 * rnd(), 10 * rnd(), 10 * rnd());
		t[i].p0 = c;
		t[i].p1 = v3(c.x + 0.05f * rnd(), c.y + 0.05f * rnd(), c.z);
		t[i].p2 = v3(c.x, c.y + 0.05f * rnd(), c.z + 0.05f * rnd());
	}
	for (uint32_t j = 0; j < ni; j++) {
		lo[j] = v3(10 * rnd(), 10 * rnd(), 10 * rnd());
		hi[j] = v3(lo[j].x + rnd(), lo[j].y + rnd(), lo[j].z + rnd());
	}
	BvhInput in = {t, NULL, nt, lo, hi, nt + ni, 0};
	Bvh ref;
	memset(&ref, 0, sizeof ref);
	assert_int_equal(bvh_build_input(&in, 1, NULL, NULL, &ref), AJAR_OK);
	check_top_level(&ref, t, nt, lo, hi, ni);
	static const int threads[] = {2, 3, 8};
	for (size_t k = 0; k < 3; k++) {
		Bvh b;
		memset(&b, 0, sizeof b);
		assert_int_equal(bvh_build_input(&in, threads[k], NULL, NULL, &b), AJAR_OK);
		assert_int_equal(b.nnodes, ref.nnodes);
		assert_memory_equal(b.nodes, ref.nodes, sizeof *b.nodes * b.nnodes);
		assert_memory_equal(b.order, ref.order, sizeof *b.order * nt);
		bvh_free(&b);
	}
	bvh_free(&ref);
	free(t);
	free(lo);
	free(hi);
}

/* What the loader keeps: counts as drawn, the emitting lamps flattened,
 * the rule keeping few small copies flat. */
static void test_loader_counts(void **state)
{
	write_instance_scene(test_dir, "room");
	char *path = test_path(test_dir, "room.gltf");
	Scene *si = load(path, GLTF_INSTANCING_ALL, 0), *sf = load(path, GLTF_INSTANCING_NONE, 0),
	      *sa = load(path, GLTF_INSTANCING_AUTO, 0);
	ajar_scene_info ii, fi, ai;
	assert_int_equal(ajar_scene_info_get(si, &ii), AJAR_OK);
	assert_int_equal(ajar_scene_info_get(sf, &fi), AJAR_OK);
	assert_int_equal(ajar_scene_info_get(sa, &ai), AJAR_OK);
	assert_true(ii.triangles == fi.triangles && ai.triangles == fi.triangles);
	assert_true(fi.unique_triangles == fi.triangles && ii.unique_triangles < fi.triangles / 3);
	/* the room (1), the ball (8 copies: five nodes, three GPU instances), the lamps' shade (2) */
	assert_int_equal(ii.instances, 11);
	assert_int_equal(fi.instances, 0);
	assert_int_equal(ai.instances, 0); /* a 168-triangle ball 8 times: flat (gltf_mesh_instanced) */
	assert_int_equal(ii.emissive_triangles, 4);
	assert_int_equal(fi.emissive_triangles, 4);
	for (int c = 0; c < 3; c++) {
		assert_true(fabsf(ii.bounds_min[c] - fi.bounds_min[c]) < 1e-4f);
		assert_true(fabsf(ii.bounds_max[c] - fi.bounds_max[c]) < 1e-4f);
	}
	scene_free(si);
	scene_free(sf);
	scene_free(sa);
	free(path);
}

/* EXT_mesh_gpu_instancing with attributes of different counts, or none. */
static void test_gpu_instancing_errors(void **state)
{
	write_instance_scene(test_dir, "room");
	char *path = test_path(test_dir, "room.gltf"), *bad = test_path(test_dir, "bad.gltf");
	FILE *f = fopen(path, "rb");
	static char text[1 << 16];
	size_t n = fread(text, 1, sizeof text - 1, f);
	fclose(f);
	text[n] = '\0';
	/* SCALE names the room's index accessor: 66 elements, not 3. */
	char *p = strstr(text, "\"SCALE\":");
	assert_non_null(p);
	char out[1 << 16];
	snprintf(out, sizeof out, "%.*s\"SCALE\":3%s", (int)(p - text), text, strchr(p, '}'));
	f = fopen(bad, "wb");
	fputs(out, f);
	fclose(f);
	Scene *s = NULL;
	assert_int_not_equal(gltf_load_instancing(bad, 0, GLTF_INSTANCING_AUTO, &s), AJAR_OK);
	assert_non_null(strstr(ajar_last_error(), "nodes[4]: EXT_mesh_gpu_instancing"));
	snprintf(out, sizeof out, "%.*s\"SCALE_\":2%s", (int)(p - text), text, strchr(p, '}'));
	char *q = strstr(out, "\"TRANSLATION\":");
	memcpy(q, "\"TRANSLATIO_\"", 13);
	q = strstr(out, "\"ROTATION\":");
	memcpy(q, "\"ROTATIO_\"", 10);
	f = fopen(bad, "wb");
	fputs(out, f);
	fclose(f);
	assert_int_equal(gltf_load_instancing(bad, 0, GLTF_INSTANCING_AUTO, &s), AJAR_ERROR_BAD_INPUT);
	assert_non_null(strstr(ajar_last_error(), "no TRANSLATION, ROTATION or SCALE"));
	free(path);
	free(bad);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_room),
		cmocka_unit_test(test_normal_maps),
		cmocka_unit_test(test_two_level_structure),
		cmocka_unit_test(test_threads_with_instances),
		cmocka_unit_test(test_loader_counts),
		cmocka_unit_test(test_gpu_instancing_errors),
	};
	return cmocka_run_group_tests(tests, test_group_setup, test_group_teardown);
}
