/* test_scene_share.c — one copy of the geometry (src/scene/scene_share.c,
 * src/prepare/scene_bvh.c): renderers prepared from one scene share its
 * triangles and BVH, built once; the scene's triangles are its BVH's leaf
 * order afterwards, each leaf's triangles inside the leaf's box; a scene
 * changed while a renderer holds the share gets arrays of its own and the
 * renderer keeps what it had; a scene destroyed first leaves the share to
 * the renderer. Host only (prepare_scene), under the sanitizers in
 * `make asan`. */
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

#include "geom/bvh.h"
#include "prepare/prepare.h"
#include "scene/scene_share.h"

static void prepare(Scene *s, SceneData *d)
{
	ajar_options o;
	ajar_options_default(&o);
	o.max_depth = 8;
	assert_int_equal(prepare_scene(s, &o, 8, 8, NULL, d), AJAR_OK);
}

/* Every leaf's triangles lie in its slot's box, and every triangle is in
 * one leaf: the triangles are in the BVH's order. */
static void check_leaf_order(const SceneData *d)
{
	uint32_t *seen = calloc(d->n_tris, sizeof *seen);
	assert_non_null(seen);
	for (size_t i = 0; i < d->n_nodes; i++)
		for (int k = 0; k < BVH_WIDTH; k++) {
			int c = d->nodes[i].child[k];
			if (c >= 0 || c == BVH_EMPTY)
				continue;
			const BvhNode *n = &d->nodes[i];
			for (int t = BVH_LEAF_FIRST(c); t < BVH_LEAF_FIRST(c) + BVH_LEAF_COUNT(c); t++) {
				const V3 *p = &d->tris[t].p0;
				for (int j = 0; j < 3; j++) {
					assert_true(p[j].x >= n->lo_x[k] && p[j].x <= n->hi_x[k]);
					assert_true(p[j].y >= n->lo_y[k] && p[j].y <= n->hi_y[k]);
					assert_true(p[j].z >= n->lo_z[k] && p[j].z <= n->hi_z[k]);
				}
				seen[t]++;
			}
		}
	for (size_t t = 0; t < d->n_tris; t++)
		assert_int_equal(seen[t], 1);
	free(seen);
}

static void test_renderers_share(void **state)
{
	Scene *s;
	assert_int_equal(ajar_scene_load(SCENE("living-room/living-room.gltf"), &s), AJAR_OK);
	SceneData a, b;
	prepare(s, &a);
	assert_ptr_equal(a.tris, s->tris);
	assert_ptr_equal(a.shade, s->shade);
	check_leaf_order(&a);
	double built = a.bvh_seconds;
	prepare(s, &b);
	/* The same arrays and the same BVH: built once. */
	assert_ptr_equal(b.tris, a.tris);
	assert_ptr_equal(b.nodes, a.nodes);
	assert_true(b.bvh_seconds == built);
	assert_int_equal(atomic_load(&s->share->refs), 3);
	/* The scene goes first; the renderers keep the arrays. */
	ajar_scene_destroy(&s);
	check_leaf_order(&a);
	prepare_free(&a);
	check_leaf_order(&b);
	prepare_free(&b);
}

static void test_changed_scene(void **state)
{
	Scene *s;
	assert_int_equal(ajar_scene_load(SCENE("cornell/cornell.gltf"), &s), AJAR_OK);
	uint32_t n = s->ntris;
	SceneData a;
	prepare(s, &a);
	Tri *before = malloc(sizeof *before * n);
	memcpy(before, a.tris, sizeof *before * n);
	/* A mesh added while a renderer holds the share: the scene copies. */
	static const float p[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	ajar_mesh m = {p, NULL, NULL, 3, NULL, 1, 0, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &m), AJAR_OK);
	assert_null(s->share);
	assert_ptr_not_equal(s->tris, a.tris);
	assert_int_equal(s->ntris, n + 1);
	assert_memory_equal(a.tris, before, sizeof *before * n);
	SceneData b;
	prepare(s, &b);
	assert_int_equal(b.n_tris, n + 1);
	check_leaf_order(&b);
	prepare_free(&a);
	prepare_free(&b);
	/* No renderer holds it now: the scene takes its arrays back. */
	Tri *mine = s->tris;
	assert_int_equal(ajar_scene_add_mesh(s, &m), AJAR_OK);
	assert_null(s->share);
	assert_ptr_equal(s->tris, mine);
	assert_int_equal(s->ntris, n + 2);
	free(before);
	ajar_scene_destroy(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_renderers_share),
		cmocka_unit_test(test_changed_scene),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
