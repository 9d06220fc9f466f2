/* bsdf_check.c — the BSDF tests' shared materials and checks (bsdf_check.h). */
#include "bsdf_check.h"

#ifdef __SANITIZE_ADDRESS__
#define N_CHI2 150000 /* sanitizers are ~10x slower; fewer samples, same cells */
#else
#define N_CHI2 600000
#endif
#define NZ 30
#define NPHI 60
#define SUB 12 /* midpoint sub-cells per cell side for the expected counts */

const Mat mats[] = {
	{"lambert", 0.8f, 0.6f, 0.4f, 0, 1.0f, 0, 1.5f, 0, 0},
	{"plastic r0.5", 0.5f, 0.7f, 0.2f, 0, 0.5f, 0, 1.5f, 1, 0},
	{"plastic r0.3 s0.5 ior1.8", 0.9f, 0.2f, 0.2f, 0, 0.3f, 0, 1.8f, 0.5f, 0},
	{"plastic r1", 0.3f, 0.3f, 0.9f, 0, 1.0f, 0, 1.5f, 1, 0},
	{"metal r0.4", 0.9f, 0.6f, 0.3f, 1, 0.4f, 0, 1.5f, 1, 0},
	{"metal r0.8", 0.95f, 0.95f, 0.95f, 1, 0.8f, 0, 1.5f, 1, 0},
	{"metal r1 white", 1, 1, 1, 1, 1.0f, 0, 1.5f, 1, 0}, /* multiple scattering is 60% of it */
	{"glass r0.4", 1.0f, 0.9f, 0.8f, 0, 0.4f, 1, 1.5f, 1, 1},
	{"glass r0.7 ior1.33", 1, 1, 1, 0, 0.7f, 1, 1.33f, 1, 1},
	{"mix", 0.8f, 0.5f, 0.3f, 0.4f, 0.5f, 0.5f, 1.5f, 1, 1},
	{"diffuse + mirror", 0.7f, 0.7f, 0.7f, 0.5f, 0, 0, 1.5f, 0, 0},
	{"diffuse + smooth glass", 0.6f, 0.8f, 0.7f, 0, 0, 0.5f, 1.5f, 0, 1},
	{"thin glass r0.25", 0.9f, 1.0f, 0.8f, 0, 0.25f, 1, 1.5f, 1, 0},
	{"thin glass r0.4", 1.0f, 0.9f, 0.8f, 0, 0.4f, 1, 1.5f, 1, 0},
	{"thin glass r0.8 ior1.33", 1, 1, 1, 0, 0.8f, 1, 1.33f, 1, 0},
	{"thin mix", 0.8f, 0.5f, 0.3f, 0.3f, 0.5f, 0.5f, 1.7f, 1, 0},
	{"diffuse + thin smooth glass", 0.6f, 0.8f, 0.7f, 0, 0, 0.5f, 1.5f, 0, 0},
};

Material material(const Mat *m)
{
	Material x;
	memset(&x, 0, sizeof(x));
	x.base_color = v3(m->r, m->g, m->b);
	x.base_tex = -1;
	x.metallic = m->metallic;
	x.roughness = m->roughness;
	x.transmission = m->transmission;
	x.ior = m->ior;
	x.specular = m->specular;
	x.flags = m->volume ? MATERIAL_VOLUME : 0;
	return x;
}

/* A tilted normal so the frame code is exercised; ns == ng. */
Bsdf make_bsdf(const Material *m)
{
	Bsdf bs;
	V3 n = v3_norm(v3(0.3f, -0.2f, 1.0f));
	bsdf_setup(&bs, m, m->base_color, n, n);
	return bs;
}

V3 dir(const Bsdf *bs, float z, float phi)
{
	float r = sqrt(fmax(0.0f, 1.0f - z * z));
	return v3_norm(v3_from_local(v3(r * cos(phi), r * sin(phi), z), bs->t, bs->b, bs->n));
}

int finite3(V3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static int cell_of(const Bsdf *bs, V3 w)
{
	double z = v3_dot(w, bs->n);
	double phi = atan2((double)v3_dot(w, bs->b), (double)v3_dot(w, bs->t));
	if (phi < 0)
		phi += 2 * M_PI;
	int iz = (int)floor((z + 1) * 0.5 * NZ), ip = (int)(phi / (2 * M_PI) * NPHI);
	iz = iz < 0 ? 0 : (iz >= NZ ? NZ - 1 : iz);
	ip = ip < 0 ? 0 : (ip >= NPHI ? NPHI - 1 : ip);
	return iz * NPHI + ip;
}

/* Relative closeness; values below 1e-2 are compared absolutely (float
 * cancellation in 1 - F near total internal reflection). */
int rel_close(float a, float b, float tol) { return fabs(a - b) <= tol * fmax(fmax(fabs(a), fabs(b)), 1e-2f); }

int reciprocity_check(const char *name, const Bsdf *bs, Rng *r, float tol, int reciprocal)
{
	int nonzero = 0;
	for (int k = 0; k < 20000; k++) {
		V3 wo = sample_uniform_sphere(rng_f(r), rng_f(r));
		V3 wi = sample_uniform_sphere(rng_f(r), rng_f(r));
		float p1, r1, p2, r2, p3, r3;
		V3 f1 = bsdf_eval(bs, wo, wi, BSDF_RADIANCE, &p1, &r1);
		V3 f2 = bsdf_eval(bs, wi, wo, BSDF_RADIANCE, &p2, &r2);
		V3 f3 = bsdf_eval(bs, wi, wo, BSDF_IMPORTANCE, &p3, &r3);
		nonzero += !v3_is_zero(f1);
		int same_side = v3_dot(wo, bs->ng) * v3_dot(wi, bs->ng) > 0 && reciprocal;
		if (!rel_close(f1.x, f3.x, tol) || !rel_close(f1.y, f3.y, tol) || !rel_close(f1.z, f3.z, tol))
			fail_msg("%s: f_radiance(wo,wi) %g != f_importance(wi,wo) %g", name, f1.x, f3.x);
		if (same_side && (!rel_close(f1.x, f2.x, tol) || !rel_close(f1.y, f2.y, tol) || !rel_close(f1.z, f2.z, tol)))
			fail_msg("%s: f not reciprocal: %g vs %g", name, f1.x, f2.x);
		if (!rel_close(r1, p2, 1e-5f) || !rel_close(p1, r2, 1e-5f))
			fail_msg("%s: pdf_rev_w mismatch", name);
		if (p1 < 0 || !isfinite(p1) || !finite3(f1))
			fail_msg("%s: bad eval", name);
	}
	return nonzero;
}

/* One chi-square test; returns its p-value. Also checks that the pdf
 * integrates to the non-delta probability and that samples agree with eval. */
double chi2_run(const char *name, uint seed, const Bsdf *bsp, V3 wo, int wo_index, int mode,
		       double alpha_each)
{
	static double obs[NZ * NPHI], expct[NZ * NPHI];
	Bsdf bs = *bsp;
	memset(obs, 0, sizeof(obs));
	Rng r = rng_init(1234, seed, (uint)wo_index, (uint)mode);
	int ndelta = 0, nok = 0;
	for (int i = 0; i < N_CHI2; i++) {
		BsdfSample s;
		float u0 = rng_f(&r), u1 = rng_f(&r), u2 = rng_f(&r);
		if (!bsdf_sample(&bs, wo, u0, u1, u2, mode, &s))
			continue;
		if (!finite3(s.f) || !finite3(s.wi) || !(s.pdf_w > 0.0f) || !isfinite(s.pdf_w))
			fail_msg("%s: bad sample f (%g %g %g) pdf %g", name, s.f.x, s.f.y, s.f.z, s.pdf_w);
		if (s.delta) {
			ndelta++;
			continue;
		}
		float pdf, pdf_rev, pdf2, pdf_rev2;
		V3 f = bsdf_eval(&bs, wo, s.wi, mode, &pdf, &pdf_rev);
		if (!rel_close(f.x, s.f.x, 1e-5f) || !rel_close(f.y, s.f.y, 1e-5f) || !rel_close(pdf, s.pdf_w, 1e-5f) ||
		    !rel_close(pdf_rev, s.pdf_rev_w, 1e-5f))
			fail_msg("%s: sample and eval disagree", name);
		/* pdf_rev_w(wo, wi) is pdf_w(wi, wo) */
		bsdf_eval(&bs, s.wi, wo, mode, &pdf2, &pdf_rev2);
		if (!rel_close(pdf_rev, pdf2, 1e-5f) || !rel_close(pdf_rev2, pdf, 1e-5f))
			fail_msg("%s: pdf_rev_w %g != reverse pdf_w %g", name, pdf_rev, pdf2);
		obs[cell_of(&bs, s.wi)] += 1;
		nok++;
	}
	/* Expected counts: midpoint rule on SUB x SUB sub-cells; the solid angle
	 * element is dz dphi. */
	double total = 0;
	for (int iz = 0; iz < NZ; iz++)
		for (int ip = 0; ip < NPHI; ip++) {
			double sum = 0, dz = 2.0 / NZ / SUB, dp = 2 * M_PI / NPHI / SUB;
			for (int a = 0; a < SUB; a++)
				for (int b = 0; b < SUB; b++) {
					float z = (float)(-1 + (iz * SUB + a + 0.5) * dz);
					float phi = (float)((ip * SUB + b + 0.5) * dp);
					float pdf, pdf_rev;
					V3 f = bsdf_eval(&bs, wo, dir(&bs, z, phi), mode, &pdf, &pdf_rev);
					if (!finite3(f) || !isfinite(pdf) || pdf < 0)
						fail_msg("%s: eval not finite", name);
					sum += pdf;
				}
			expct[iz * NPHI + ip] = sum * dz * dp * N_CHI2;
			total += sum * dz * dp;
		}
	/* The pdf integrates to the probability of non-delta samples: at most
	 * 1 - P(delta), less by the visible normals whose reflection points
	 * below the surface (those samples fail). */
	double p_delta = (double)ndelta / N_CHI2, p_ok = (double)nok / N_CHI2;
	double sigma = sqrt(p_ok * (1 - p_ok) / N_CHI2) + sqrt(p_delta * (1 - p_delta) / N_CHI2);
	if (fabs(total - p_ok) > 5 * sigma + 2e-3 || total > 1 - p_delta + 5 * sigma + 2e-3)
		fail_msg("%s wo %d: pdf integrates to %g; non-delta samples %g, delta %g", name, wo_index, total,
			 p_ok, p_delta);
	double p = chi2_test(obs, expct, NZ * NPHI, 5.0);
	double zero_obs = 0;
	for (int i = 0; i < NZ * NPHI; i++)
		if (expct[i] == 0)
			zero_obs += obs[i];
	if (zero_obs > 1e-4 * N_CHI2)
		fail_msg("%s wo %d: %g samples where pdf_w is 0", name, wo_index, zero_obs);
	if (p < alpha_each) {
		for (int i = 0; i < NZ * NPHI; i++) /* where it went wrong */
			if (fabs(obs[i] - expct[i]) > 5 * sqrt(expct[i] + 1))
				print_message("cell z%d phi%d: observed %g expected %g\n", i / NPHI, i % NPHI, obs[i], expct[i]);
		fail_msg("%s wo %d mode %d: chi-square p-value %g < %g (pdf total %g)", name, wo_index, mode, p,
			 alpha_each, total);
	}
	return p;
}

/* Monte Carlo albedo of f |cos_i| / pdf per channel, delta samples included.
 * Importance mode is the energy-conservation integral for every BSDF (the
 * radiance mode of glass from the inside is scaled by eta^2 on purpose). */
V3 albedo(const Bsdf *bs, V3 wo, int mode, uint seed, V3 *sigma)
{
	Rng r = rng_init(seed, 0, 0, 0);
	double s[3] = {0}, s2[3] = {0};
	for (int i = 0; i < N_ALBEDO; i++) {
		BsdfSample x;
		float u0 = rng_f(&r), u1 = rng_f(&r), u2 = rng_f(&r);
		if (!bsdf_sample(bs, wo, u0, u1, u2, mode, &x))
			continue;
		V3 w = v3_scale(x.f, fabs(v3_dot(x.wi, bs->n)) / x.pdf_w);
		assert_true(finite3(w));
		for (int c = 0; c < 3; c++) {
			s[c] += v3_comp(w, c);
			s2[c] += v3_comp(w, c) * v3_comp(w, c);
		}
	}
	V3 mean, sd;
	float *pm = &mean.x, *ps = &sd.x;
	for (int c = 0; c < 3; c++) {
		double mu = s[c] / N_ALBEDO;
		pm[c] = (float)mu;
		ps[c] = (float)sqrt(fmax(s2[c] / N_ALBEDO - mu * mu, 0) / N_ALBEDO);
	}
	*sigma = sd;
	return mean;
}

V3 tilted_n(float deg) { return v3(sinf(deg * (float)M_PI / 180), 0, cosf(deg * (float)M_PI / 180)); }

V3 elev_dir(float elev, float az)
{
	float e = elev * (float)M_PI / 180, a = az * (float)M_PI / 180;
	return v3(cosf(e) * cosf(a), cosf(e) * sinf(a), sinf(e));
}
