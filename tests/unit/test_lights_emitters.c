/* test_lights_emitters.c — the emitters' and portals' tables
 * (src/prepare/light_tables.c) and their sampling (kernels/light/lights.h):
 * emissive triangles chosen by power and uniform points on them, emissive
 * textures and alpha masks (only where they emit), the metallic-roughness
 * texture; portal triangles chosen by area; chi-square against the
 * expected counts. */
#include "lit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Emissive triangles of different areas and emissions, one black, one
 * with zero area: selection by power, uniform points, front normals. */
static void test_emitter_sampling(void **state)
{
	rng_state = 12;
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint32_t black = add_material(l.s, v3(0, 0, 0));
	V3 em[4] = {v3(1, 1, 1), v3(10, 0, 0), v3(0, 0, 3), v3(0.5f, 2, 0.5f)};
	uint32_t mats[4];
	for (int i = 0; i < 4; i++)
		mats[i] = add_material(l.s, em[i]);
	add_tri(l.s, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), black);
	add_tri(l.s, v3(0, 0, 1), v3(2, 0, 1), v3(0, 3, 1), mats[0]);      /* area 3 */
	add_tri(l.s, v3(5, 0, 0), v3(5, 0.5f, 0), v3(5, 0, 0.5f), mats[1]); /* 0.125 */
	add_tri(l.s, v3(1, 1, 1), v3(2, 2, 2), v3(3, 3, 3), mats[2]);      /* area 0 */
	add_tri(l.s, v3(-1, 2, 0), v3(-1, 2, 4), v3(3, 2, 0), mats[2]);    /* 8 */
	add_tri(l.s, v3(0, -1, 0), v3(0, -1, 1), v3(1, -1, 0), mats[3]);   /* 0.5 */
	lit_build(&l);
	assert_int_equal(l.lt.nemitters, 4);
	int expect_emitter[6] = {-1, 0, 1, -1, 2, 3};
	double power[4];
	double total = 0.0;
	for (int i = 0; i < 6; i++) {
		assert_int_equal(l.tris[i].emitter, expect_emitter[i]);
		if (expect_emitter[i] < 0)
			continue;
		const Emitter *e = &l.lt.emitters[expect_emitter[i]];
		assert_int_equal(e->tri, i);
		const Tri *t = &l.tris[i];
		double area = 0.5 * v3_len(v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0)));
		assert_float_equal(e->area, area, 1e-6 * area);
		V3 L = l.s->materials[t->material].emission;
		power[expect_emitter[i]] = area * M_PI * (0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z);
		total += power[expect_emitter[i]];
	}
	assert_float_equal(l.lt.emitter_power, total, 1e-5 * total);
	assert_float_equal(l.lt.emitter_cdf[0], 0.0f, 0.0f);
	assert_float_equal(l.lt.emitter_cdf[4], 1.0f, 0.0f);

	enum { N = 100000, SUBD = 4, NCELL = SUBD * SUBD };
	double obs[4] = {0}, expct[4];
	for (int k = 0; k < 4; k++) {
		expct[k] = N * power[k] / total;
		assert_float_equal(l.lt.emitters[k].pdf_select, power[k] / total, 1e-6);
	}
	/* Points on the big emitter, binned into its 16 congruent
	 * sub-triangles (equal areas, so equal expected counts). */
	double pobs[NCELL] = {0}, pexp[NCELL];
	int big = 4;
	for (int k = 0; k < N; k++) {
		V3 p, n;
		float pdf_a;
		int tri = emitter_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		assert_true(tri >= 0 && tri < 6 && l.tris[tri].emitter >= 0);
		const Tri *t = &l.tris[tri];
		obs[t->emitter] += 1.0;
		assert_float_equal(pdf_a, emitter_pdf_a(&l.sc, tri, p), 0.0f);
		assert_float_equal(pdf_a, power[t->emitter] / total / l.lt.emitters[t->emitter].area,
				   1e-5 * pdf_a);
		V3 ng = tri_normal(t);
		assert_float_equal(v3_len(n), 1.0f, 1e-5f);
		assert_float_equal(v3_dot(n, ng), v3_len(ng), 1e-4f * v3_len(ng));
		/* Barycentrics of p by least squares on the edges. */
		V3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0), q = v3_sub(p, t->p0);
		float d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2);
		float det = d11 * d22 - d12 * d12;
		float b1 = (d22 * v3_dot(q, e1) - d12 * v3_dot(q, e2)) / det;
		float b2 = (d11 * v3_dot(q, e2) - d12 * v3_dot(q, e1)) / det;
		assert_true(b1 >= -1e-5f && b2 >= -1e-5f && b1 + b2 <= 1.0f + 1e-5f);
		if (tri == big) {
			float x = fminf(fmaxf(b1 * SUBD, 0.0f), SUBD - 1e-3f);
			float y = fminf(fmaxf(b2 * SUBD, 0.0f), SUBD - 1e-3f);
			int i = (int)x, j = (int)y;
			if (i + j >= SUBD) /* rounding at the hypotenuse */
				j = SUBD - 1 - i;
			int upper = i + j < SUBD - 1 && (x - i) + (y - j) > 1.0f;
			/* Row j holds 2 (SUBD - j) - 1 sub-triangles. */
			int cell = 0;
			for (int r = 0; r < j; r++)
				cell += 2 * (SUBD - r) - 1;
			cell += 2 * i + upper;
			pobs[cell] += 1.0;
		}
	}
	double p = chi2_test(obs, expct, 4, 5.0);
	printf("  emitter selection: p = %.3f\n", p);
	assert_true(p > ALPHA);
	for (int c = 0; c < NCELL; c++)
		pexp[c] = expct[2] / NCELL;
	p = chi2_test(pobs, pexp, NCELL, 5.0);
	printf("  emitter points: p = %.3f\n", p);
	assert_true(p > ALPHA);

	/* Radiance leaves the front face only; non-emitters give none. */
	V3 front = tri_normal(&l.tris[1]);
	assert_float_equal(emitter_radiance(&l.sc, 1, l.tris[1].p0, front).x, 1.0f, 0.0f);
	assert_true(v3_is_zero(emitter_radiance(&l.sc, 1, l.tris[1].p0, v3_neg(front))));
	assert_true(v3_is_zero(emitter_radiance(&l.sc, 0, l.tris[0].p0, tri_normal(&l.tris[0]))));
	assert_float_equal(emitter_pdf_a(&l.sc, 0, l.tris[0].p0), 0.0f, 0.0f);
	lit_free(&l);
}

/* A unit quad in z = 0 (UVs = xy) with an 8 x 8 emissive texture whose
 * left half (x < 0.5) is black, nearest filtering, and a triangle whose
 * UVs lie in the black half: the quad emits half the power of an
 * untextured one, its points are sampled only where it emits and
 * uniformly there (chi-square over 8 x 8 cells of the lit half), and the
 * black triangle is no emitter at all. */
static void test_emissive_texture(void **state)
{
	(void)state;
	rng_state = 17;
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint8_t rgba[8 * 8 * 4];
	for (int i = 0; i < 64; i++) {
		uint8_t c = (i % 8) < 4 ? 0 : 255;
		rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = c;
		rgba[4 * i + 3] = 255;
	}
	uint32_t img, tex;
	assert_int_equal(scene_add_texture(l.s, 8, 8, rgba, &img), AJAR_OK);
	const float xf[6] = {1, 0, 0, 0, 1, 0};
	assert_int_equal(scene_add_texture_use(l.s, img, TEX_NEAREST, xf, &tex), AJAR_OK);
	uint32_t m = add_material(l.s, v3(2, 2, 2));
	l.s->materials[m].emissive_tex = (int)tex + 1;
	float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
	float uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3};
	assert_int_equal(scene_add_triangles(l.s, "quad", pos, NULL, uv, 4, idx, 2, m), AJAR_OK);
	float pos2[] = {3, 0, 0, 4, 0, 0, 3, 1, 0};
	float uv2[] = {0.1f, 0, 0.4f, 0, 0.1f, 1};
	assert_int_equal(scene_add_triangles(l.s, "dark", pos2, NULL, uv2, 3, NULL, 1, m), AJAR_OK);
	lit_build(&l);
	assert_true(l.tris[0].emitter >= 0 && l.tris[1].emitter >= 0);
	assert_int_equal(l.tris[2].emitter, -1);
	/* Area 1, half of it at radiance 2 (luminance 2): pi W. */
	assert_float_equal(l.lt.emitter_power, AJAR_PI, 1e-5 * AJAR_PI);
	enum { N = 64000, G = 8 };
	double obs[G * G] = {0}, expct[G * G];
	for (int k = 0; k < N; k++) {
		V3 p, n;
		float pdf_a;
		int tri = emitter_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		assert_true(tri == 0 || tri == 1);
		assert_true(p.x >= 0.5f - 1e-6f);
		/* Uniform over the lit half: density 2 per unit area. */
		assert_float_equal(pdf_a, 2.0f, 1e-4f);
		assert_float_equal(emitter_pdf_a(&l.sc, tri, p), pdf_a, 1e-4f);
		assert_float_equal(emitter_radiance(&l.sc, tri, p, v3(0, 0, 1)).x, 2.0f, 0.0f);
		int i = (int)fminf((p.x - 0.5f) * 2 * G, G - 1), j = (int)fminf(p.y * G, G - 1);
		obs[j * G + i] += 1.0;
	}
	for (int c = 0; c < G * G; c++)
		expct[c] = (double)N / (G * G);
	double p = chi2_test(obs, expct, G * G, 5.0);
	printf("  points on the lit half: p = %.3f\n", p);
	assert_true(p > ALPHA);
	/* The black half: no emission and zero density. */
	V3 dark = v3(0.25f, 0.6f, 0.0f);
	int t = 1; /* (0,0) (1,1) (0,1) holds x < y */
	assert_true(v3_is_zero(emitter_radiance(&l.sc, t, dark, v3(0, 0, 1))));
	assert_float_equal(emitter_pdf_a(&l.sc, t, dark), 0.0f, 0.0f);

	/* An alpha-masked emitter (checker of 4 x 4 texels, clear where
	 * x + y is even): half the power, sampled only where it is. */
	lit_free(&l);
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	uint8_t chk[4 * 4 * 4];
	for (int i = 0; i < 16; i++) {
		chk[4 * i] = chk[4 * i + 1] = chk[4 * i + 2] = 255;
		chk[4 * i + 3] = ((i % 4) + (i / 4)) % 2 ? 255 : 0;
	}
	assert_int_equal(scene_add_texture(l.s, 4, 4, chk, &img), AJAR_OK);
	assert_int_equal(scene_add_texture_use(l.s, img, TEX_NEAREST, xf, &tex), AJAR_OK);
	m = add_material(l.s, v3(2, 2, 2));
	l.s->materials[m].base_tex = (int)tex;
	l.s->materials[m].base_alpha = 1.0f;
	l.s->materials[m].alpha_cutoff = 0.5f;
	l.s->materials[m].flags = MATERIAL_ALPHA_MASK;
	assert_int_equal(scene_add_triangles(l.s, "quad", pos, NULL, uv, 4, idx, 2, m), AJAR_OK);
	lit_build(&l);
	assert_float_equal(l.lt.emitter_power, AJAR_PI, 1e-5 * AJAR_PI);
	for (int k = 0; k < 2000; k++) {
		V3 p, n;
		float pdf_a;
		int tri = emitter_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		int ix = (int)fminf(p.x * 4, 3), iy = (int)fminf(p.y * 4, 3);
		assert_true((ix + iy) % 2 == 1);
		assert_float_equal(pdf_a, 2.0f, 1e-4f);
		assert_float_equal(emitter_radiance(&l.sc, tri, p, v3(0, 0, 1)).x, 2.0f, 0.0f);
	}

	/* The metallic-roughness texture (linear, B metallic, G roughness)
	 * times the factors, sRGB decoding only for colour. */
	uint8_t mr[4] = {0, 128, 64, 255};
	uint32_t mimg;
	assert_int_equal(scene_add_texture(l.s, 1, 1, mr, &mimg), AJAR_OK);
	l.sc.textures = l.s->textures;
	l.sc.texels = l.s->texels;
	Material *mm = &l.s->materials[m];
	mm->metallic = 1.0f;
	mm->roughness = 0.5f;
	mm->mr_tex = (int)mimg + 1;
	mm->base_tex = (int)mimg;
	Surface s;
	memset(&s, 0, sizeof s);
	s.material = (int)m;
	s.ng = s.ns = v3(0, 0, 1);
	s.tu = s.tv = 0.3f;
	s.color = v3(1, 1, 1);
	s.alpha = 1.0f;
	Bsdf bs;
	surface_bsdf(&l.sc, &s, surface_base_color(&l.sc, &s), &bs);
	assert_float_equal(bs.metallic, 64.0f / 255.0f, 1e-6f);
	assert_float_equal(bs.alpha, powf(0.5f * 128.0f / 255.0f, 2.0f), 1e-6f);
	assert_float_equal(bs.base_color.y, 0.5f * srgb_to_linear(128.0f / 255.0f), 1e-6f);
	lit_free(&l);
}

static void test_portal_sampling(void **state)
{
	rng_state = 13;
	Lit l;
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	add_material(l.s, v3(0, 0, 0));
	/* A 2 x 1 window (two triangles) and a small 0.5 x 0.5 one. */
	float pos[] = {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0, 5, 0, 0, 5.5f, 0, 0, 5, 0.5f, 0};
	uint32_t idx[] = {0, 1, 2, 0, 2, 3, 4, 5, 6};
	assert_int_equal(scene_add_portal(l.s, "window", pos, 7, idx, 3), AJAR_OK);
	lit_build(&l);
	assert_int_equal(l.lt.nportals, 3);
	double area[3] = {1.0, 1.0, 0.125}, total = 2.125;
	enum { N = 50000 };
	double obs[3] = {0}, expct[3];
	for (int k = 0; k < 3; k++) {
		expct[k] = N * area[k] / total;
		assert_float_equal(l.s->portals[k].pdf_select, area[k] / total, 1e-6);
		assert_float_equal(l.s->portals[k].area, area[k], 1e-6);
	}
	for (int k = 0; k < N; k++) {
		V3 p, n;
		float pdf_a;
		int i = portal_sample(&l.sc, rnd(), rnd(), rnd(), &p, &n, &pdf_a);
		assert_true(i >= 0 && i < 3);
		obs[i] += 1.0;
		assert_float_equal(pdf_a, 1.0 / total, 1e-5);
		assert_float_equal(n.z, 1.0f, 1e-6f);
		assert_float_equal(p.z, 0.0f, 0.0f);
		assert_true(i == 2 ? p.x >= 5.0f && p.x <= 5.5f : p.x >= 0.0f && p.x <= 2.0f);
	}
	double p = chi2_test(obs, expct, 3, 5.0);
	printf("  portal selection: p = %.3f\n", p);
	assert_true(p > ALPHA);
	lit_free(&l);

	/* No portals: nothing to sample. */
	assert_int_equal(scene_new("<test>", &l.s), AJAR_OK);
	add_material(l.s, v3(0, 0, 0));
	lit_build(&l);
	V3 pp, nn;
	float pdf_a;
	assert_int_equal(portal_sample(&l.sc, 0.5f, 0.5f, 0.5f, &pp, &nn, &pdf_a), -1);
	lit_free(&l);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_emissive_texture),
		cmocka_unit_test(test_emitter_sampling),
		cmocka_unit_test(test_portal_sampling),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
