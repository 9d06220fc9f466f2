/* test_sampling.c — kernels/sample/sampling.h and kernels/sample/rng.h on the host.
 *
 * Every warp is histogrammed and compared with its density by a chi-square
 * test (cells whose exact probability is known in closed form); sample_cdf
 * against its discrete probabilities, zero-width buckets included; the RNG
 * for determinism, range, uniformity and decorrelation of neighbours; the
 * polynomial log, exp, atan2 and sin/cos of kernels/base/fastmath.h against
 * double precision over the ranges they promise; Russian roulette
 * (kernels/sample/roulette.h) for its survival probability and an unchanged
 * expected throughput; the low-discrepancy numbers of kernels/sample/qmc.h and
 * rng.h for their net structure, uniformity and independence. */
#include "testutil.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/fastmath.h"
#include "sample/rng.h"
#include "sample/roulette.h"
#include "sample/sampling.h"
#include "material/texture.h"

#define N_SAMPLES 1000000
#define N_TESTS 13 /* chi-square tests in this file, for the Sidak correction */
#define ALPHA_TOTAL 1e-3

static double alpha_each(void) { return 1.0 - pow(1.0 - ALPHA_TOTAL, 1.0 / N_TESTS); }

static void check_chi2(const char *what, const double *obs, const double *expct, int n)
{
	double p = chi2_test(obs, expct, n, 5.0);
	if (p < alpha_each())
		fail_msg("%s: chi-square p-value %g below %g", what, p, alpha_each());
	/* chi2_test pools cells of small expectation; samples where the
	 * density is exactly zero must not occur at all. */
	for (int i = 0; i < n; i++)
		if (expct[i] == 0.0 && obs[i] > 0.0)
			fail_msg("%s: %g samples in cell %d of zero probability", what, obs[i], i);
}

/* Histogram of directions over (cos theta in [zmin, 1], phi) cells. */
#define NZ 30
#define NPHI 60
static int dir_cell(V3 w, float zmin)
{
	int iz = (int)floor((w.z - zmin) / (1.0f - zmin) * NZ);
	double phi = atan2((double)w.y, (double)w.x);
	if (phi < 0)
		phi += 2 * M_PI;
	int ip = (int)(phi / (2 * M_PI) * NPHI);
	iz = iz < 0 ? 0 : (iz >= NZ ? NZ - 1 : iz);
	ip = ip < 0 ? 0 : (ip >= NPHI ? NPHI - 1 : ip);
	return iz * NPHI + ip;
}

static void test_cosine_hemisphere(void **state)
{
	(void)state;
	static double obs[NZ * NPHI], expct[NZ * NPHI];
	memset(obs, 0, sizeof(obs));
	Rng r = rng_init(1, 2, 3, 4);
	for (int i = 0; i < N_SAMPLES; i++) {
		V3 w = sample_cosine_hemisphere(rng_f(&r), rng_f(&r));
		assert_true(fabs(v3_len(w) - 1.0f) < 1e-5f && w.z >= 0.0f);
		obs[dir_cell(w, 0.0f)] += 1;
	}
	/* integral of cos / pi over a (z, phi) cell = (z1^2 - z0^2) / 2 * dphi / pi */
	for (int iz = 0; iz < NZ; iz++)
		for (int ip = 0; ip < NPHI; ip++) {
			double z0 = (double)iz / NZ, z1 = (double)(iz + 1) / NZ;
			expct[iz * NPHI + ip] = N_SAMPLES * (z1 * z1 - z0 * z0) / 2 * (2 * M_PI / NPHI) / M_PI;
		}
	check_chi2("cosine hemisphere", obs, expct, NZ * NPHI);
	assert_float_equal(pdf_cosine_hemisphere_w(0.5f), 0.5f / M_PI, 1e-7);
	assert_float_equal(pdf_cosine_hemisphere_w(-0.5f), 0.0f, 0.0);
}

/* Uniform sphere and cone: constant density over z in [zmin, 1]. */
static void check_uniform_cap(const char *what, float zmin, int cone)
{
	static double obs[NZ * NPHI], expct[NZ * NPHI];
	memset(obs, 0, sizeof(obs));
	Rng r = rng_init(7, (uint)(zmin * 1000.0f + 1000.0f), 0, 1);
	for (int i = 0; i < N_SAMPLES; i++) {
		float u1 = rng_f(&r), u2 = rng_f(&r);
		V3 w = cone ? sample_uniform_cone(u1, u2, zmin) : sample_uniform_sphere(u1, u2);
		assert_true(fabs(v3_len(w) - 1.0f) < 1e-5f && w.z >= zmin - 1e-6f);
		obs[dir_cell(w, zmin)] += 1;
	}
	for (int i = 0; i < NZ * NPHI; i++)
		expct[i] = (double)N_SAMPLES / (NZ * NPHI);
	check_chi2(what, obs, expct, NZ * NPHI);
	double pdf = cone ? pdf_uniform_cone_w(zmin) : pdf_uniform_sphere_w();
	assert_float_equal(pdf * 2 * M_PI * (1 - zmin), 1.0, 1e-5);
}

static void test_uniform_sphere(void **state)
{
	(void)state;
	check_uniform_cap("uniform sphere", -1.0f, 0);
}

static void test_uniform_cone(void **state)
{
	(void)state;
	check_uniform_cap("uniform cone 0.3", 0.3f, 1);
	check_uniform_cap("uniform cone 0.99", 0.99f, 1);
	assert_float_equal(pdf_uniform_cone_w(1.0f), 0.0f, 0.0);
}

/* Square cells of [-1, 1]^2; expected from the disk's area in each cell. */
#define ND 40
static void test_concentric_disk(void **state)
{
	(void)state;
	static double obs[ND * ND], expct[ND * ND];
	memset(obs, 0, sizeof(obs));
	Rng r = rng_init(11, 0, 0, 0);
	for (int i = 0; i < N_SAMPLES; i++) {
		float x, y;
		sample_concentric_disk(rng_f(&r), rng_f(&r), &x, &y);
		assert_true(x * x + y * y <= 1.0f + 1e-6f);
		int ix = (int)((x + 1.0f) * 0.5f * ND), iy = (int)((y + 1.0f) * 0.5f * ND);
		ix = ix >= ND ? ND - 1 : ix;
		iy = iy >= ND ? ND - 1 : iy;
		obs[iy * ND + ix] += 1;
	}
	/* Area of the disk in each cell by a fine midpoint grid. */
	const int sub = 64;
	for (int iy = 0; iy < ND; iy++)
		for (int ix = 0; ix < ND; ix++) {
			int in = 0;
			for (int j = 0; j < sub; j++)
				for (int k = 0; k < sub; k++) {
					double x = -1 + 2.0 * (ix + (k + 0.5) / sub) / ND;
					double y = -1 + 2.0 * (iy + (j + 0.5) / sub) / ND;
					in += x * x + y * y < 1;
				}
			double area = (2.0 / ND) * (2.0 / ND) * in / (sub * sub);
			expct[iy * ND + ix] = N_SAMPLES * area / M_PI;
		}
	/* Cells cut by the circle have only approximate expectations; the
	 * midpoint grid is accurate to ~1e-4 of a cell, well inside the noise. */
	double p = chi2_test(obs, expct, ND * ND, 5.0);
	if (p < alpha_each())
		fail_msg("concentric disk: chi-square p-value %g", p);
	float x, y;
	sample_concentric_disk(0.5f, 0.5f, &x, &y);
	assert_true(x == 0.0f && y == 0.0f);
}

/* Barycentrics on a square grid over [0, 1]^2: the diagonal b1 + b2 = 1
 * passes through cell corners, so cells are whole, half or empty. */
#define NT 40
static void test_triangle(void **state)
{
	(void)state;
	static double obs[NT * NT], expct[NT * NT];
	memset(obs, 0, sizeof(obs));
	Rng r = rng_init(13, 0, 0, 0);
	for (int i = 0; i < N_SAMPLES; i++) {
		float b1, b2;
		sample_triangle(rng_f(&r), rng_f(&r), &b1, &b2);
		assert_true(b1 >= 0.0f && b2 >= 0.0f && b1 + b2 <= 1.0f + 1e-6f);
		int i1 = (int)(b1 * NT), i2 = (int)(b2 * NT);
		i1 = i1 >= NT ? NT - 1 : i1;
		i2 = i2 >= NT ? NT - 1 : i2;
		obs[i2 * NT + i1] += 1;
	}
	double cell = 2.0 / (NT * NT); /* probability of a whole cell (density 2) */
	for (int i2 = 0; i2 < NT; i2++)
		for (int i1 = 0; i1 < NT; i1++)
			expct[i2 * NT + i1] = N_SAMPLES * (i1 + i2 < NT - 1 ? cell : (i1 + i2 == NT - 1 ? cell / 2 : 0));
	check_chi2("triangle", obs, expct, NT * NT);
}

static void test_cdf(void **state)
{
	(void)state;
	/* Zero-width buckets first, inside, and last. */
	const float w[] = {0, 1, 3, 0, 0, 2, 0.5f, 0};
	const int n = (int)(sizeof(w) / sizeof(w[0]));
	float cdf[sizeof(w) / sizeof(w[0]) + 1];
	double sum = 0;
	for (int i = 0; i < n; i++)
		sum += w[i];
	double acc = 0;
	cdf[0] = 0;
	for (int i = 0; i < n; i++) {
		acc += w[i];
		cdf[i + 1] = (float)(acc / sum);
	}
	cdf[n] = 1;
	double obs[sizeof(w) / sizeof(w[0])] = {0}, expct[sizeof(w) / sizeof(w[0])];
	enum { NR = 20 };
	double remap[NR] = {0}, remap_exp[NR];
	Rng r = rng_init(17, 0, 0, 0);
	for (int s = 0; s < N_SAMPLES; s++) {
		float pdf, ur, u = rng_f(&r);
		int i = sample_cdf(cdf, n, u, &pdf, &ur);
		assert_true(i >= 0 && i < n);
		assert_true(w[i] > 0);
		assert_float_equal(pdf, w[i] / sum, 1e-6);
		assert_true(ur >= 0.0f && ur < 1.0f);
		obs[i] += 1;
		if (i == 2)
			remap[(int)(ur * NR)] += 1;
	}
	for (int i = 0; i < n; i++)
		expct[i] = N_SAMPLES * w[i] / sum;
	check_chi2("sample_cdf buckets", obs, expct, n);
	for (int i = 0; i < NR; i++)
		remap_exp[i] = obs[2] / NR;
	check_chi2("sample_cdf u_remap", remap, remap_exp, NR);

	/* The ends: u = 0 skips the leading empty bucket, u just below 1 (and
	 * u = 1) stay out of the trailing one. */
	float pdf, ur;
	assert_int_equal(sample_cdf(cdf, n, 0.0f, &pdf, &ur), 1);
	assert_float_equal(ur, 0.0f, 0.0);
	assert_int_equal(sample_cdf(cdf, n, 0.99999994f, &pdf, &ur), 6);
	assert_int_equal(sample_cdf(cdf, n, 1.0f, &pdf, &ur), 6);
	assert_true(ur < 1.0f);
	/* Exactly on an interior boundary: the bucket that starts there. */
	assert_int_equal(sample_cdf(cdf, n, cdf[5], &pdf, &ur), 5);
	/* An empty table gives no bucket. */
	const float empty[3] = {0, 0, 0};
	assert_int_equal(sample_cdf(empty, 2, 0.5f, &pdf, &ur), -1);
	assert_float_equal(pdf, 0.0f, 0.0);
	/* One bucket. */
	const float one[2] = {0, 1};
	assert_int_equal(sample_cdf(one, 1, 0.25f, &pdf, &ur), 0);
	assert_float_equal(pdf, 1.0f, 0.0);
	assert_float_equal(ur, 0.25f, 0.0);
}

static void test_rng_deterministic(void **state)
{
	(void)state;
	Rng a = rng_init(42, 1000, 7, 2), b = rng_init(42, 1000, 7, 2);
	for (int i = 0; i < 1000; i++)
		assert_int_equal(rng_u32(&a), rng_u32(&b));
	/* Any one input changed gives another sequence. */
	const uint in[5][4] = {{43, 1000, 7, 2}, {42, 1001, 7, 2}, {42, 1000, 8, 2}, {42, 1000, 7, 3}, {0, 0, 0, 0}};
	for (int k = 0; k < 5; k++) {
		Rng x = rng_init(42, 1000, 7, 2), y = rng_init(in[k][0], in[k][1], in[k][2], in[k][3]);
		int same = 0;
		for (int i = 0; i < 64; i++)
			same += rng_u32(&x) == rng_u32(&y);
		assert_true(same < 4);
	}
	/* Pinned values: renders are repeatable across versions only if the
	 * stream never changes (PoCL gave these same bits when written). */
	Rng z = rng_init(0, 0, 0, 0);
	assert_int_equal(rng_u32(&z), 758717757u);
	assert_int_equal(rng_u32(&z), 2854040001u);
	Rng q = rng_init(42, 1000, 7, 2);
	assert_int_equal(rng_u32(&q), 1420759174u);
	assert_int_equal(rng_u32(&q), 3694288159u);
}

static void test_rng_uniform(void **state)
{
	(void)state;
	enum { NB = 100 };
	double obs[NB] = {0}, expct[NB];
	Rng r = rng_init(5, 6, 7, 8);
	for (int i = 0; i < N_SAMPLES; i++) {
		float u = rng_f(&r);
		assert_true(u >= 0.0f && u < 1.0f);
		obs[(int)(u * NB)] += 1;
	}
	for (int i = 0; i < NB; i++)
		expct[i] = (double)N_SAMPLES / NB;
	check_chi2("rng_f uniform", obs, expct, NB);

	/* Neighbouring pixels (and samples) must be independent: the pair of
	 * first numbers of pixel p and p + 1 is uniform on the square. */
	enum { NP = 32 };
	static double pair[NP * NP], pair_exp[NP * NP];
	memset(pair, 0, sizeof(pair));
	const int npairs = N_SAMPLES / 4;
	for (int p = 0; p < npairs; p++) {
		Rng a = rng_init(9, (uint)p, 0, 0), b = rng_init(9, (uint)p + 1, 0, 0);
		Rng c = rng_init(9, (uint)p, 1, 0);
		float ua = rng_f(&a), ub = rng_f(&b), uc = rng_f(&c);
		pair[(int)(ua * NP) * NP + (int)(ub * NP)] += 1;
		pair[(int)(ua * NP) * NP + (int)(uc * NP)] += 1;
	}
	for (int i = 0; i < NP * NP; i++)
		pair_exp[i] = 2.0 * npairs / (NP * NP);
	check_chi2("rng neighbours", pair, pair_exp, NP * NP);
}

/* fastmath.h against libm in double: log over every binade (subnormals
 * included), exp over (-87, 88), atan2 around the circle at magnitudes from
 * 1e-30 to 1e30, sin/cos over [-pi, pi]; and the limits. */
static void test_fast_math(void **state)
{
	(void)state;
	double e_log = 0.0, e_exp = 0.0, e_atan = 0.0, e_atan_rel = 0.0, e_sc = 0.0;
	for (int i = 0; i < 300000; i++) {
		float x = (float)exp2(-149.0 + 277.0 * (i + 0.5) / 300000.0); /* [2^-149, 2^128) */
		if (!(x > 0.0f) || !(x < FLT_MAX))
			continue;
		double ref = log((double)x);
		e_log = fmax(e_log, fabs(fast_log(x) - ref) / fmax(1.0, fabs(ref)));
	}
	for (int i = 0; i < 300000; i++) {
		float x = -86.99f + 174.98f * (float)i / 300000.0f;
		double ref = exp((double)x);
		e_exp = fmax(e_exp, fabs(fast_exp(x) - ref) / ref);
	}
	for (int i = 0; i < 200000; i++) {
		double a = -M_PI + 2.0 * M_PI * (i + 0.5) / 200000.0, r = pow(10.0, -30.0 + 60.0 * (i % 61) / 60.0);
		float y = (float)(r * sin(a)), x = (float)(r * cos(a));
		double ref = atan2((double)y, (double)x), got = fast_atan2(y, x);
		e_atan = fmax(e_atan, fabs(got - ref));
		if (fabs(ref) < 0.1) /* small angles (small solid angles): relative */
			e_atan_rel = fmax(e_atan_rel, fabs(got - ref) / fmax(fabs(ref), 1e-30));
		float s, c;
		float t = (float)a;
		fast_sincos(t, &s, &c);
		e_sc = fmax(e_sc, fmax(fabs(s - sin((double)t)), fabs(c - cos((double)t))));
	}
	printf("fast_log %.2e, fast_exp %.2e (relative), fast_atan2 %.2e (%.2e relative below 0.1), fast_sincos %.2e\n",
	       e_log, e_exp, e_atan, e_atan_rel, e_sc);
	assert_true(e_log < 3e-7);
	assert_true(e_exp < 3e-7);
	assert_true(e_atan < 3e-7);
	assert_true(e_atan_rel < 1e-6);
	assert_true(e_sc < 3e-7);
	/* sRGB decoding (texture.h) through them: within 1e-6 relative of
	 * the exact power over [0, 1], the 8-bit values included. */
	double e_srgb = 0.0;
	for (int i = 0; i <= 25500; i++) {
		float v = (float)i / 25500.0f;
		double ref = v <= 0.04045f ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
		e_srgb = fmax(e_srgb, fabs(srgb_to_linear(v) - ref) / fmax(ref, 1e-30));
	}
	printf("srgb_to_linear %.2e (relative)\n", e_srgb);
	assert_true(e_srgb < 1e-6);
	assert_true(srgb_to_linear(0.0f) == 0.0f && fabs(srgb_to_linear(1.0f) - 1.0f) < 1e-6f);
	/* Limits. */
	assert_true(fast_log(0.0f) == -AJAR_INF && fast_log(-1.0f) == -AJAR_INF);
	assert_true(fast_log(INFINITY) == AJAR_INF);
	assert_true(fast_log(1.0f) == 0.0f);
	assert_true(fast_exp(0.0f) == 1.0f && fast_exp(-100.0f) == 0.0f && fast_exp(NAN) == 0.0f);
	assert_true(fast_exp(100.0f) == AJAR_INF);
	assert_true(fast_atan2(0.0f, 0.0f) == 0.0f && fast_atan2(0.0f, -1.0f) == AJAR_PI);
	assert_true(fabs(fast_atan2(1.0f, 0.0f) - M_PI / 2) < 1e-7 && fabs(fast_atan2(-1.0f, 0.0f) + M_PI / 2) < 1e-7);
	float s, c;
	fast_sincos(AJAR_PI, &s, &c);
	assert_true(fabs(s) < 1e-6 && c == -1.0f);
}

/* Survivors are counted against q = min(boost max(beta) / beta_ref,
 * RR_MAX_SURVIVAL) within 5 binomial standard errors, and the mean of the
 * throughput afterwards (0 for a walk that ended) must equal beta: that
 * is what keeps the estimate unbiased. */
static void test_roulette(void **state)
{
	(void)state;
	const struct {
		V3 beta;
		float ref, boost;
	} cases[] = {
		{{0.05f, 0.02f, 0.01f}, 1.0f, RR_BOOST},            /* dark: mostly ends */
		{{0.3f, 0.5f, 0.1f}, 1.2f, RR_BOOST_CONNECTED},    /* relative to beta_ref, below the cap */
		{{0.3f, 0.5f, 0.1f}, 1.2f, RR_BOOST},              /* the same, the larger boost */
		{{0.9f, 0.9f, 0.9f}, 1.0f, RR_BOOST_CONNECTED},    /* bright: capped at RR_MAX_SURVIVAL */
		{{1e-6f, 0.0f, 0.0f}, 1e-3f, RR_BOOST},
	};
	const int n = 400000;
	for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
		Rng rng = rng_init(99, (uint)c, 0, 0);
		double q = fmin(cases[c].boost * v3_maxc(cases[c].beta) / cases[c].ref, RR_MAX_SURVIVAL);
		double alive = 0.0, sum[3] = {0.0, 0.0, 0.0};
		for (int i = 0; i < n; i++) {
			V3 b = cases[c].beta;
			if (rr_survive(&b, cases[c].ref, cases[c].boost, &rng)) {
				alive += 1.0;
				sum[0] += b.x;
				sum[1] += b.y;
				sum[2] += b.z;
			}
		}
		double se = sqrt(q * (1.0 - q) / n);
		printf("roulette case %zu: survived %.5f, q %.5f (se %.1e)\n", c, alive / n, q, se);
		assert_true(fabs(alive / n - q) < 5.0 * se + 1e-12);
		const float *bc = &cases[c].beta.x;
		for (int k = 0; k < 3; k++) {
			double want = bc[k], got = sum[k] / n;
			/* beta / q per survivor: relative standard error sqrt((1 - q) / (q n)) */
			double tol = 5.0 * want * sqrt((1.0 - q) / (q * n)) + 1e-7 * want;
			if (fabs(got - want) > tol)
				fail_msg("roulette case %zu channel %d: mean %g, want %g", c, k, got, want);
		}
	}
}

/* Whether points[0, 2^k) form a (0,k,2)-net: one point in every cell of
 * each 2^a x 2^(k-a) grid. */
static int is_net(const float *x, const float *y, int k)
{
	int n = 1 << k;
	static unsigned char seen[1 << 12];
	for (int a = 0; a <= k; a++) {
		memset(seen, 0, (size_t)n);
		for (int i = 0; i < n; i++) {
			int cx = (int)(x[i] * (float)(1 << a)), cy = (int)(y[i] * (float)(1 << (k - a)));
			int c = (cx << (k - a)) | cy;
			if (seen[c]++)
				return 0;
		}
	}
	return 1;
}

/* Every pair of every pixel: the first 2^k samples form a (0,k,2)-net
 * (the shuffle keeps them together), for k up to 12; the first 2^k of
 * a later block too. */
static void test_qmc_nets(void **state)
{
	(void)state;
	static float x[1 << 12], y[1 << 12];
	for (uint seed = 1; seed < 40; seed += 7)
		for (uint pair = 0; pair < 20; pair += 3)
			for (int k = 1; k <= 12; k += 1 + (k > 4)) {
				for (int i = 0; i < (1 << k); i++)
					qmc_pair((uint)i, pair, seed * 2654435761u, &x[i], &y[i]);
				if (!is_net(x, y, k))
					fail_msg("seed %u pair %u: the first %d samples are not a (0,%d,2)-net", seed, pair, 1 << k, k);
				for (int i = 0; i < (1 << k); i++) {
					assert_true(x[i] >= 0.0f && x[i] < 1.0f && y[i] >= 0.0f && y[i] < 1.0f);
					assert_true(x[i] == qmc_f((uint)i, 2 * pair, seed * 2654435761u));
					assert_true(y[i] == qmc_f((uint)i, 2 * pair + 1, seed * 2654435761u));
				}
			}
	/* Samples 3 * 2^8 .. 4 * 2^8 - 1: an aligned block is a net too. */
	for (int i = 0; i < 256; i++)
		qmc_pair((uint)(768 + i), 5, 12345u, &x[i], &y[i]);
	assert_true(is_net(x, y, 8));
}

/* One sample index, many pixels: each point of a pair is uniform on the
 * square (Owen scrambling), for the first sample and a later one. And
 * two pairs of the same pixel and sample are independent: without the
 * shuffle their coordinates would be tied by the common index. */
static void test_qmc_uniform(void **state)
{
	(void)state;
	enum { NP = 32 };
	static double obs[NP * NP], expct[NP * NP];
	const int n = N_SAMPLES / 4;
	for (int c = 0; c < NP * NP; c++)
		expct[c] = (double)n / (NP * NP);
	const uint index[2] = {0u, 37u};
	for (int t = 0; t < 2; t++) {
		memset(obs, 0, sizeof(obs));
		for (int p = 0; p < n; p++) {
			float q[RNG_QMC_FLOATS];
			rng_qmc_table(3, (uint)p, index[t], q);
			Rng r = rng_init_pixel(3, (uint)p, index[t], q);
			float u, v;
			rng_pixel(&r, &u, &v);
			obs[(int)(u * NP) * NP + (int)(v * NP)] += 1;
		}
		check_chi2(t ? "qmc pixel pair, sample 37" : "qmc pixel pair, sample 0", obs, expct, NP * NP);
	}
	/* Within one pixel: x of pair 0 against x of pair 1 over the samples. */
	memset(obs, 0, sizeof(obs));
	for (int p = 0; p < n / 1024; p++)
		for (uint i = 0; i < 1024; i++) {
			float a = qmc_f(i, 0, (uint)p * 747796405u + 1u), b = qmc_f(i, 2, (uint)p * 747796405u + 1u);
			obs[(int)(a * NP) * NP + (int)(b * NP)] += 1;
		}
	for (int c = 0; c < NP * NP; c++)
		expct[c] = (double)(n / 1024 * 1024) / (NP * NP);
	check_chi2("qmc pairs independent", obs, expct, NP * NP);
}

/* The sequences' bookkeeping: the pixel pair and the scattering pairs of
 * the main sequence, the next-event sequence beside it, PCG once each is
 * used up, and streams without low-discrepancy numbers unchanged. */
static void test_rng_sequences(void **state)
{
	(void)state;
	float q[RNG_QMC_FLOATS];
	rng_qmc_table(9, 77, 5, q);
	Rng r = rng_init_pixel(9, 77, 5, q), pcg = rng_init(9, 77, 5, 0);
	uint seed = rng_qmc_seed(9, 77);
	float u0, u1, u2, jx, jy;
	rng_pixel(&r, &jx, &jy);
	assert_true(jx == qmc_f(5, 0, seed) && jy == qmc_f(5, 1, seed));
	rng_nee3(&r, &u0, &u1, &u2);
	assert_true(u1 == qmc_f(5, RNG_QMC_DIMS, seed) && u2 == qmc_f(5, RNG_QMC_DIMS + 1, seed));
	assert_true(u0 == qmc_f(5, RNG_QMC_DIMS + 2, seed));
	rng_f3(&r, &u0, &u1, &u2);
	assert_true(u1 == qmc_f(5, 2, seed) && u2 == qmc_f(5, 3, seed));
	/* The lobe, and rng_f, are PCG: the same numbers as the plain stream. */
	assert_true(u0 == rng_pcg_f(&pcg));
	assert_true(rng_f(&r) == rng_pcg_f(&pcg));
	/* Used up: both sequences go on with PCG. */
	while (r.dim + 2u <= RNG_QMC_DIMS)
		rng_f3(&r, &u0, &u1, &u2);
	while (r.nee_dim + 2u <= RNG_QMC_DIMS)
		rng_nee3(&r, &u0, &u1, &u2);
	Rng copy = r;
	rng_f3(&r, &u0, &u1, &u2);
	assert_true(u0 == rng_pcg_f(&copy) && u1 == rng_pcg_f(&copy) && u2 == rng_pcg_f(&copy));
	rng_nee3(&r, &u0, &u1, &u2);
	assert_true(u0 == rng_pcg_f(&copy) && u1 == rng_pcg_f(&copy) && u2 == rng_pcg_f(&copy));
	/* A stream from rng_init has no low-discrepancy part. */
	Rng a = rng_init(1, 2, 3, 4), b = rng_init(1, 2, 3, 4);
	rng_f3(&a, &u0, &u1, &u2);
	assert_true(u0 == rng_pcg_f(&b) && u1 == rng_pcg_f(&b) && u2 == rng_pcg_f(&b));
	/* Forks are PCG streams of their own, repeatable. */
	Rng f1 = rng_init_pixel(9, 77, 5, q), f2 = rng_init_pixel(9, 77, 5, q);
	Rng g1 = rng_fork(&f1), g2 = rng_fork(&f2);
	assert_int_equal(g1.dim, RNG_QMC_DIMS);
	for (int i = 0; i < 16; i++)
		assert_int_equal(rng_u32(&g1), rng_u32(&g2));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cosine_hemisphere), cmocka_unit_test(test_uniform_sphere),
		cmocka_unit_test(test_uniform_cone),      cmocka_unit_test(test_concentric_disk),
		cmocka_unit_test(test_triangle),          cmocka_unit_test(test_cdf),
		cmocka_unit_test(test_rng_deterministic), cmocka_unit_test(test_rng_uniform),
		cmocka_unit_test(test_fast_math),         cmocka_unit_test(test_roulette),
		cmocka_unit_test(test_qmc_nets),          cmocka_unit_test(test_qmc_uniform),
		cmocka_unit_test(test_rng_sequences),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
