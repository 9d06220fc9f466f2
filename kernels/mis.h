/* mis.h — multiple importance sampling heuristics (Veach 1997, ch. 9). */
#ifndef AJAR_MIS_H
#define AJAR_MIS_H
#include "compat.h"

/* Power heuristic (beta = 2) weight of a strategy with density a against
 * one with density b, both in the same measure. */
INLINE float mis_power(float a, float b)
{
	if (!(a > 0.0f))
		return 0.0f;
	float r = b / a; /* a ratio: squares of raw densities overflow */
	return 1.0f / (1.0f + r * r);
}

INLINE float mis_balance(float a, float b)
{
	if (!(a > 0.0f))
		return 0.0f;
	return 1.0f / (1.0f + b / a);
}
#endif
