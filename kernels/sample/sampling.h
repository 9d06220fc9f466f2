/* sampling.h — warping uniform numbers to directions, points and buckets.
 *
 * Each routine comes with its exact density, and each density names its
 * measure (`_w` solid angle; discrete probabilities for sample_cdf), so the
 * integrators can combine them in MIS. Local directions have z up. The
 * chi-square tests in tests/test_sampling.c check every pair. */
#ifndef AJAR_SAMPLING_H
#define AJAR_SAMPLING_H
#include "base/fastmath.h"
#include "base/vec.h"

/* Shirley–Chiu concentric map of the square onto the unit disk: uniform by
 * area, and it keeps strata compact (less distortion than r = sqrt(u)). */
INLINE void sample_concentric_disk(float u1, float u2, float *x, float *y)
{
	float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
	if (a == 0.0f && b == 0.0f) {
		*x = 0.0f;
		*y = 0.0f;
		return;
	}
	float r, phi;
	if (fabs(a) > fabs(b)) {
		r = a;
		phi = (AJAR_PI * 0.25f) * (b / a);
	} else {
		r = b;
		phi = AJAR_PI * 0.5f - (AJAR_PI * 0.25f) * (a / b);
	}
	float c, s;
	fast_sincos(phi, &s, &c);
	*x = r * c;
	*y = r * s;
}

/* Malley's method: project the disk up onto the hemisphere. */
INLINE V3 sample_cosine_hemisphere(float u1, float u2)
{
	float x, y;
	sample_concentric_disk(u1, u2, &x, &y);
	return v3(x, y, sqrt(fmax(0.0f, 1.0f - x * x - y * y)));
}

INLINE float pdf_cosine_hemisphere_w(float cos_theta) { return cos_theta > 0.0f ? cos_theta * AJAR_INV_PI : 0.0f; }

INLINE V3 sample_uniform_sphere(float u1, float u2)
{
	float z = 1.0f - 2.0f * u1;
	float r = sqrt(fmax(0.0f, 1.0f - z * z));
	float c, sn;
	fast_sincos(AJAR_PI * (2.0f * u2 - 1.0f), &sn, &c); /* a uniform angle */
	return v3(r * c, r * sn, z);
}

INLINE float pdf_uniform_sphere_w(void) { return 0.25f * AJAR_INV_PI; }

/* Uniform over the directions within acos(cos_max) of +z. */
INLINE V3 sample_uniform_cone(float u1, float u2, float cos_max)
{
	float z = 1.0f - u1 * (1.0f - cos_max);
	float r = sqrt(fmax(0.0f, 1.0f - z * z));
	float c, sn;
	fast_sincos(AJAR_PI * (2.0f * u2 - 1.0f), &sn, &c); /* a uniform angle */
	return v3(r * c, r * sn, z);
}

INLINE float pdf_uniform_cone_w(float cos_max)
{
	float solid_angle = 2.0f * AJAR_PI * (1.0f - cos_max);
	return solid_angle > 0.0f ? 1.0f / solid_angle : 0.0f;
}

/* Uniform point on a triangle as barycentrics (b0 = 1 - b1 - b2): the
 * square-root warp is area preserving, so the density is 1 / area. */
INLINE void sample_triangle(float u1, float u2, float *b1, float *b2)
{
	float s = sqrt(u1);
	*b1 = 1.0f - s;
	*b2 = u2 * s;
}

/* A uniform point *p on triangle (p0, p1, p2) and its unit normal *n,
 * (p1 - p0) x (p2 - p0): the CCW front face. */
INLINE void sample_triangle_point(V3 p0, V3 p1, V3 p2, float u1, float u2, V3 *p, V3 *n)
{
	float b1, b2;
	sample_triangle(u1, u2, &b1, &b2);
	V3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
	*p = v3_add(p0, v3_add(v3_scale(e1, b1), v3_scale(e2, b2)));
	*n = v3_norm(v3_cross(e1, e2));
}

/* The last i in [0, n - 1] with cdf[i] <= u and cdf[i] < total (0 if
 * none), in a nondecreasing table of n + 1 entries: a binary search. */
INLINE int cdf_last_below_search(GLOBAL const float *cdf, int lo, int hi, int step, float u, float total)
{
	while (lo < hi) { /* invariant: the answer lies in [lo, hi] */
		int mid = (lo + hi + 1) >> 1;
		float c = cdf[step * mid];
		if (c <= u && c < total)
			lo = mid;
		else
			hi = mid - 1;
	}
	return lo;
}

#if defined(AJAR_DEVICE) && defined(__AVX__) && defined(__clang__)
/* On a CPU with AVX (PoCL), the search runs over every 16th entry and the
 * last 16 are counted in one vector compare: in a nondecreasing table the
 * entries that pass are a prefix, so their count is the answer, and the
 * four steps the count replaces were branches the predictor misses half
 * the time. The same index as the binary search, so the same bits (a sky
 * image's two searches were a fifth of pt's time on PoCL; on GPUs the
 * plain search stays). */
INLINE int cdf_last_below(GLOBAL const float *cdf, int n, float u, float total)
{
	int base = 16 * cdf_last_below_search(cdf, 0, (n - 1) >> 4, 16, u, total);
	if (base + 15 > n) /* the 16 would run past cdf[n] */
		return base + cdf_last_below_search(cdf + base, 0, n - 1 - base, 1, u, total);
	float16 c = vload16(0, cdf + base);
	int16 j = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
	int16 pass = (c <= u) & (c < total) & (j >= 1) & (j <= n - 1 - base); /* -1 or 0 */
	int8 s8 = pass.lo + pass.hi;
	int4 s4 = s8.lo + s8.hi;
	int2 s2 = s4.lo + s4.hi;
	return base - (s2.x + s2.y);
}
#else
INLINE int cdf_last_below(GLOBAL const float *cdf, int n, float u, float total)
{
	return cdf_last_below_search(cdf, 0, n - 1, 1, u, total);
}
#endif

/* Bucket i of a tabulated CDF (n + 1 entries, cdf[0] = 0, cdf[n] = 1) with
 * cdf[i] <= u < cdf[i + 1]. Zero-width buckets are never returned: the
 * search finds the last i with cdf[i] <= u, which is past any run of equal
 * entries, and also requires cdf[i] < cdf[n] so that u at or above the end
 * lands in the last non-empty bucket. *pdf is the bucket's discrete
 * probability; *u_remap reuses u's remaining bits, uniform in [0, 1).
 * Returns -1 with *pdf = 0 if the table is empty (cdf[n] <= 0). */
INLINE int sample_cdf(GLOBAL const float *cdf, int n, float u, float *pdf, float *u_remap)
{
	float total = cdf[n];
	*pdf = 0.0f;
	*u_remap = 0.0f;
	if (!(total > 0.0f) || n < 1)
		return -1;
	u = fmax(u, 0.0f);
	int lo = cdf_last_below(cdf, n, u, total);
	float width = cdf[lo + 1] - cdf[lo];
	if (!(width > 0.0f)) /* only for a malformed table (cdf[0] > 0) */
		return -1;
	*pdf = width;
	*u_remap = fmin(fmax((u - cdf[lo]) / width, 0.0f), 0.99999994f);
	return lo;
}

#endif
