/* qmc.h — the low-discrepancy part of a pixel sample's random numbers.
 *
 * Dimensions are taken in pairs; each pair is the Sobol (0,2)-sequence
 * (its first two dimensions: van der Corput and the one with direction
 * numbers v_{k+1} = v_k ^ (v_k >> 1)), made random and independent of the
 * other pairs and pixels as Burley does it ("Practical hash-based Owen
 * scrambling", JCGT 2020):
 *  - the sample index is shuffled by a nested uniform scramble seeded per
 *    pixel and pair, a permutation under which the first 2^k samples of a
 *    pixel still form a (0,k,2)-net of the pair (their low k index bits stay
 *    distinct, and those alone fix the first k bits of both coordinates);
 *  - each coordinate is Owen-scrambled with its own seed, which keeps that
 *    net and makes every single point uniform in [0,1)^2.
 * Every sample is therefore uniform (estimates stay unbiased), while the
 * samples of one pixel fill each pair's square far more evenly than
 * independent ones, which is where most of a pixel's variance at hundreds of
 * samples comes from: pixel position, the first scattering and next-event
 * directions (kernels/sample/README.md, "Low-discrepancy numbers"). */
#ifndef AJAR_QMC_H
#define AJAR_QMC_H
#include "base/compat.h"

/* The integer steps, written once for a type T with suffix S: a uint
 * here, and on the device the 16 lanes of a uint16 as well (qmc_pairs16),
 * the same operations and so the same bits.
 *   qmc_reverse_bits: bit i to bit 31 - i.
 *   qmc_hash: a 32-bit integer hash (Wellons' lowbias32), seeds from seeds.
 *   qmc_lk_reversed: Laine and Karras' permutation of a binary fraction
 *     stored bit-reversed (its most significant bit in bit 0): every bit is
 *     flipped by a hash of the bits above it, and each step only carries
 *     bits upward (Burley's constants).
 *   qmc_sobol1_reversed: the second Sobol dimension of point i,
 *     bit-reversed: its generator matrix is Pascal's triangle mod 2, so bit
 *     m is the parity of the bits j of i with C(j, m) odd, which by Lucas'
 *     theorem are the j whose binary digits contain m's: a superset parity
 *     over the five bits of a bit's position, one shift per digit. (The
 *     forward fraction, bit-reversed, is what the scrambling wants; the
 *     loop over the 32 direction numbers it replaces cost a twentieth of a
 *     living-room render.) */
#define QMC_INT_STEPS(T, S, Q)                                                                  \
	Q T qmc_reverse_bits##S(T x)                                                            \
	{                                                                                       \
		x = (x << 16) | (x >> 16);                                                      \
		x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);                        \
		x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);                        \
		x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);                        \
		return ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);                     \
	}                                                                                       \
	Q T qmc_hash##S(T x)                                                                    \
	{                                                                                       \
		x ^= x >> 16;                                                                   \
		x *= 0x7feb352du;                                                               \
		x ^= x >> 15;                                                                   \
		x *= 0x846ca68bu;                                                               \
		return x ^ (x >> 16);                                                           \
	}                                                                                       \
	Q T qmc_lk_reversed##S(T x, T seed)                                                     \
	{                                                                                       \
		x += seed;                                                                      \
		x ^= x * 0x6c50b47cu;                                                           \
		x ^= x * 0xb82f1e52u;                                                           \
		x ^= x * 0xc7afe638u;                                                           \
		x ^= x * 0x8d22f6e6u;                                                           \
		return x;                                                                       \
	}                                                                                       \
	Q T qmc_sobol1_reversed##S(T i)                                                         \
	{                                                                                       \
		i ^= (i >> 1) & 0x55555555u;                                                    \
		i ^= (i >> 2) & 0x33333333u;                                                    \
		i ^= (i >> 4) & 0x0f0f0f0fu;                                                    \
		i ^= (i >> 8) & 0x00ff00ffu;                                                    \
		return i ^ ((i >> 16) & 0x0000ffffu);                                           \
	}

QMC_INT_STEPS(uint, , INLINE)
#ifdef AJAR_DEVICE
QMC_INT_STEPS(uint16, 16, HOT_INLINE)
#endif

/* Owen scrambling of x read as a binary fraction (most significant bit
 * first). */
INLINE uint qmc_owen(uint x, uint seed) { return qmc_reverse_bits(qmc_lk_reversed(qmc_reverse_bits(x), seed)); }

INLINE float qmc_to_float(uint x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

/* The pair's seed, and sample `index` shuffled for it. */
INLINE uint qmc_pair_index(uint index, uint pair, uint seed, uint *pair_seed)
{
	*pair_seed = qmc_hash(seed ^ qmc_hash(pair + 0x9e3779b9u));
	return qmc_owen(index, *pair_seed);
}

/* Both coordinates of pair `pair` of sample `index` of the pixel whose seed
 * is `seed`, in [0, 1) with 24 bits (exact in a float, never 1). */
INLINE void qmc_pair(uint index, uint pair, uint seed, float *x, float *y)
{
	uint ps, i = qmc_pair_index(index, pair, seed, &ps);
	/* van der Corput's fraction is i bit-reversed, so reversed it is i. */
	*x = qmc_to_float(qmc_reverse_bits(qmc_lk_reversed(i, qmc_hash(ps + 1u))));
	*y = qmc_to_float(qmc_reverse_bits(qmc_lk_reversed(qmc_sobol1_reversed(i), qmc_hash(ps + 2u))));
}

/* Dimension `dim` alone: coordinate dim & 1 of pair dim >> 1. */
INLINE float qmc_f(uint index, uint dim, uint seed)
{
	uint ps, i = qmc_pair_index(index, dim >> 1, seed, &ps);
	uint x = (dim & 1u) ? qmc_sobol1_reversed(i) : i;
	return qmc_to_float(qmc_reverse_bits(qmc_lk_reversed(x, qmc_hash(ps + 1u + (dim & 1u)))));
}

#ifdef AJAR_DEVICE
/* qmc_pair(index, p, seed, x, y) of pairs p = 0 to 15: lane p of *x and *y. */
HOT_INLINE void qmc_pairs16(uint index, uint seed, float16 *x, float16 *y)
{
	uint16 pair = (uint16)(0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u, 10u, 11u, 12u, 13u, 14u, 15u);
	uint16 ps = qmc_hash16(seed ^ qmc_hash16(pair + 0x9e3779b9u));
	uint16 i = qmc_reverse_bits16(qmc_lk_reversed16(qmc_reverse_bits16((uint16)(index)), ps));
	uint16 xi = qmc_reverse_bits16(qmc_lk_reversed16(i, qmc_hash16(ps + 1u)));
	uint16 yi = qmc_reverse_bits16(qmc_lk_reversed16(qmc_sobol1_reversed16(i), qmc_hash16(ps + 2u)));
	*x = convert_float16(xi >> 8) * (1.0f / 16777216.0f);
	*y = convert_float16(yi >> 8) * (1.0f / 16777216.0f);
}
#endif

#endif
