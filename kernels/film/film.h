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

INLINE long film_fixed(float v, float u)
{
	if (!(v > 0.0f)) /* also NaN */
		return 0;
	return (long)floor(fmin(v, FILM_MAX) * FILM_SCALE + u);
}
#endif
