/* fastmath.h — log, exp, atan2 and sin/cos as fixed polynomials, the same
 * on the host and every device, accurate to a few float ulps (tests:
 * test_sampling.c, test_fast_math).
 *
 * PoCL's CPU device computes these with generic library code (SLEEF's logf,
 * an atan2 and a sin/cos argument reduction built for any input) that took
 * a quarter of a window-room path-tracing sample and 15% of a portal sample
 * in its log alone; the integrators only ever need moderate ranges. */
#ifndef AJAR_FASTMATH_H
#define AJAR_FASTMATH_H
#include "base/compat.h"

/* Natural log of x > 0; -AJAR_INF for 0 (and for anything not > 0),
 * AJAR_INF for +inf. Absolute error below 2e-7 for |log x| <= 1, relative
 * error below that beyond. */
INLINE float fast_log(float x)
{
	if (!(x > 0.0f))
		return -AJAR_INF;
	uint b = f2u(x);
	if (b >= 0x7f800000u) /* +inf */
		return AJAR_INF;
	float e = 0.0f;
	if (b < 0x00800000u) { /* subnormal: scale by 2^23 */
		b = f2u(x * 8388608.0f);
		e = -23.0f;
	}
	e += (float)((int)(b >> 23) - 127);
	float m = u2f((b & 0x007fffffu) | 0x3f800000u); /* [1, 2) */
	if (m > 1.41421356f) {
		m *= 0.5f;
		e += 1.0f;
	}
	/* ln m = 2 atanh t, t = (m - 1) / (m + 1), |t| < 0.172: five terms
	 * leave an error below 1e-9. */
	float t = (m - 1.0f) / (m + 1.0f), t2 = t * t;
	float s = 2.0f * t * (1.0f + t2 * (0.33333333f + t2 * (0.2f + t2 * (0.14285714f + t2 * 0.11111111f))));
	return e * 0.69314718f + s;
}

/* e^x: 0 below -87 (and for NaN), AJAR_INF above 88; relative error below
 * 2e-7 in between. */
INLINE float fast_exp(float x)
{
	if (!(x > -87.0f))
		return 0.0f;
	if (x > 88.0f)
		return AJAR_INF;
	/* e^x = 2^n e^g with |g| <= ln2 / 2: Taylor to g^7, error below 1e-8.
	 * ln2 in two parts (Cody and Waite): n times the first is exact. */
	float n = floor(x * 1.44269504f + 0.5f);
	float g = (x - n * 0.693145751953125f) - n * 1.428606765330187e-6f;
	float p = 1.0f + g * (1.0f + g * (0.5f + g * (0.16666667f + g * (0.041666667f + g * (0.0083333333f +
		g * (0.0013888889f + g * 0.00019841270f))))));
	return p * u2f((uint)((int)n + 127) << 23);
}

/* atan of |t| <= tan(pi / 8): Taylor to t^17, relative error below 1e-8. */
INLINE float fast_atan_small(float t)
{
	float t2 = t * t;
	float p = -0.058823529f;
	p = 0.066666667f + t2 * p;
	p = -0.076923077f + t2 * p;
	p = 0.090909091f + t2 * p;
	p = -0.11111111f + t2 * p;
	p = 0.14285714f + t2 * p;
	p = -0.2f + t2 * p;
	p = 0.33333333f + t2 * p;
	return t - t * t2 * p;
}

/* atan2(y, x) in [-pi, pi], 0 for (0, 0); absolute error below 3e-7. */
INLINE float fast_atan2(float y, float x)
{
	float ax = fabs(x), ay = fabs(y);
	float hi = ax > ay ? ax : ay, lo = ax > ay ? ay : ax;
	if (!(hi > 0.0f))
		return 0.0f;
	float z = lo / hi; /* [0, 1] */
	float r = z > 0.41421356f ? 0.78539816f + fast_atan_small((z - 1.0f) / (z + 1.0f)) : fast_atan_small(z);
	if (ay > ax)
		r = 1.57079633f - r;
	if (x < 0.0f)
		r = AJAR_PI - r;
	return y < 0.0f ? -r : r;
}

/* sin and cos of |x| <= pi; absolute error below 3e-7. */
INLINE void fast_sincos(float x, float *s, float *c)
{
	float a = fabs(x);
	int back = a > 1.57079633f; /* sin(pi - a) = sin a, cos(pi - a) = -cos a */
	if (back)
		a = AJAR_PI - a;
	float a2 = a * a;
	/* Taylor to a^13 and a^14: errors below 1e-8 at pi / 2. */
	float ps = 1.6059044e-10f;
	ps = -2.5052108e-8f + a2 * ps;
	ps = 2.7557319e-6f + a2 * ps;
	ps = -1.9841270e-4f + a2 * ps;
	ps = 0.0083333333f + a2 * ps;
	ps = -0.16666667f + a2 * ps;
	ps = a + a * a2 * ps;
	float pc = 2.0876757e-9f;
	pc = -2.7557319e-7f + a2 * pc;
	pc = 2.4801587e-5f + a2 * pc;
	pc = -0.0013888889f + a2 * pc;
	pc = 0.041666667f + a2 * pc;
	pc = -0.5f + a2 * pc;
	pc = 1.0f + a2 * pc;
	*s = x < 0.0f ? -ps : ps;
	*c = back ? -pc : pc;
}
#endif
