/* rng.h — the random number stream of one pixel sample.
 *
 * Counter-based seeding: (seed, pixel, sample index, stream) is hashed with
 * the splitmix64 finaliser into the state and the stream selector of a PCG32
 * generator (O'Neill 2014, XSH-RR output). The hash makes neighbouring
 * pixels and samples independent streams, and the same four numbers give the
 * same sequence on every device and on the host, so renders are repeatable
 * bit for bit and several devices can render disjoint samples. */
#ifndef AJAR_RNG_H
#define AJAR_RNG_H
#include "compat.h"

typedef struct {
	ulong state;
	ulong inc; /* odd: selects one of 2^63 PCG streams */
} Rng;

/* splitmix64's output function: a bijective 64-bit mixer with full
 * avalanche, so nearby inputs give unrelated outputs. */
INLINE ulong rng_mix64(ulong z)
{
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9UL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebUL;
	return z ^ (z >> 31);
}

INLINE uint rng_u32(Rng *r)
{
	ulong old = r->state;
	r->state = old * 6364136223846793005UL + r->inc;
	uint xorshifted = (uint)(((old >> 18) ^ old) >> 27);
	uint rot = (uint)(old >> 59);
	return (xorshifted >> rot) | (xorshifted << ((0u - rot) & 31u));
}

INLINE Rng rng_init(uint seed, uint pixel, uint sample_index, uint stream)
{
	/* Two chained hashes so that every input bit reaches every output bit;
	 * the golden-ratio offsets keep all-zero inputs away from the fixed
	 * point 0 of the mixer. */
	ulong a = rng_mix64((((ulong)seed << 32) | (ulong)pixel) + 0x9e3779b97f4a7c15UL);
	ulong b = rng_mix64(a ^ ((((ulong)sample_index << 32) | (ulong)stream) + 0x6a09e667f3bcc909UL));
	Rng r;
	r.state = 0UL;
	r.inc = (rng_mix64(b + 0x9e3779b97f4a7c15UL) << 1) | 1UL;
	/* PCG's seeding sequence: step, add the initial state, step. */
	rng_u32(&r);
	r.state += b;
	rng_u32(&r);
	return r;
}

/* Uniform in [0, 1): the top 24 bits are exact in a float, so the largest
 * value is 1 - 2^-24 and never rounds up to 1. */
INLINE float rng_f(Rng *r) { return (float)(rng_u32(r) >> 8) * (1.0f / 16777216.0f); }

#endif
