/* film.h — how sample values are accumulated: in 64-bit fixed point.
 *
 * Integer addition is associative, so the sum of a pixel's samples does not
 * depend on how samples are split into passes, on which device rendered
 * them, or on the order of atomic splats: a render is bit-identical for the
 * same seed whatever the schedule. Each value is rounded stochastically with
 * a number from the sample's own stream, so the rounding is unbiased. */
#ifndef AJAR_FILM_H
#define AJAR_FILM_H
#include "base/vec.h"

#define FILM_SCALE 1048576.0f /* 2^20: steps of ~1e-6 */
#define FILM_MAX 1.0e6f       /* per-sample clamp that keeps 2^63 out of reach */
/* The most one sample adds to a film value: FILM_MAX at FILM_SCALE,
 * 1,048,576,000,000 (just under 2^40). A pixel's own film holds at most
 * AJAR_MAX_SPP (2^21) of them, 2.2e18, a quarter of 2^63; the splats of
 * light paths (bdpt, portal) have no such bound, and the host checks
 * their sums (src/render/render_film.c). */
#define FILM_SAMPLE_MAX 1048576000000L

INLINE long film_fixed(float v, float u)
{
	if (!(v > 0.0f)) /* also NaN */
		return 0;
	return (long)floor(fmin(v, FILM_MAX) * FILM_SCALE + u);
}
#endif
