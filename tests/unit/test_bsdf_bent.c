/* test_bsdf_bent.c — kernels/material/bsdf.h where the shading normal faces
 * away from a direction (normal maps): the bend itself, chi-square and the
 * adjoint relation with a tilted normal, no black fringes. */
#include "bsdf_check.h"

/* The bend of a shading normal that faces away (bsdf.h, bsdf_bend_t): over
 * random tilts and directions, the bent normal lies on the arc from n to
 * ng, keeps the direction above it, and puts its mirror image at least
 * min(0.9 cos, 0.01) above the surface, exactly that where it bends. */
static void test_bend(void **state)
{
	(void)state;
	Rng r = rng_init(7, 1, 2, 3);
	Material m = material(&mats[0]);
	int nbent = 0;
	for (int k = 0; k < 200000; k++) {
		float tilt = 85.0f * rng_f(&r);
		Bsdf bs;
		bsdf_setup(&bs, &m, m.base_color, tilted_n(tilt), v3(0, 0, 1));
		V3 w = sample_uniform_sphere(rng_f(&r), rng_f(&r)), x;
		if (fabs(w.z) < 1e-4f)
			continue;
		float tn = bsdf_tilt(&bs, &x), t = bsdf_bend_t(&bs, x, tn, w);
		assert_true(t >= 0 && t <= tn);
		V3 mn = bsdf_frame_t(&bs, x, tn, t).n;
		V3 ws = w.z < 0 ? v3_neg(w) : w; /* the bend is the same from either side */
		float thr = fminf(0.9f * ws.z, 0.01f), h = 2 * v3_dot(ws, mn) * mn.z - ws.z;
		assert_true(v3_dot(ws, mn) > 0);
		assert_true(fabs(mn.y) < 1e-6f && mn.x >= -1e-6f); /* on the arc */
		if (h < thr - 1e-4f)
			fail_msg("tilt %g w (%g %g %g): mirror height %g below %g", tilt, w.x, w.y, w.z, h, thr);
		if (t < tn) {
			nbent++;
			if (fabs(h - thr) > 1e-4f + 1e-3f * thr)
				fail_msg("tilt %g: bent normal's mirror height %g, want %g", tilt, h, thr);
		}
	}
	assert_true(nbent > 10000);
}

/* Normal-mapped surfaces: a shading normal tilted 50 degrees from ng.
 * Chi-square of the sampling (which then samples in wo's bent normal)
 * against pdf_w, from a direction the normal faces away from and a
 * grazing one it faces; the adjoint relation and pdf_rev_w over random
 * pairs. */
static void test_bent_chi2(void **state)
{
	(void)state;
	const int mi[] = {1, 4, 7, 9}; /* plastic, metal, glass, mix (they hold every lobe) */
	const float wo_ea[][2] = {{10, 180}, {3, 20}};
	int nm = (int)(sizeof(mi) / sizeof(mi[0])), nw = (int)(sizeof(wo_ea) / sizeof(wo_ea[0]));
	double alpha_each = 1.0 - pow(1.0 - ALPHA_TOTAL, 1.0 / (nm * nw)), pmin = 1;
	for (int i = 0; i < nm; i++) {
		Material m = material(&mats[mi[i]]);
		Bsdf bs;
		bsdf_setup(&bs, &m, m.base_color, tilted_n(50), v3(0, 0, 1));
		assert_true(bs.flags & BSDF_TILTED);
		for (int k = 0; k < nw; k++)
			pmin = fmin(pmin, chi2_run(mats[mi[i]].name, (uint)mi[i], &bs, elev_dir(wo_ea[k][0], wo_ea[k][1]), 100 + k,
						   BSDF_RADIANCE, alpha_each));
		Rng r = rng_init(31, (uint)i, 0, 0);
		/* Bent normals make f only adjoint, not reciprocal (bsdf.h). */
		float tol = mats[mi[i]].transmission > 0 ? 2e-3f : 1e-4f;
		int nonzero = reciprocity_check(mats[mi[i]].name, &bs, &r, tol, 0);
		assert_true(nonzero > 1000);
	}
	print_message("tilted normal chi2: %d tests, smallest p-value %g (threshold %g)\n", nm * nw, pmin, alpha_each);
}

/* No black fringes: with a shading normal tilted 60 degrees, seen from
 * directions it faces away from (down to 2 degrees above the surface) and
 * grazing ones it faces, a white Lambertian, white plastic and white rough
 * metal reflect (radiance mode, f |wi.n| / pdf) between 0.5 and 1 + 2%
 * (measured 0.75 to 1.00); before the bend they were black (0) wherever wo
 * lay below n. The same
 * integral estimated by uniform sampling of the hemisphere through
 * bsdf_eval agrees within 5 standard errors: f is 0 wherever pdf_w is, so
 * BSDF sampling alone is unbiased. */
static void test_bent_fringe(void **state)
{
	(void)state;
	const Mat white[] = {{"white lambert", 1, 1, 1, 0, 1.0f, 0, 1.5f, 0, 0},
			     {"white plastic r0.5", 1, 1, 1, 0, 0.5f, 0, 1.5f, 1, 0},
			     {"white metal r0.3", 1, 1, 1, 1, 0.3f, 0, 1.5f, 1, 0}};
	const float wo_ea[][2] = {{2, 180}, {10, 180}, {25, 160}, {2, 0}, {8, 30}};
	for (int i = 0; i < 3; i++) {
		Material m = material(&white[i]);
		Bsdf bs;
		bsdf_setup(&bs, &m, m.base_color, tilted_n(60), v3(0, 0, 1));
		for (int k = 0; k < (int)(sizeof(wo_ea) / sizeof(wo_ea[0])); k++) {
			V3 wo = elev_dir(wo_ea[k][0], wo_ea[k][1]), sd;
			V3 a = albedo(&bs, wo, BSDF_RADIANCE, (uint)(500 + i * 10 + k), &sd);
			Rng r = rng_init(77, (uint)i, (uint)k, 0);
			double s = 0, s2 = 0;
			for (int j = 0; j < N_ALBEDO; j++) {
				V3 wi = sample_uniform_sphere(rng_f(&r), rng_f(&r)), f;
				wi.z = fabsf(wi.z);
				float pdf, pdf_rev;
				f = bsdf_eval(&bs, wo, wi, BSDF_RADIANCE, &pdf, &pdf_rev);
				double v = f.x * fabs(v3_dot(wi, bs.n)) * 2 * M_PI;
				s += v;
				s2 += v * v;
			}
			double mu = s / N_ALBEDO, su = sqrt(fmax(s2 / N_ALBEDO - mu * mu, 0) / N_ALBEDO);
			print_message("%s, wo %g deg az %g: albedo %.4f +- %.4f (uniform %.4f +- %.4f)\n", white[i].name,
				      wo_ea[k][0], wo_ea[k][1], a.x, sd.x, mu, su);
			if (!(a.x > 0.5f && a.x < 1.02f + 5 * sd.x))
				fail_msg("%s wo %g deg az %g: albedo %g", white[i].name, wo_ea[k][0], wo_ea[k][1], a.x);
			/* The diffuse base never bends (as Cycles' diffuse closure
			 * keeps N): from every view the Lambertian returns what n's
			 * hemisphere keeps above ng, (1 + cos 60) / 2 = 0.75,
			 * analytically. */
			if (i == 0 && fabs(a.x - 0.75) > 5 * sd.x + 1e-3)
				fail_msg("white lambert wo %g deg az %g: albedo %g, want 0.75", wo_ea[k][0], wo_ea[k][1], a.x);
			/* and pointwise: f |wi . n| = max(wi . n, 0) / pi, whichever
			 * side wo is on, in both modes. */
			for (int j = 0; i == 0 && j < 2000; j++) {
				V3 wi = sample_uniform_sphere(rng_f(&r), rng_f(&r));
				wi.z = fabsf(wi.z);
				float pdf, pdf_rev;
				V3 fr = bsdf_eval(&bs, wo, wi, BSDF_RADIANCE, &pdf, &pdf_rev);
				V3 fi = bsdf_eval(&bs, wi, wo, BSDF_IMPORTANCE, &pdf, &pdf_rev);
				float want = fmaxf(v3_dot(wi, bs.n), 0.0f) / (float)M_PI;
				if (fabsf(fr.x * fabsf(v3_dot(wi, bs.n)) - want) > 1e-6f || fi.x != fr.x)
					fail_msg("white lambert wo %g deg az %g: f cos %g, want %g (importance f %g)",
						 wo_ea[k][0], wo_ea[k][1], fr.x * fabsf(v3_dot(wi, bs.n)), want, fi.x);
			}
			if (fabs(a.x - mu) > 5 * sqrt(sd.x * sd.x + su * su) + 1e-3)
				fail_msg("%s wo %g deg az %g: sampled albedo %g, uniform %g", white[i].name, wo_ea[k][0],
					 wo_ea[k][1], a.x, mu);
		}
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_bend),
		cmocka_unit_test(test_bent_chi2),
		cmocka_unit_test(test_bent_fringe),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
