/* test_bdpt.c — bidirectional path tracing, checked on the host with the
 * kernels' own code (tests/support/kernel_host.h):
 *   - MIS records: for random paths in the shipped scenes and a scene with
 *     glass, mirrors, an emitter and the sky, the densities bdpt_mis_path
 *     builds for a strategy equal those an independent oracle computes from
 *     the path's geometry, and the weights of all strategies that can
 *     produce the path sum to 1, for the power and the balance heuristic;
 *   - each strategy alone, unweighted, converges to the path tracer's image
 *     of paths of exactly its length; light tracing alone (t = 1) too;
 *   - the weighted strategy layers sum to the image;
 *   - the weights with a light subpath's pn_0 cache are those without it,
 *     bit for bit, and those from the subpaths' MIS tails and the
 *     connection's own densities equal the whole path's up to rounding;
 *   - bdpt and pt agree.
 * Statistics: image means from B independent batches (different seeds);
 * the batch spread gives the standard error, and a difference must stay
 * within Z standard errors (Student t with B - 1 degrees of freedom). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernel_host.h"
#include "mis_oracle.h"
#include "testutil.h"

/* Random paths of every strategy in one scene: records against the
 * oracle, and the sum of weights. Returns how many paths were checked. */
static int check_mis(HostScene *h, int nsamples)
{
	SceneView *sc = &h->view;
	Params *prm = h->data.params;
	PathVertex l[SUBPATH_MAX], e[SUBPATH_MAX], x[2 * SUBPATH_MAX];
	int dl[2 * SUBPATH_MAX];
	MisVertex rec[2 * SUBPATH_MAX], orc[2 * SUBPATH_MAX], rcp[2 * SUBPATH_MAX];
	int checked = 0, with_delta = 0, with_env = 0, records = 0, off = 0;
	int depth = prm->max_depth;
	for (int n = 0; n < nsamples; n++) {
		Rng rng = rng_init(99, (uint)n, 0, 7);
		float px = rng_f(&rng) * prm->camera.width, py = rng_f(&rng) * prm->camera.height;
		int nl = bdpt_light_subpath(sc, l, depth, &rng);
		int ne = bdpt_eye_subpath(sc, px, py, e, depth + 1, &rng);
		for (int s = 0; s <= nl; s++) {
			for (int t = 1; t <= ne; t++) {
				int k = s + t;
				if (k - 1 > depth || (s == 0 && t < 2))
					continue;
				if (s == 0) {
					const PathVertex *z = &e[t - 1];
					if (!(z->type == VERTEX_ENV || (z->tri >= 0 && sc->tris[z->tri].emitter >= 0)))
						continue;
					if (v3_is_zero(bdpt_emitted(sc, z, z->wo)))
						continue;
				} else {
					if ((vertex_infinite(&l[s - 1]) || (s == 1 && vertex_delta_light(&l[0]))) && t == 1)
						continue;
					if (e[t - 1].type == VERTEX_ENV)
						continue;
					/* Both ends must scatter toward each other. */
					if (s >= 2) {
						V3 w = v3_norm(v3_sub(e[t - 1].p, l[s - 1].p));
						if (v3_is_zero(bdpt_scatter(&l[s - 1], w, BSDF_IMPORTANCE)))
							continue;
					}
					if (t >= 2 && v3_is_zero(bdpt_scatter(&e[t - 1], oracle_dir(&e[t - 1], &l[s - 1]),
									   BSDF_RADIANCE)))
						continue;
				}
				/* The path and its delta flags. */
				for (int i = 0; i < s; i++) {
					x[i] = l[i];
					dl[i] = l[i].delta;
				}
				for (int j = 0; j < t; j++) {
					x[k - 1 - j] = e[j];
					dl[k - 1 - j] = e[j].delta;
				}
				if (s > 0)
					dl[s - 1] = 0;
				dl[s] = 0;
				dl[0] = 0;
				if (s == 0 && x[0].type != VERTEX_ENV)
					x[0].type = VERTEX_LIGHT;
				bdpt_mis_path(sc, l, s, e, t, rec, 0);
				/* and with the connection's densities as its evaluation finds them */
				BdptConnPdf cp;
				if (s >= 1 && t >= 2) {
					V3 w = oracle_dir(&e[t - 1], &l[s - 1]);
					bdpt_scatter_pdf(&e[t - 1], w, BSDF_RADIANCE, &cp.e_fwd);
					cp.e_rev = bdpt_rev_pdf(&e[t - 1], w);
				}
				if (s >= 2) {
					V3 w = v3_norm(v3_sub(e[t - 1].p, l[s - 1].p));
					bdpt_scatter_pdf(&l[s - 1], w, BSDF_IMPORTANCE, &cp.l_fwd);
					cp.l_rev = bdpt_rev_pdf(&l[s - 1], w);
				}
				bdpt_mis_records(sc, l, s, e, t, rcp, 0, NULL, 0, s > 0 ? &cp : NULL);
				oracle(sc, x, dl, k, orc);
				for (int i = 0; i < k; i++) {
					if (i == k - 1 || (i == 0 && t == k))
						continue; /* camera's pf, and pr of ... never used */
					for (int w = 0; w < 2; w++) {
						const MisVertex *r = w ? &rcp[i] : &rec[i];
						double diff = fmax(rel_diff(r->pf, orc[i].pf), rel_diff(r->pr, orc[i].pr));
						if (i == 0)
							diff = fmax(diff, rel_diff(r->pn, orc[0].pn));
						records++;
						off += diff > 1e-2;
						if ((diff > 0.1 && !near_contact(x, k, i, prm->scene_radius)) ||
						    r->delta != orc[i].delta)
							fail_msg("strategy (s=%d, t=%d), vertex %d of %d: kernel pf %g pr %g delta "
								 "%d (%s), oracle pf %g pr %g delta %d",
								 s, t, i, k, r->pf, r->pr, r->delta,
								 w ? "connection's densities" : "recomputed", orc[i].pf, orc[i].pr,
								 orc[i].delta);
					}
				}
				/* over every strategy, and over the sets that connect eye
				 * vertices to the first 1 or 2 light vertices only */
				for (int conn = 0; conn <= 2; conn++) {
					int limit = mis_conn_limit(conn, mis_first_scatter(orc, k));
					if (!mis_conn_in_set(limit, k, s))
						continue;
					for (int heur = 0; heur < 2; heur++) {
						double sum = 0;
						for (int s2 = 0; s2 < k; s2++)
							if (strategy_valid(orc, k, s2) && mis_conn_in_set(limit, k, s2))
								sum += mis_path_weight_conn(orc, k, s2, heur, limit);
						if (fabs(sum - 1) > 1e-4)
							fail_msg("strategy (%d,%d): weights sum to %.7f (heuristic %d, "
								 "connections to %d light vertices)",
								 s, t, sum, heur, conn);
					}
				}
				checked++;
				for (int i = 0; i < k; i++)
					with_delta += orc[i].delta;
				with_env += x[0].type == VERTEX_ENV;
			}
		}
	}
	print_message("%d paths checked, %d delta vertices, %d from the environment; %d of %d records "
		      "beyond 1%%\n", checked, with_delta, with_env, off, records);
	assert_true(off <= records / 100);
	return checked;
}

static void test_mis_cornell(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("cornell/cornell.gltf"), NULL, 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(check_mis(&h, 300) > 1000);
	host_scene_close(&h);
}

static void test_mis_window_room(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("window-room/window-room.gltf"), NULL, 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(check_mis(&h, 300) > 300);
	host_scene_close(&h);
}

/* Glass, a mirror, a glossy metal, an emitter and the sky. */
static Scene *glossy_scene(void)
{
	ajar_scene *s;
	ajar_material m;
	uint32_t diffuse, glass, mirror, metal, light;
	const float sky[3] = {0.4f, 0.5f, 0.7f};
	assert_int_equal(ajar_scene_create(&s), AJAR_OK);
	ajar_material_default(&m);
	assert_int_equal(ajar_scene_add_material(s, &m, &diffuse), AJAR_OK);
	m.transmission = 1;
	m.roughness = 0;
	m.specular = 1;
	assert_int_equal(ajar_scene_add_material(s, &m, &glass), AJAR_OK);
	ajar_material_default(&m);
	m.metallic = 1;
	m.roughness = 0;
	assert_int_equal(ajar_scene_add_material(s, &m, &mirror), AJAR_OK);
	m.roughness = 0.4f;
	assert_int_equal(ajar_scene_add_material(s, &m, &metal), AJAR_OK);
	ajar_material_default(&m);
	m.emission[0] = m.emission[1] = m.emission[2] = 5;
	assert_int_equal(ajar_scene_add_material(s, &m, &light), AJAR_OK);
	/* floor, two walls, a glass slab, a light facing down */
	static const float floor_p[] = {-2, 0, -2, 2, 0, -2, 2, 0, 2, -2, 0, 2};
	static const float wall_p[] = {-2, 0, -2, -2, 2, -2, 2, 2, -2, 2, 0, -2};
	static const float side_p[] = {2, 0, -2, 2, 2, -2, 2, 2, 2, 2, 0, 2};
	static const float slab_p[] = {-1, 0.2f, 0, 0, 0.2f, 0, 0, 1.2f, 0, -1, 1.2f, 0};
	static const float light_p[] = {-0.5f, 1.9f, -1, -0.5f, 1.9f, 0, 0.5f, 1.9f, 0, 0.5f, 1.9f, -1};
	static const uint32_t quad[] = {0, 2, 1, 0, 3, 2}, quad_ccw[] = {0, 1, 2, 0, 2, 3};
	ajar_mesh mesh = {floor_p, NULL, NULL, 4, quad, 2, diffuse, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	mesh.positions = wall_p;
	mesh.material = mirror;
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	mesh.positions = side_p;
	mesh.material = metal;
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	mesh.positions = slab_p;
	mesh.material = glass;
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	mesh.positions = light_p;
	mesh.indices = quad_ccw;
	mesh.material = light;
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	assert_int_equal(ajar_scene_set_environment_color(s, sky), AJAR_OK);
	ajar_camera cam = {{0.5f, 1.0f, 3.5f}, {0, 0.7f, 0}, {0, 1, 0}, 1.0f, 0};
	assert_int_equal(ajar_scene_set_camera(s, &cam), AJAR_OK);
	return s;
}

static void test_mis_glossy_glass_sky(void **state)
{
	HostScene h;
	host_scene_open(&h, NULL, glossy_scene(), 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(check_mis(&h, 800) > 1000);
	host_scene_close(&h);
}

/* Glazed windows: every path that crosses a pane does so by a null event
 * (no vertex), and its records are those of the whole edge; paths that
 * reflect off a pane have a delta vertex on it. Window-room with a pane
 * under its constant sky, and window-room-forest glazed under its sun. */
static void test_mis_glazed(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("window-room/window-room-glazed.gltf"), NULL, 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(h.data.params->num_panes == 2);
	assert_true(check_mis(&h, 300) > 300);
	host_scene_close(&h);
	host_scene_open(&h, SCENE("window-room-forest/window-room-forest-glazed.gltf"), NULL, 32, 32, INTEGRATOR_BDPT,
			8);
	assert_true(check_mis(&h, 300) > 300);
	host_scene_close(&h);
}

static void test_mis_living_room(void **state)
{
	HostScene h;
	host_scene_open(&h, SCENE("living-room/living-room.gltf"), NULL, 32, 18, INTEGRATOR_BDPT, 8);
	assert_true(check_mis(&h, 600) > 300);
	host_scene_close(&h);
}

/* ---- Punctual lights ---------------------------------------------------- */

/* Adds a point light, a spot and a directional light (colours, a range)
 * to scene `s`, placed for a room of about `size` with its floor at 0
 * around (cx, cz); `emitters` 0 removes the emission of every material. */
static Scene *with_punctual(Scene *s, float cx, float cz, float size, int emitters)
{
	ajar_light l;
	ajar_light_default(&l);
	l.position[0] = cx - 0.2f * size;
	l.position[1] = 0.6f * size;
	l.position[2] = cz;
	l.color[1] = 0.7f;
	l.intensity = 683.0f * 0.3f * size * size;
	l.range = 2.0f * size;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_SPOT;
	l.position[0] = cx + 0.2f * size;
	l.position[1] = 0.8f * size;
	l.position[2] = cz;
	l.direction[0] = -0.3f;
	l.direction[1] = -1.0f;
	l.direction[2] = 0.2f;
	l.inner_cone = 0.3f;
	l.outer_cone = 0.7f;
	l.intensity = 683.0f * 0.5f * size * size;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	l.direction[0] = 0.3f;
	l.direction[1] = -0.5f;
	l.direction[2] = 0.8f;
	l.color[2] = 0.6f;
	l.intensity = 683.0f * 2.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	if (!emitters)
		for (uint32_t i = 0; i < s->nmaterials; i++)
			s->materials[i].emission = v3(0, 0, 0);
	return s;
}

static Scene *load_with_punctual(const char *path, float cx, float cz, float size, int emitters)
{
	ajar_scene *s;
	if (ajar_scene_load(path, &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	return with_punctual(s, cx, cz, size, emitters);
}

/* Cornell box (no portals: the directional light's lines cross the disk
 * of the scene's radius) and the glossy scene (delta lobes next to the
 * lights) with all three light types, beside their emitters and sky. */
static void test_mis_punctual(void **state)
{
	HostScene h;
	host_scene_open(&h, NULL, load_with_punctual(SCENE("cornell/cornell.gltf"), 0.278f, 0.28f, 0.55f, 1), 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(check_mis(&h, 300) > 1000);
	host_scene_close(&h);
	host_scene_open(&h, NULL, with_punctual(glossy_scene(), 0, -0.5f, 2, 1), 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(check_mis(&h, 600) > 1000);
	host_scene_close(&h);
}

/* The window room with the sun shining in through its window, and its
 * sky if `sky`. */
static Scene *sun_window_room(int sky)
{
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	ajar_light l;
	ajar_light_default(&l);
	l.type = AJAR_LIGHT_DIRECTIONAL;
	l.direction[0] = 0.3f;
	l.direction[1] = -0.5f;
	l.direction[2] = 0.8f;
	l.intensity = 683.0f * 5.0f;
	assert_int_equal(ajar_scene_add_light(s, &l), AJAR_OK);
	if (!sky)
		s->env_type = ENV_NONE;
	return s;
}

/* Its light subpaths start on the portal, and paths whose first vertex no
 * such line reaches (outside walls) are left to next-event estimation. */
static void test_mis_sun_portal(void **state)
{
	HostScene h;
	host_scene_open(&h, NULL, sun_window_room(1), 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(h.data.params->num_portals > 0);
	assert_true(check_mis(&h, 400) > 300);
	host_scene_close(&h);
}

/* window-room under a sky image with a sun high behind the window. */
static ajar_scene *sky_window_room(void)
{
	ajar_scene *s;
	if (ajar_scene_load(SCENE("window-room/window-room.gltf"), &s) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	float *sky = test_sun_sky(256, 128, 0.1f, sinf(0.84f), -cosf(0.84f), 0.03f, 3000.0f);
	assert_int_equal(scene_set_env_image(s, 256, 128, sky, 1.0f), AJAR_OK);
	return s;
}

/* In that room the environment's light subpaths start on the portal
 * (lights.h, line_sample), and their pf_1 (line_pdf_perp) is checked
 * against the oracle's own crossing count. */
static void test_mis_sky_image_portal(void **state)
{
	ajar_scene *s = sky_window_room();
	HostScene h;
	host_scene_open(&h, NULL, s, 32, 32, INTEGRATOR_BDPT, 8);
	assert_true(h.data.params->num_portals > 0 && h.data.params->env_type == ENV_IMAGE);
	assert_true(check_mis(&h, 400) > 1000);
	host_scene_close(&h);
}

/* ---- The light subpath's pn_0 cache ------------------------------------- */

/* Every strategy of random samples, in bdpt_strategies' order with one
 * BdptPnCache per light subpath, weighted three ways: without the cache
 * (bdpt_weight, the reference), with it (the same bits), and as
 * bdpt_strategies weighs, from the subpaths' MIS tails and the densities
 * the connection's evaluation found (bdpt_mis_tails, BdptConnPdf): equal
 * up to float rounding, within *worst (the largest difference, returned
 * there). Counts the connections (s >= 2) that took a cached pn_0 and
 * those whose x_2 lay behind x_1's shading normal (the cache's second
 * side) after the first side had been filled. */
static int beyond_delta; /* strategies of check_pn_cache with more light vertices than conn, past delta ones */

static int check_pn_cache(HostScene *h, int nsamples, int *reused, int *other_side, float *worst)
{
	SceneView *sc = &h->view;
	int depth = h->data.params->max_depth, compared = 0, conn = h->data.params->bdpt_conn;
	PathVertex l[SUBPATH_MAX], e[SUBPATH_MAX];
	for (int n = 0; n < nsamples; n++) {
		Rng rng = rng_init(97, (uint)n, 0, 7);
		float px = rng_f(&rng) * h->data.params->camera.width, py = rng_f(&rng) * h->data.params->camera.height;
		int nl = bdpt_light_subpath(sc, l, depth, &rng);
		int ne = bdpt_eye_subpath(sc, px, py, e, depth + 1, &rng);
		BdptPnCache pc, pt;
		pc.have = pt.have = 0;
		pc.tails = 0;
		bdpt_mis_tails(sc, l, nl, e, ne, &pt);
		for (int t = 1; t <= ne; t++) {
			for (int s = t >= 2 ? 0 : 1; s <= nl && s + t - 1 <= depth; s++) {
				int limit = mis_conn_limit(conn, bdpt_first_scatter(l, s, e, t));
				if (!mis_conn_in_set(limit, s + t, s))
					continue; /* not among the strategies bdpt_strategies takes */
				PathVertex y;
				const PathVertex *lp = l;
				BdptConnPdf cp;
				uint pixel;
				if (s == 0) {
					if (e[t - 1].type != VERTEX_ENV && sc->tris[e[t - 1].tri].emitter < 0)
						continue;
				} else if (t == 1) {
					if (v3_is_zero(bdpt_to_camera_pdf(sc, &l[s - 1], s == 1, &e[0], &pixel, &cp)))
						continue;
				} else if (e[t - 1].type != VERTEX_SURFACE) {
					break;
				} else if (s == 1) {
					if (v3_is_zero(bdpt_nee_conn(sc, &e[t - 1], &e[t - 2], &y, &rng, &cp)))
						continue;
					lp = &y;
				} else if (v3_is_zero(bdpt_connect_pdf(sc, &l[s - 1], &e[t - 1], &cp))) {
					continue;
				}
				int had = pc.have & 3;
				if (s >= 2) {
					const PathVertex *x2 = s >= 3 ? &l[2] : &e[t - 1];
					int side = vertex_nee_side(&l[1], x2);
					*reused += had >> side & 1;
					*other_side += had && !(had >> side & 1);
				}
				float want = bdpt_weight(sc, lp, s, e, t), got = bdpt_weight_cached(sc, lp, s, e, t, &pc, 0);
				const BdptConnPdf *cpp = s > 0 ? &cp : NULL;
				float fast = bdpt_weight_cached(sc, lp, s, e, t, &pt, cpp);
				MisVertex rec[2 * SUBPATH_MAX];
				BdptPnCache none = {{0.0f, 0.0f}, 0.0f, 0, 0};
				int k = bdpt_mis_records(sc, lp, s, e, t, rec, 0, &none, 0, cpp);
				if (mis_conn_limit(conn, mis_first_scatter(rec, k)) != limit)
					fail_msg("strategy (s=%d, t=%d) of sample %d: the set from the subpaths differs from "
						 "the records'", s, t, n);
				float whole = mis_path_weight_conn(rec, k, s, h->data.params->mis, limit);
				if (s > 0 && memcmp(&want, &got, sizeof got) != 0)
					fail_msg("strategy (s=%d, t=%d) of sample %d: weight %.9g with the cache, %.9g without", s,
						 t, n, got, want);
				if (!(fabsf(fast - whole) <= *worst)) {
					*worst = fabsf(fast - whole);
					print_message("largest difference so far: strategy (s=%d, t=%d) of sample %d: %.9g "
						      "from tails, %.9g from the whole path\n", s, t, n, fast, whole);
				}
				compared++;
				beyond_delta += conn > 0 && s > conn && t >= 2; /* past a delta light vertex */
			}
		}
	}
	print_message("%d weights the same bits with the cache; %d connections took a cached pn_0, %d filled "
		      "the second side\n", compared, *reused, *other_side);
	return compared;
}

/* A sky image through window-room's window, with a rough glass pane in the
 * room (light subpaths pass it, so one light subpath connects on both sides
 * of a vertex's normal), the glossy scene under a sky image, and door-ajar
 * (an emitter's pn_0). With the cache's side test replaced by side 0 the
 * first scene fails (weight 0.999907613 against 0.999906182); so does the
 * tails' comparison with the light tail read one vertex off (s - 2 for
 * s - 3) or the eye tail's delta test of e[a - 1] dropped. */
static void test_pn_cache_same_bits(void **state)
{
	ajar_scene *s = sky_window_room();
	ajar_material m;
	uint32_t glass;
	ajar_material_default(&m);
	m.transmission = 1;
	m.roughness = 0.3f;
	assert_int_equal(ajar_scene_add_material(s, &m, &glass), AJAR_OK);
	/* a pane across the room between the window (z = 0) and the floor the sky's
	 * lines reach: most light subpaths' first vertex, and the camera (z = 0.3)
	 * sees through it */
	static const float pane_p[] = {0.1f, 0.1f, 0.6f, 3.9f, 0.1f, 0.6f, 3.9f, 2.6f, 0.6f, 0.1f, 2.6f, 0.6f};
	static const uint32_t quad[] = {0, 1, 2, 0, 2, 3};
	ajar_mesh mesh = {pane_p, NULL, NULL, 4, quad, 2, glass, NULL};
	assert_int_equal(ajar_scene_add_mesh(s, &mesh), AJAR_OK);
	/* A second portal, tilted across the window (x 1.6..2.4, y 1..1.8, z =
	 * 0): with two planes the sky's next-event density reads the
	 * receiver's normal, so the two sides of the pane have two pn_0. */
	static const float tilt_p[] = {1.6f, 1.0f, 0.4f, 2.4f, 1.0f, 0.4f, 2.4f, 1.8f, 0.0f, 1.6f, 1.8f, 0.0f};
	ajar_mesh tilt = {tilt_p, NULL, NULL, 4, quad, 2, 0, NULL};
	assert_int_equal(ajar_scene_add_portal(s, &tilt), AJAR_OK);
	HostScene h;
	int reused = 0, other = 0;
	float worst = 0.0f;
	host_scene_open(&h, NULL, s, 24, 24, INTEGRATOR_BDPT, 8);
	assert_true(h.data.params->num_portals == 4 && h.data.params->env_type == ENV_IMAGE);
	assert_true(check_pn_cache(&h, 400, &reused, &other, &worst) > 2000);
	host_scene_close(&h);
	assert_true(reused > 500);
	assert_true(other > 20);

	ajar_scene *g = glossy_scene();
	float *sky = test_sun_sky(128, 64, 0.3f, 0.8f, 0.5f, 0.05f, 500.0f);
	assert_int_equal(scene_set_env_image(g, 128, 64, sky, 1.0f), AJAR_OK);
	host_scene_open(&h, NULL, g, 24, 24, INTEGRATOR_BDPT, 8);
	assert_true(check_pn_cache(&h, 400, &reused, &other, &worst) > 300);
	host_scene_close(&h);

	host_scene_open(&h, SCENE("door-ajar/door-ajar.gltf"), NULL, 24, 24, INTEGRATOR_BDPT, 8);
	assert_true(check_pn_cache(&h, 1200, &reused, &other, &worst) > 300);
	host_scene_close(&h);
	/* float rounding: the sums are associated differently (1.8e-7 seen) */
	assert_true(worst <= 2e-6f);
}

/* With the eye vertices joined to the first 1 or 2 light vertices only
 * (Params.bdpt_conn, the portal integrator's set under a sun; light
 * tracing keeps every light vertex), the weights from the tails made for
 * that set equal the whole path's over it. With the set test taken out of
 * mis_eye_tail the sky room fails (s = 1, t = 8: 0.90 from the tails
 * against 0.999), and with it taken out of mis_light_tails (s = 8, t = 1:
 * 0.006 against 0.996). The glazed room under its sky's sun: light
 * subpaths mirrored by the pane, whose next vertex joins the eye vertices
 * as a second light vertex (mis_conn_limit). */
static void test_conn_weights_from_tails(void **state)
{
	for (int conn = 1; conn <= 2; conn++) {
		HostScene h;
		int reused = 0, other = 0;
		float worst = 0.0f;
		host_scene_open(&h, NULL, sky_window_room(), 24, 24, INTEGRATOR_BDPT, 8);
		h.data.params->bdpt_conn = conn;
		assert_true(check_pn_cache(&h, 400, &reused, &other, &worst) > 1000);
		host_scene_close(&h);
		host_scene_open(&h, SCENE("door-ajar/door-ajar.gltf"), NULL, 24, 24, INTEGRATOR_BDPT, 8);
		h.data.params->bdpt_conn = conn;
		assert_true(check_pn_cache(&h, 5000, &reused, &other, &worst) > 300);
		host_scene_close(&h);
		beyond_delta = 0;
		host_scene_open(&h, SCENE("window-room-forest/window-room-forest-glazed.gltf"), NULL, 24, 24,
				INTEGRATOR_BDPT, 8);
		h.data.params->bdpt_conn = conn;
		assert_true(check_pn_cache(&h, 3000, &reused, &other, &worst) > 300);
		host_scene_close(&h);
		print_message("connections to %d light vertices: largest difference %.3g, %d strategies past a delta "
			      "light vertex\n", conn, worst, beyond_delta);
		if (conn == 2)
			assert_true(beyond_delta > 0);
		assert_true(worst <= 2e-6f);
	}
}

/* ---- Convergence ------------------------------------------------------- */

#define BATCHES 32

static void batch_estimate(HostScene *h, uint32_t spp, int layer, Estimate *est)
{
	host_batch_estimate(h, spp, layer, BATCHES, 1000, est);
}

/* |a - b| within z combined standard errors, per channel. */
static void assert_agree(const char *what, const Estimate *a, const Estimate *b, double z)
{
	for (int c = 0; c < 3; c++) {
		double se = sqrt(a->se[c] * a->se[c] + b->se[c] * b->se[c]);
		double d = a->mean[c] - b->mean[c];
		print_message("%s, channel %d: %.5f +- %.5f vs %.5f +- %.5f (%.1f se)\n", what, c, a->mean[c], a->se[c],
			      b->mean[c], b->se[c], se > 0 ? d / se : 0.0);
		if (fabs(d) > z * se + 1e-7)
			fail_msg("%s, channel %d: %.6f vs %.6f differ by %.1f standard errors", what, c, a->mean[c],
				 b->mean[c], d / se);
	}
}

/* Every strategy of paths of 1..3 segments, unweighted, against the path
 * tracer's image of exactly that many segments. 9 layers x 3 channels:
 * at 5 standard errors with 31 degrees of freedom a false alarm is ~1e-3
 * for the whole test. */
static void test_strategies_unbiased(void **state)
{
	HostScene hb, hp;
	const int len = 3;
	host_scene_open(&hb, SCENE("cornell/cornell.gltf"), NULL, 12, 12, INTEGRATOR_BDPT, len);
	host_scene_open(&hp, SCENE("cornell/cornell.gltf"), NULL, 12, 12, INTEGRATOR_PT, len);
	hb.data.params->strategy_len = len;
	hb.data.params->strategy_unweighted = 1;
	for (int n = 1; n <= len; n++) {
		Estimate pt;
		char what[64];
		hp.data.params->min_depth = hp.data.params->max_depth = n;
		batch_estimate(&hp, 16, -1, &pt);
		for (int s = 0; s <= n; s++) {
			Estimate st;
			batch_estimate(&hb, 16, (n - 1) * (n + 2) / 2 + s, &st);
			snprintf(what, sizeof what, "length %d, strategy (s=%d, t=%d)", n, s, n + 1 - s);
			assert_agree(what, &st, &pt, 5.0);
		}
	}
	host_scene_close(&hb);
	host_scene_close(&hp);
}

/* The same with punctual lights alone (the Cornell box's emission taken
 * away): s = 0 cannot reach them and the camera does not see them, so
 * layer (s = 0) and (s = 1, t = 1) stay black, while every other strategy,
 * light subpaths from the lights included, must give the path tracer's
 * image. */
static void test_strategies_unbiased_punctual(void **state)
{
	HostScene hb, hp;
	const int len = 3;
	host_scene_open(&hb, NULL, load_with_punctual(SCENE("cornell/cornell.gltf"), 0.278f, 0.28f, 0.55f, 0), 12, 12, INTEGRATOR_BDPT, len);
	host_scene_open(&hp, NULL, load_with_punctual(SCENE("cornell/cornell.gltf"), 0.278f, 0.28f, 0.55f, 0), 12, 12, INTEGRATOR_PT, len);
	hb.data.params->strategy_len = len;
	hb.data.params->strategy_unweighted = 1;
	for (int n = 1; n <= len; n++) {
		Estimate pt, zero = {{0, 0, 0}, {0, 0, 0}};
		char what[64];
		hp.data.params->min_depth = hp.data.params->max_depth = n;
		batch_estimate(&hp, 16, -1, &pt);
		for (int s = 0; s <= n; s++) {
			Estimate st;
			batch_estimate(&hb, 16, (n - 1) * (n + 2) / 2 + s, &st);
			snprintf(what, sizeof what, "punctual, length %d, strategy (s=%d, t=%d)", n, s, n + 1 - s);
			assert_agree(what, &st, s == 0 || (s == 1 && n == 1) ? &zero : &pt, 5.0);
		}
	}
	host_scene_close(&hb);
	host_scene_close(&hp);
}

/* The weighted layers add up to the image, exactly (fixed-point sums). */
static void test_layers_sum_to_image(void **state)
{
	HostScene h;
	const int len = 4;
	host_scene_open(&h, SCENE("cornell/cornell.gltf"), NULL, 10, 10, INTEGRATOR_BDPT, len);
	h.data.params->strategy_len = len;
	int nl = bdpt_layer_count(len);
	double rgb[300], *lay = malloc(sizeof(double) * 300 * nl);
	host_render(&h, 8, 5, rgb, lay);
	for (int i = 0; i < 300; i++) {
		double sum = 0;
		for (int j = 0; j < nl; j++)
			sum += lay[300 * j + i];
		assert_true(fabs(sum - rgb[i]) <= 1e-5 * fabs(rgb[i]) + 1e-5);
	}
	free(lay);
	host_scene_close(&h);
}

/* bdpt against pt on the full image, with glass, mirror, metal and sky. */
static void test_bdpt_matches_pt_glossy(void **state)
{
	HostScene hb, hp;
	Estimate b, p;
	host_scene_open(&hb, NULL, glossy_scene(), 12, 12, INTEGRATOR_BDPT, 6);
	host_scene_open(&hp, NULL, glossy_scene(), 12, 12, INTEGRATOR_PT, 6);
	batch_estimate(&hb, 8, -1, &b);
	batch_estimate(&hp, 16, -1, &p);
	assert_agree("glossy scene bdpt vs pt", &b, &p, 5.0);
	host_scene_close(&hb);
	host_scene_close(&hp);
}

/* bdpt against pt with punctual lights: the Cornell box with all three
 * types beside its emitter. Not the glossy scene: a punctual light seen
 * in a mirror or through smooth glass (paths light - delta lobe - ... -
 * camera with no other vertex to connect at) is out of pt's reach, as its
 * rays never hit the light, while bdpt's light subpaths find those
 * caustics. */
static void test_bdpt_matches_pt_punctual(void **state)
{
	HostScene hb, hp;
	Estimate b, p;
	host_scene_open(&hb, NULL, load_with_punctual(SCENE("cornell/cornell.gltf"), 0.278f, 0.28f, 0.55f, 1), 12, 12,
			INTEGRATOR_BDPT, 6);
	host_scene_open(&hp, NULL, load_with_punctual(SCENE("cornell/cornell.gltf"), 0.278f, 0.28f, 0.55f, 1), 12, 12,
			INTEGRATOR_PT, 6);
	batch_estimate(&hb, 8, -1, &b);
	batch_estimate(&hp, 16, -1, &p);
	assert_agree("Cornell box with punctual lights, bdpt vs pt", &b, &p, 5.0);
	host_scene_close(&hb);
	host_scene_close(&hp);
}

/* And bdpt against pt there: the light subpaths that start on the portal
 * carry the sun's indirect light into the room. */
static void test_bdpt_matches_pt_sun_portal(void **state)
{
	HostScene hb, hp;
	Estimate b, p;
	host_scene_open(&hb, NULL, sun_window_room(0), 12, 12, INTEGRATOR_BDPT, 6);
	host_scene_open(&hp, NULL, sun_window_room(0), 12, 12, INTEGRATOR_PT, 6);
	batch_estimate(&hb, 8, -1, &b);
	batch_estimate(&hp, 16, -1, &p);
	assert_agree("window room lit by the sun, bdpt vs pt", &b, &p, 5.0);
	host_scene_close(&hb);
	host_scene_close(&hp);
}

/* The smaller sets of bdpt_conn against pt, under the sun lamp and under a
 * sky image with a sun: what they leave out, the other strategies' weights
 * take up. */
static void test_conn_matches_pt(void **state)
{
	for (int sky = 0; sky < 2; sky++) {
		HostScene hp;
		Estimate p;
		host_scene_open(&hp, NULL, sky ? sky_window_room() : sun_window_room(0), 12, 12, INTEGRATOR_PT, 6);
		batch_estimate(&hp, sky ? 128 : 16, -1, &p);
		for (int conn = 1; conn <= 2; conn++) {
			HostScene hb;
			Estimate b;
			char what[96];
			host_scene_open(&hb, NULL, sky ? sky_window_room() : sun_window_room(0), 12, 12, INTEGRATOR_BDPT, 6);
			hb.data.params->bdpt_conn = conn;
			batch_estimate(&hb, 8, -1, &b);
			snprintf(what, sizeof what, "%s, bdpt joining eye vertices to %d light vertices vs pt",
				 sky ? "window room under a sky image" : "window room lit by the sun", conn);
			assert_agree(what, &b, &p, 5.0);
			host_scene_close(&hb);
		}
		host_scene_close(&hp);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_mis_cornell),
		cmocka_unit_test(test_mis_window_room),
		cmocka_unit_test(test_mis_glossy_glass_sky),
		cmocka_unit_test(test_mis_glazed), cmocka_unit_test(test_mis_living_room),
		cmocka_unit_test(test_layers_sum_to_image),
		cmocka_unit_test(test_strategies_unbiased),
		cmocka_unit_test(test_bdpt_matches_pt_glossy),
		cmocka_unit_test(test_mis_punctual),
		cmocka_unit_test(test_mis_sun_portal),
		cmocka_unit_test(test_mis_sky_image_portal),
		cmocka_unit_test(test_pn_cache_same_bits),
		cmocka_unit_test(test_conn_weights_from_tails),
		cmocka_unit_test(test_strategies_unbiased_punctual),
		cmocka_unit_test(test_bdpt_matches_pt_punctual),
		cmocka_unit_test(test_bdpt_matches_pt_sun_portal),
		cmocka_unit_test(test_conn_matches_pt),
	};
	return cmocka_run_group_tests_name("bdpt", tests, NULL, NULL);
}
