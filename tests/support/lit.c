/* lit.c — see lit.h. */
#include "lit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

uint64_t rng_state;

static uint32_t rnd_u32(void)
{
	/* PCG32 (O'Neill), fixed seed per test. */
	uint64_t old = rng_state;
	rng_state = old * 6364136223846793005ULL + 1442695040888963407ULL;
	uint32_t xs = (uint32_t)(((old >> 18) ^ old) >> 27), rot = (uint32_t)(old >> 59);
	return (xs >> rot) | (xs << ((-rot) & 31));
}

float rnd(void) { return ((float)(rnd_u32() >> 8) + 0.5f) * (1.0f / 16777216.0f); }

uint32_t add_material(Scene *s, V3 emission)
{
	Material m;
	memset(&m, 0, sizeof(m));
	m.base_color = v3(0.5f, 0.5f, 0.5f);
	m.base_tex = -1;
	m.emission = emission;
	m.roughness = 1.0f;
	m.ior = 1.5f;
	uint32_t id;
	assert_int_equal(scene_add_material(s, &m, &id), AJAR_OK);
	return id;
}

void add_tri(Scene *s, V3 a, V3 b, V3 c, uint32_t mat)
{
	float pos[9] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
	uint32_t idx[3] = {0, 1, 2};
	assert_int_equal(scene_add_triangles(s, "test", pos, NULL, NULL, 3, idx, 1, mat), AJAR_OK);
}

void lit_build(Lit *l)
{
	Scene *s = l->s;
	l->tris = malloc(sizeof(Tri) * (s->ntris ? s->ntris : 1));
	assert_non_null(l->tris);
	if (s->ntris)
		memcpy(l->tris, s->tris, sizeof(Tri) * s->ntris);
	assert_int_equal(lights_build(s, l->tris, s->shade, s->extra, s->ntris, s->materials, s->portals, s->nportal_tris,
				      v3(0, 0, 0), 10.0f, &l->lt),
			 AJAR_OK);
	memset(&l->prm, 0, sizeof(l->prm));
	l->prm.num_tris = (int)s->ntris;
	l->prm.num_emitters = (int)l->lt.nemitters;
	l->prm.num_portals = (int)s->nportal_tris;
	l->prm.env_type = s->env_type;
	l->prm.env_width = (int)s->env_width;
	l->prm.env_height = (int)s->env_height;
	l->prm.env_strength = s->env_strength;
	lights_set_env_rotation(&l->prm, s->env_rotation);
	l->prm.env_color = s->env_color;
	l->prm.env_pdf_select = l->lt.env_pdf_select;
	memset(&l->sc, 0, sizeof(l->sc));
	l->sc.tris = l->tris;
	l->sc.shade = s->shade;
	l->sc.textures = s->textures;
	l->sc.texels = s->texels;
	l->sc.materials = s->materials;
	l->sc.emitters = l->lt.emitters;
	l->sc.emitter_cdf = l->lt.emitter_cdf;
	l->sc.env = l->lt.env;
	l->sc.portals = s->portals;
	l->sc.portal_cdf = l->lt.portal_cdf;
	l->sc.params = &l->prm;
	l->planes = NULL;
	l->sky = NULL;
}

void lit_free(Lit *l)
{
	free(l->planes);
	free(l->sky);
	lights_free(&l->lt);
	free(l->tris);
	scene_free(l->s);
}

float *synthetic_sky(uint32_t w, uint32_t h)
{
	float *rgb = malloc(sizeof(float) * 3 * w * h);
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
			float blob = 20.0f * expf(-((u - 0.3f) * (u - 0.3f) + (v - 0.2f) * (v - 0.2f)) * 40.0f);
			float low = 3.0f * expf(-((u - 0.7f) * (u - 0.7f) + (v - 0.7f) * (v - 0.7f)) * 20.0f);
			float base = 0.2f + 0.1f * u;
			float *p = rgb + 3 * (y * w + x);
			p[0] = blob + low + base;
			p[1] = blob + 0.5f * low + base;
			p[2] = 0.5f * blob + base * 2.0f;
			if (y == h / 2 + 1 || x == 3)
				p[0] = p[1] = p[2] = 0.0f;
		}
	return rgb;
}

/* Total solid-angle density of light_sample at x in direction wi: the
 * environment's share plus every emitter the ray crosses (light sampling
 * ignores occlusion, so overlapping emitters add up). */
static double light_density(const Lit *l, V3 x, V3 n, V3 wi)
{
	double pdf = light_pdf_w(&l->sc, x, n, wi, -1, AJAR_INF, 1.0f);
	RayPre r = ray_pre(x, wi);
	for (uint32_t k = 0; k < l->lt.nemitters; k++) {
		int tri = l->lt.emitters[k].tri;
		float t, u, v;
		if (!tri_intersect(&r, &l->tris[tri], AJAR_INF, &t, &u, &v))
			continue;
		pdf += light_pdf_w(&l->sc, x, n, wi, tri, t, -v3_dot(v3_norm(tri_normal(&l->tris[tri])), wi));
	}
	return pdf;
}

void check_light_sample(Lit *l, V3 x, V3 n, const char *name)
{
	enum { CT = 24, CP = 48, SUB = 24, N = 300000, NC = CT * CP + 1 };
	static double obs[NC], expct[NC];
	memset(obs, 0, sizeof(obs));
	double total = 0.0;
	for (int ct = 0; ct < CT; ct++)
		for (int cp = 0; cp < CP; cp++) {
			double sum = 0.0;
			for (int j = 0; j < SUB; j++)
				for (int i = 0; i < SUB; i++) {
					float c = 1.0f - 2.0f * (ct + (j + 0.5f) / SUB) / CT;
					float phi = 2.0f * AJAR_PI * (cp + (i + 0.5f) / SUB) / CP;
					float s = sqrtf(fmaxf(0.0f, 1.0f - c * c));
					sum += light_density(l, x, n, v3(s * cosf(phi), c, s * sinf(phi)));
				}
			double cell = sum * (4.0 * M_PI / (CT * CP)) / (SUB * SUB);
			expct[ct * CP + cp] = cell * N;
			total += cell;
		}
	expct[NC - 1] = N * (1.0 - total);
	int env_count = 0;
	for (int k = 0; k < N; k++) {
		LightSample ls;
		if (!light_sample(&l->sc, x, n, rnd(), rnd(), rnd(), &ls)) {
			obs[NC - 1] += 1.0;
			continue;
		}
		env_count += ls.is_env;
		assert_true(ls.pdf_w > 0.0f);
		assert_float_equal(v3_len(ls.wi), 1.0f, 1e-5f);
		/* light_pdf_w reproduces the sample's own density. */
		if (ls.is_env) {
			/* Through portals the sample adds its own triangle's term
			 * first, so the sum may round differently. */
			assert_true(ls.dist == AJAR_INF);
			assert_float_equal(light_pdf_w(&l->sc, x, n, ls.wi, -1, ls.dist, 1.0f), ls.pdf_w, 1e-5f * ls.pdf_w);
		} else {
			assert_float_equal(ls.dist, v3_len(v3_sub(ls.p, x)), 1e-5f * ls.dist);
			float cos_light = -v3_dot(ls.n, ls.wi);
			RayPre r = ray_pre(x, ls.wi);
			float t, u, v;
			int tri = -1;
			for (uint32_t e = 0; e < l->lt.nemitters && tri < 0; e++) {
				int ti = l->lt.emitters[e].tri;
				if (tri_intersect(&r, &l->tris[ti], ls.dist * 1.0001f, &t, &u, &v) &&
				    fabsf(t - ls.dist) < 1e-4f * ls.dist)
					tri = ti;
			}
			assert_true(tri >= 0);
			assert_float_equal(light_pdf_w(&l->sc, x, n, ls.wi, tri, ls.dist, cos_light), ls.pdf_w,
					   1e-4f * ls.pdf_w);
			V3 Le = emitter_radiance(&l->sc, tri, ls.p, v3_neg(ls.wi));
			assert_true(Le.x == ls.Le.x && Le.y == ls.Le.y && Le.z == ls.Le.z);
		}
		float c = fminf(fmaxf(ls.wi.y, -1.0f), 1.0f);
		float phi = atan2f(ls.wi.z, ls.wi.x);
		if (phi < 0.0f)
			phi += 2.0f * AJAR_PI;
		int ct = (int)((1.0f - c) * 0.5f * CT), cp = (int)(phi / (2.0f * AJAR_PI) * CP);
		ct = ct < 0 ? 0 : (ct >= CT ? CT - 1 : ct);
		cp = cp < 0 ? 0 : (cp >= CP ? CP - 1 : cp);
		obs[ct * CP + cp] += 1.0;
	}
	double expected_env = N * l->lt.env_pdf_select;
	assert_true(fabs(env_count - expected_env) <= 5.0 * sqrt(expected_env + 1.0));
	double p = chi2_test(obs, expct, NC, 5.0);
	printf("  light_sample %-14s p = %.3f (env picked %.3f, refused %.3f)\n", name, p,
	       (double)env_count / N, obs[NC - 1] / N);
	assert_true(p > ALPHA);
}

void build_light_scene(Lit *l)
{
	assert_int_equal(scene_new("<test>", &l->s), AJAR_OK);
	Scene *s = l->s;
	uint32_t grey = add_material(s, v3(0, 0, 0));
	uint32_t white = add_material(s, v3(1, 1, 1));
	uint32_t red = add_material(s, v3(4, 0.5f, 0.5f));
	uint32_t blue = add_material(s, v3(0.2f, 0.2f, 3));
	/* Square at y = 1.5 facing down (CCW seen from below). */
	add_tri(s, v3(-1, 1.5f, -1), v3(1, 1.5f, -1), v3(1, 1.5f, 1), white);
	add_tri(s, v3(-1, 1.5f, -1), v3(1, 1.5f, 1), v3(-1, 1.5f, 1), white);
	/* Tilted triangle at z ~ -2 facing +z, and a larger one behind it. */
	add_tri(s, v3(-0.5f, -0.5f, -2), v3(1, -0.5f, -2.5f), v3(0, 1, -2), red);
	add_tri(s, v3(-2, -1, -4), v3(2, -1, -4), v3(0, 2, -4), blue);
	/* At x = 2, facing +x: x sees its back. */
	add_tri(s, v3(2, -1, -1), v3(2, 1, -1), v3(2, 0, 1), white);
	/* Occluder below. */
	add_tri(s, v3(-1, -1, -1), v3(1, -1, -1), v3(0, -1, 1), grey);
}

void add_window_portals(Lit *l)
{
	float pos[] = {-0.8f, -0.4f, 1, 0.8f, -0.4f, 1, 0.8f, 0.8f, 1, -0.8f, 0.8f, 1, /* window, z = 1 */
		       0.0f, 0.0f, 2, 1.5f, 0.0f, 2, 1.5f, 1.5f, 2,                /* behind it, z = 2 */
		       3.0f, 0.2f, 2, 3.05f, 0.2f, 2, 3.0f, 0.25f, 2,              /* tiny and far */
		       -1.5f, -1, -1, -1.5f, 1, -1, -1.5f, 0, 1,                   /* x on its sky side */
		       0, -2, -1, 1, -2, 1, -1, -2, 1};                            /* no sky behind it */
	uint32_t idx[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
	assert_int_equal(scene_add_portal(l->s, "windows", pos, 16, idx, 6), AJAR_OK);
	lit_build(l);
}

void grid_window(float *pos, uint32_t *idx)
{
	for (int j = 0; j <= GRID_NY; j++)
		for (int i = 0; i <= GRID_NX; i++) {
			float *v = &pos[3 * (j * (GRID_NX + 1) + i)];
			v[0] = -1.0f + 2.0f * (float)i / GRID_NX;
			v[1] = -0.6f + 1.5f * (float)j / GRID_NY;
			v[2] = 1.0f;
		}
	int t = 0;
	for (int j = 0; j < GRID_NY; j++)
		for (int i = 0; i < GRID_NX; i++) {
			uint32_t a = (uint32_t)(j * (GRID_NX + 1) + i), b = a + 1, c = a + GRID_NX + 2, d = a + GRID_NX + 1;
			uint32_t q[6] = {a, b, c, a, c, d};
			for (int k = 0; k < 6; k++)
				idx[3 * t + k] = q[k];
			t += 2;
		}
}
