/* roulette.h — Russian roulette, one rule for every walk.
 *
 * A walk that continues with throughput beta survives with probability
 * q = min(RR_BOOST max(beta) / beta_ref, RR_MAX_SURVIVAL) and carries
 * beta / q on; any q in (0, 1] keeps the estimate unbiased, so the rule only
 * trades variance against time.
 *
 * beta_ref is what "a throughput that still matters" means for the walk.
 * For a camera walk it is the throughput after the first scattering, not 1:
 * a pixel's value already carries the albedo of the surface it sees, so on
 * a dark carpet (albedo 0.1) an absolute rule would end nine walks in ten at
 * the second bounce, and the pixel's indirect light, which is most of its
 * value, would rest on a tenth of the samples. Relative to the pixel, what
 * matters is the throughput since that first scattering (the idea behind
 * adjoint-driven Russian roulette, Vorba and Krivanek 2016, with the pixel's
 * albedo standing in for its estimate). RR_BOOST trades longer camera walks
 * against their cost: 2 helped pt, window-room and living-room more but cost
 * door-ajar's portal integrator, whose every eye vertex connects to many
 * light vertices, 10% in efficiency; 1.5 leaves door-ajar and bathroom
 * even and makes window-room and living-room 1.65x as efficient (README). */
#ifndef AJAR_ROULETTE_H
#define AJAR_ROULETTE_H
#include "rng.h"
#include "vec.h"

#define RR_BOOST 1.5f
#define RR_MAX_SURVIVAL 0.95f

/* Plays the roulette on *beta: 0 if the walk ends, else 1 with *beta
 * divided by the survival probability. */
INLINE int rr_survive(V3 *beta, float beta_ref, Rng *rng)
{
	float q = fmin(RR_BOOST * v3_maxc(*beta) / beta_ref, RR_MAX_SURVIVAL);
	if (!(rng_f(rng) < q))
		return 0;
	*beta = v3_scale(*beta, 1.0f / q);
	return 1;
}

#endif
