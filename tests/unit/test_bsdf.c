/* test_bsdf.c — kernels/material/bsdf.h on the host.
 *
 * For every material family and several outgoing directions (both sides of
 * the surface, a tilted normal): a chi-square test of bsdf_sample's
 * directions against bsdf_eval's pdf_w, integrated numerically over
 * (cos theta, phi) cells of the sphere as Mitsuba's chi2 test does; pdf_w
 * integrating to 1 - P(delta); sample and eval agreeing; reciprocity and
 * the adjoint (importance) relation; Monte Carlo albedo <= 1; exact
 * Lambertian; delta mirror and smooth glass directions and Fresnel weights;
 * no NaN at grazing and degenerate directions. */
#include "bsdf_check.h"

static double chi2_one(const Mat *mm, int wo_index, int mode, double alpha_each)
{
	Material m = material(mm);
	Bsdf bs = make_bsdf(&m);
	return chi2_run(mm->name, (uint)(mm - mats), &bs, dir(&bs, wos[wo_index][0], wos[wo_index][1]), wo_index, mode,
			alpha_each);
}

static void test_chi2(void **state)
{
	(void)state;
	int ntests = N_MATS * N_WOS + 2; /* + glass in importance mode */
	double alpha_each = 1.0 - pow(1.0 - ALPHA_TOTAL, 1.0 / ntests);
	double pmin = 1;
	for (int i = 0; i < N_MATS; i++)
		for (int k = 0; k < N_WOS; k++)
			pmin = fmin(pmin, chi2_one(&mats[i], k, BSDF_RADIANCE, alpha_each));
	/* Importance mode changes only f, but the sampling path is shared:
	 * check it once from each side of the glass. */
	pmin = fmin(pmin, chi2_one(&mats[7], 1, BSDF_IMPORTANCE, alpha_each));
	pmin = fmin(pmin, chi2_one(&mats[7], 3, BSDF_IMPORTANCE, alpha_each));
	print_message("chi2: %d tests, smallest p-value %g (threshold %g)\n", ntests, pmin, alpha_each);
}

/* Random pairs: f(wo, wi) == f(wi, wo) for reflection, and for every pair
 * f_radiance(wo, wi) == f_importance(wi, wo) (the adjoint BSDF), and
 * pdf_rev_w(wo, wi) == pdf_w(wi, wo). */
static void test_reciprocity(void **state)
{
	(void)state;
	Rng r = rng_init(99, 0, 0, 0);
	for (int i = 0; i < N_MATS; i++) {
		Material m = material(&mats[i]);
		Bsdf bs = make_bsdf(&m);
		/* Dielectric Fresnel near the critical angle is a steep sqrt:
		 * float rounding of the cosines alone reaches ~1e-3 there. */
		float tol = mats[i].transmission > 0 ? 2e-3f : 1e-4f;
		int nonzero = reciprocity_check(mats[i].name, &bs, &r, tol, 1);
		assert_true(nonzero > 1000);
	}
}


static void test_energy(void **state)
{
	(void)state;
	const float cos_list[] = {1.0f, 0.7f, 0.3f, 0.05f, -0.4f, -0.02f};
	for (int i = 0; i < N_MATS; i++) {
		Material m = material(&mats[i]);
		Bsdf bs = make_bsdf(&m);
		for (int k = 0; k < (int)(sizeof(cos_list) / sizeof(cos_list[0])); k++) {
			V3 wo = dir(&bs, cos_list[k], 0.7f);
			V3 sd, a = albedo(&bs, wo, BSDF_IMPORTANCE, (uint)(i * 16 + k), &sd);
			/* The tables' interpolation error, as test_white_furnace allows
			 * it: thin glass returns E1 + (1 - E1) with E1 read from the
			 * table, 2.3e-3 above 1 at roughness 0.25, normal incidence. */
			float tol = mats[i].transmission > 0 ? 3e-3f : 1e-3f;
			if (v3_maxc(v3_sub(a, v3_scale(sd, 5.0f))) > 1.0f + tol)
				fail_msg("%s cos %g: albedo (%g %g %g) > 1", mats[i].name, cos_list[k], a.x, a.y, a.z);
			if (i == 0) /* Lambertian: exactly the base colour */
				for (int c = 0; c < 3; c++)
					assert_float_equal(v3_comp(a, c), v3_comp(bs.base_color, c),
							   5 * v3_comp(sd, c) + 1e-4);
		}
	}
	/* Lambertian f and pdf are exact. */
	Material m = material(&mats[0]);
	Bsdf bs = make_bsdf(&m);
	V3 wo = dir(&bs, 0.8f, 1.0f), wi = dir(&bs, 0.3f, 4.0f);
	float pdf, pdf_rev;
	V3 f = bsdf_eval(&bs, wo, wi, BSDF_RADIANCE, &pdf, &pdf_rev);
	assert_float_equal(f.x, 0.8f / M_PI, 1e-6);
	assert_float_equal(f.z, 0.4f / M_PI, 1e-6);
	assert_float_equal(pdf, 0.3f / M_PI, 1e-6);
	assert_float_equal(pdf_rev, 0.8f / M_PI, 1e-6);
	/* Glass from outside in radiance mode is 1/eta^2 of importance mode. */
	m = material(&mats[7]);
	bs = make_bsdf(&m);
	wo = dir(&bs, 0.8f, 1.0f);
	wi = dir(&bs, -0.7f, 1.0f + (float)M_PI);
	V3 fr = bsdf_eval(&bs, wo, wi, BSDF_RADIANCE, &pdf, &pdf_rev);
	V3 fi = bsdf_eval(&bs, wo, wi, BSDF_IMPORTANCE, &pdf, &pdf_rev);
	assert_true(fi.x > 0.0f);
	assert_float_equal(fr.x * 1.5f * 1.5f, fi.x, 1e-5 * fi.x);
}

/* White furnace of one BSDF: a white material (base colour 1) must keep
 * all the energy at every angle: the metal's and the glass's multiple-
 * scattering lobes and the base under the coat return what single
 * scattering loses. Over roughness x {metal, plastic and glass at ior 1.5
 * and 1.8} x outgoing cosines (glass from both sides), the Monte Carlo
 * albedo (importance transport: energy) must be 1 within 5 standard errors
 * plus the tables' interpolation error (32 x 32 nodes: measured below 1e-3
 * away from grazing, 2e-3 at cos 0.05; glass, 16 x 16 x 16 nodes, 2e-3 more:
 * up to 3e-3 measured). Without the compensation metal at roughness 1 lost
 * 60% at normal incidence, glass from inside 50%. */
static void test_white_furnace(void **state)
{
	(void)state;
	const float rough[] = {0.05f, 0.1f, 0.2f, 0.35f, 0.5f, 0.75f, 1.0f};
	const float cos_list[] = {1.0f, 0.7f, 0.4f, 0.15f, 0.05f};
	const float tol[] = {2e-3f, 2e-3f, 2e-3f, 3e-3f, 5e-3f};
	double worst = 0;
	static const char *names[] = {"metal", "plastic", "plastic", "glass", "glass", "thin glass", "thin glass"};
	for (int fam = 0; fam < 7; fam++)
		for (int ri = 0; ri < (int)(sizeof(rough) / sizeof(rough[0])); ri++) {
			Mat mm = {"white", 1, 1, 1, fam == 0 ? 1.0f : 0.0f, rough[ri], fam >= 3 ? 1.0f : 0.0f,
				  fam == 2 || fam == 4 || fam == 6 ? 1.8f : 1.5f, 1, fam == 3 || fam == 4};
			Material m = material(&mm);
			Bsdf bs = make_bsdf(&m);
			for (int k = 0; k < 2 * (int)(sizeof(cos_list) / sizeof(cos_list[0])); k++) {
				int kc = k / 2, back = k & 1; /* glass from inside too */
				if (back && fam < 3)
					continue;
				V3 wo = dir(&bs, back ? -cos_list[kc] : cos_list[kc], 0.7f);
				V3 sd, a = albedo(&bs, wo, BSDF_IMPORTANCE, (uint)(1000 + fam * 100 + ri * 10 + k), &sd);
				double dev = fabs(a.x - 1.0);
				worst = fmax(worst, dev - 5 * sd.x);
				if (dev > 5 * sd.x + tol[kc] + (fam >= 3 ? 2e-3 : 0))
					fail_msg("%s r %g ior %g cos %g: white furnace albedo %.5f +- %.5f, want 1", names[fam],
						 rough[ri], mm.ior, back ? -cos_list[kc] : cos_list[kc], a.x, sd.x);
			}
		}
	print_message("white furnace: largest |albedo - 1| beyond 5 sigma %.2e\n", worst);
}

/* The coat's multiple scattering: a black-base plastic reflects exactly the
 * coat's single scattering Es plus its multiple-scattering lobe's albedo
 * coat_fms (1 - E1), both read from the tables (bsdf_tables.h), and a white
 * base still gives 1 (as test_white_furnace: 5 standard errors plus the
 * tables' interpolation error). At roughness 0.9 and ior 1.5 the lobe adds
 * 13% to the coat's Es at normal incidence, 10% at cos 0.7, 5% at 0.4, 2%
 * at 0.15 (checked: over 5% at cos >= 0.7); the black base fell short by
 * that much before it. */
static void test_coat_ms(void **state)
{
	(void)state;
	const float rough[] = {0.3f, 0.6f, 0.9f, 1.0f};
	const float cos_list[] = {1.0f, 0.7f, 0.4f, 0.15f};
	const float tol[] = {2e-4f, 2e-4f, 2e-4f, 3e-4f};
	for (int ri = 0; ri < 4; ri++)
		for (int base = 0; base < 2; base++) {
			float c = (float)base;
			Mat mm = {"coat", c, c, c, 0, rough[ri], 0, 1.5f, 1, 0};
			Material m = material(&mm);
			Bsdf bs = make_bsdf(&m);
			for (int k = 0; k < 4; k++) {
				V3 wo = dir(&bs, cos_list[k], 0.7f);
				float e1, es = bsdf_coat_albedo(&bs, cos_list[k], &e1);
				float ms = bs.coat_fms * (1.0f - e1);
				float want = base ? 1.0f : es + ms;
				V3 sd, a = albedo(&bs, wo, BSDF_IMPORTANCE, (uint)(5000 + ri * 10 + k + 100 * base), &sd);
				double t = 5 * sd.x + (base ? 5 * tol[k] : tol[k]);
				if (fabs(a.x - want) > t)
					fail_msg("coat r %g base %d cos %g: albedo %.5f +- %.5f, want %.5f (Es %.5f, ms %.5f)",
						 rough[ri], base, cos_list[k], a.x, sd.x, want, es, ms);
				if (!base && ri == 2 && k < 2)
					assert_true(ms > 0.05f * es);
			}
		}
}

/* Perfect mirror: the reflected direction, weight Schlick(base, cos). */
static void test_mirror(void **state)
{
	(void)state;
	Mat mm = {"mirror", 0.9f, 0.5f, 0.2f, 1, 0, 0, 1.5f, 1, 0};
	Material m = material(&mm);
	Bsdf bs = make_bsdf(&m);
	assert_true(bsdf_is_delta(&bs) && bsdf_has_delta(&bs));
	for (int k = 0; k < 4; k++) {
		float c = k < 3 ? wos[k][0] : -0.3f;
		V3 wo = dir(&bs, c, 1.0f);
		BsdfSample s;
		assert_true(bsdf_sample(&bs, wo, 0.5f, 0.3f, 0.6f, BSDF_RADIANCE, &s));
		assert_true(s.delta);
		V3 want = v3_sub(v3_scale(bs.n, 2 * v3_dot(wo, bs.n)), wo);
		assert_float_equal(v3_len(v3_sub(s.wi, want)), 0, 1e-5);
		float w = bsdf_schlick_w(fabs(c));
		V3 thr = v3_scale(s.f, fabs(v3_dot(s.wi, bs.n)) / s.pdf_w);
		assert_float_equal(thr.x, 0.9f + 0.1f * w, 1e-5);
		assert_float_equal(thr.z, 0.2f + 0.8f * w, 1e-5);
		assert_float_equal(s.pdf_w, 1.0f, 1e-6);
		assert_float_equal(s.pdf_rev_w, 1.0f, 1e-6);
		float pdf, pdf_rev;
		assert_true(v3_is_zero(bsdf_eval(&bs, wo, s.wi, BSDF_RADIANCE, &pdf, &pdf_rev)));
		assert_true(pdf == 0.0f && pdf_rev == 0.0f);
	}
	/* A rough surface and a plastic are not delta; a mix is partly. */
	Mat rough = mm, mix = mm;
	rough.roughness = 0.5f;
	mix.metallic = 0.5f;
	m = material(&rough);
	bs = make_bsdf(&m);
	assert_false(bsdf_is_delta(&bs) || bsdf_has_delta(&bs));
	m = material(&mix);
	bs = make_bsdf(&m);
	assert_false(bsdf_is_delta(&bs));
	assert_true(bsdf_has_delta(&bs));
}

/* Smooth glass: reflection with probability F, refraction by Snell's law,
 * weights 1 and tint (/ eta^2 in radiance mode), total internal reflection. */
static void test_smooth_glass(void **state)
{
	(void)state;
	Mat mm = {"glass", 1.0f, 0.8f, 0.6f, 0, 0, 1, 1.5f, 1, 1};
	Material m = material(&mm);
	Bsdf bs = make_bsdf(&m);
	assert_true(bsdf_is_delta(&bs) && bsdf_has_delta(&bs));
	assert_float_equal(bsdf_null_prob(&bs, dir(&bs, 0.7f, 2.0f)), 0, 0);
	const float cs[] = {1.0f, 0.7f, 0.2f, -0.9f, -0.8f, -0.5f};
	for (int k = 0; k < 6; k++) {
		float c = cs[k];
		float eta = c > 0 ? 1.5f : 1 / 1.5f; /* eta_t / eta_i */
		double fresnel = bsdf_fresnel_dielectric(fabs(c), eta);
		V3 wo = dir(&bs, c, 2.0f);
		int n = 20000, nrefl = 0;
		Rng r = rng_init(5, (uint)k, 0, 0);
		for (int i = 0; i < n; i++) {
			BsdfSample s;
			int mode = i & 1 ? BSDF_RADIANCE : BSDF_IMPORTANCE;
			float u0 = rng_f(&r), u1 = rng_f(&r), u2 = rng_f(&r);
			if (!bsdf_sample(&bs, wo, u0, u1, u2, mode, &s))
				fail_msg("glass: no sample");
			assert_true(s.delta);
			float ci = v3_dot(s.wi, bs.n);
			V3 thr = v3_scale(s.f, fabs(ci) / s.pdf_w);
			if (ci * c > 0) {
				nrefl++;
				V3 want = v3_sub(v3_scale(bs.n, 2 * v3_dot(wo, bs.n)), wo);
				assert_float_equal(v3_len(v3_sub(s.wi, want)), 0, 1e-5);
				assert_float_equal(thr.x, 1, 1e-5);
				assert_float_equal(thr.z, 1, 1e-5);
				assert_float_equal(s.pdf_w, fresnel, 1e-5);
			} else {
				/* Snell: eta_i sin_i = eta_t sin_t; coplanar, opposite side */
				float so = sqrt(1 - c * c), si = sqrt(fmax(0.0f, 1 - ci * ci));
				assert_float_equal(so, eta * si, 1e-4);
				assert_float_equal(v3_dot(v3_cross(wo, s.wi), bs.n), 0, 1e-5);
				assert_true(v3_dot(s.wi, v3_sub(wo, v3_scale(bs.n, v3_dot(wo, bs.n)))) <= 1e-6f);
				float scale = mode == BSDF_RADIANCE ? 1 / (eta * eta) : 1;
				assert_float_equal(thr.y, 0.8f * scale, 1e-5);
				assert_float_equal(s.pdf_w, 1 - fresnel, 1e-5);
				/* Fresnel transmittance is the same seen from wi's side */
				assert_float_equal(s.pdf_rev_w, s.pdf_w, 1e-5);
			}
		}
		double sd = sqrt(fresnel * (1 - fresnel) / n);
		if (fabs((double)nrefl / n - fresnel) > 5 * sd + 1e-9)
			fail_msg("glass cos %g: reflected fraction %g, Fresnel %g", c, (double)nrefl / n, fresnel);
	}
	/* At normal incidence F = ((1.5 - 1) / (1.5 + 1))^2 = 0.04; from inside
	 * beyond the critical angle (sin > 1/1.5) F = 1. */
	assert_float_equal(bsdf_fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-6);
	assert_float_equal(bsdf_fresnel_dielectric(0.5f, 1 / 1.5f), 1.0f, 0);
}

/* Smooth thin glass (no volume): reflection with probability F, else the
 * null event straight through (wi = -wo) with throughput base_color;
 * bsdf_null_prob is that event's probability and bsdf_null_weight the
 * transmittance (1 - F) base_color, the same from both sides. At normal
 * incidence (1 - F0) = 0.96 for ior 1.5: the pane passes 96%. */
static void test_thin_smooth_glass(void **state)
{
	(void)state;
	Mat mm = {"pane", 1.0f, 0.8f, 0.6f, 0, 0, 1, 1.5f, 1, 0};
	Material m = material(&mm);
	Bsdf bs = make_bsdf(&m);
	assert_true(bsdf_is_delta(&bs) && bsdf_has_delta(&bs) && bsdf_has_null(&bs));
	V3 w0 = dir(&bs, 1.0f, 0.0f);
	V3 t0 = bsdf_null_weight(&bs, w0);
	assert_float_equal(t0.x, 0.96f, 1e-6);
	assert_float_equal(t0.y, 0.96f * 0.8f, 1e-6);
	const float cs[] = {1.0f, 0.7f, 0.2f, -0.9f, -0.5f, -0.1f};
	for (int k = 0; k < 6; k++) {
		float c = cs[k];
		double fresnel = bsdf_fresnel_dielectric(fabs(c), 1.5f); /* either side: air on both */
		V3 wo = dir(&bs, c, 2.0f);
		assert_float_equal(bsdf_null_prob(&bs, wo), 1 - fresnel, 1e-6);
		V3 tw = bsdf_null_weight(&bs, wo), tb = bsdf_null_weight(&bs, v3_neg(wo));
		assert_float_equal(tw.z, (1 - fresnel) * 0.6f, 1e-6);
		assert_memory_equal(&tw, &tb, sizeof tw);
		int n = 20000, nrefl = 0;
		Rng r = rng_init(7, (uint)k, 0, 0);
		for (int i = 0; i < n; i++) {
			BsdfSample s;
			int mode = i & 1 ? BSDF_RADIANCE : BSDF_IMPORTANCE;
			float u0 = rng_f(&r), u1 = rng_f(&r), u2 = rng_f(&r);
			if (!bsdf_sample(&bs, wo, u0, u1, u2, mode, &s))
				fail_msg("thin glass: no sample");
			V3 thr = v3_scale(s.f, fabs(v3_dot(s.wi, bs.n)) / s.pdf_w);
			if (s.delta == 1) {
				nrefl++;
				V3 want = v3_sub(v3_scale(bs.n, 2 * v3_dot(wo, bs.n)), wo);
				assert_float_equal(v3_len(v3_sub(s.wi, want)), 0, 1e-5);
				assert_float_equal(thr.x, 1, 1e-5);
				assert_float_equal(s.pdf_w, fresnel, 1e-5);
				assert_float_equal(s.pdf_rev_w, fresnel, 1e-5);
			} else {
				assert_int_equal(s.delta, BSDF_NULL);
				assert_float_equal(v3_len(v3_add(s.wi, wo)), 0, 1e-6);
				assert_float_equal(thr.x, 1.0f, 1e-5); /* no eta^2: nothing bends */
				assert_float_equal(thr.y, 0.8f, 1e-5);
				assert_float_equal(s.pdf_w, 1 - fresnel, 1e-5);
				assert_float_equal(s.pdf_rev_w, s.pdf_w, 1e-5);
			}
		}
		double sd = sqrt(fresnel * (1 - fresnel) / n);
		if (fabs((double)nrefl / n - fresnel) > 5 * sd + 1e-9)
			fail_msg("thin glass cos %g: reflected fraction %g, Fresnel %g", c, (double)nrefl / n, fresnel);
	}
	/* Half glass, half diffuse: the null event keeps the glass lobe's share. */
	Mat half = {"half pane", 0.6f, 0.8f, 0.7f, 0, 0, 0.5f, 1.5f, 0, 0};
	m = material(&half);
	bs = make_bsdf(&m);
	assert_false(bsdf_is_delta(&bs));
	V3 wo = dir(&bs, 0.8f, 1.0f);
	int n = 40000, nnull = 0;
	Rng r = rng_init(8, 0, 0, 0);
	for (int i = 0; i < n; i++) {
		BsdfSample s;
		float u0 = rng_f(&r), u1 = rng_f(&r), u2 = rng_f(&r);
		if (bsdf_sample(&bs, wo, u0, u1, u2, BSDF_RADIANCE, &s) && s.delta == BSDF_NULL)
			nnull++;
	}
	double pn = bsdf_null_prob(&bs, wo);
	assert_true(pn > 0.3 && pn < 0.7);
	if (fabs((double)nnull / n - pn) > 5 * sqrt(pn * (1 - pn) / n))
		fail_msg("half pane: null fraction %g, bsdf_null_prob %g", (double)nnull / n, pn);
	V3 tw = bsdf_null_weight(&bs, wo);
	assert_float_equal(tw.x, 0.5 * (1 - bsdf_fresnel_dielectric(0.8f, 1.5f)) * 0.6, 1e-6);
}

/* Degenerate inputs: grazing, in-plane, opposite and zero directions, flipped
 * or zero shading normals, extreme random numbers. Nothing may be NaN. */
static void test_no_nan(void **state)
{
	(void)state;
	const V3 dirs[] = {v3(0, 0, 1),         v3(0, 0, -1),         v3(1, 0, 0),
			   v3(1, 0, 1e-8f),     v3(1, 0, -1e-8f),     v3_norm(v3(1, 1, 1e-4f)),
			   v3(0, 0, 0),         v3_norm(v3(-1, 0, 1e-3f)), v3_norm(v3(0.3f, 0.2f, -1))};
	const float us[] = {0.0f, 0.5f, 0.99999994f, 1e-7f};
	const int nd = (int)(sizeof(dirs) / sizeof(dirs[0]));
	const V3 normals[][2] = {{v3(0, 0, 1), v3(0, 0, 1)},
				 {v3_norm(v3(0.5f, 0, 1)), v3(0, 0, 1)},
				 {v3(0, 0, -1), v3(0, 0, 1)},
				 {v3(0, 0, 0), v3(0, 0, 1)},
				 {v3(1, 0, 0), v3(0, 0, 1)}};
	Mat extra[] = {{"tiny", 0.5f, 0.5f, 0.5f, 0.3f, 0.01f, 0.3f, 1.0f, 1, 0},
		       {"ior big", 0.5f, 0.5f, 0.5f, 0, 0.2f, 1, 10.0f, 1, 0},
		       {"black", 0, 0, 0, 0, 0.5f, 0, 1.5f, 1, 0},
		       {"black lambert", 0, 0, 0, 0, 0.5f, 0, 1.5f, 0, 0}};
	for (int mi = 0; mi < N_MATS + 4; mi++) {
		const Mat *mm = mi < N_MATS ? &mats[mi] : &extra[mi - N_MATS];
		Material m = material(mm);
		for (int ni = 0; ni < 5; ni++) {
			Bsdf bs;
			bsdf_setup(&bs, &m, m.base_color, normals[ni][0], normals[ni][1]);
			for (int a = 0; a < nd; a++)
				for (int b = 0; b < nd; b++) {
					float pdf, pdf_rev;
					V3 f = bsdf_eval(&bs, dirs[a], dirs[b], BSDF_RADIANCE, &pdf, &pdf_rev);
					if (!finite3(f) || !isfinite(pdf) || !isfinite(pdf_rev) || pdf < 0 || pdf_rev < 0)
						fail_msg("%s: eval NaN (normal %d, dirs %d %d)", mm->name, ni, a, b);
				}
			for (int a = 0; a < nd; a++)
				for (int i = 0; i < 4; i++)
					for (int j = 0; j < 4; j++)
						for (int k = 0; k < 4; k++) {
							BsdfSample s;
							if (!bsdf_sample(&bs, dirs[a], us[i], us[j], us[k], BSDF_RADIANCE, &s))
								continue;
							if (!finite3(s.f) || !finite3(s.wi) || !(s.pdf_w > 0) || !isfinite(s.pdf_w) ||
							    !isfinite(s.pdf_rev_w))
								fail_msg("%s: sample NaN (normal %d, dir %d)", mm->name, ni, a);
						}
		}
	}
}


int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_chi2),
		cmocka_unit_test(test_reciprocity),
		cmocka_unit_test(test_energy),
		cmocka_unit_test(test_white_furnace),
		cmocka_unit_test(test_coat_ms),
		cmocka_unit_test(test_mirror),
		cmocka_unit_test(test_smooth_glass),
		cmocka_unit_test(test_thin_smooth_glass),
		cmocka_unit_test(test_no_nan),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
