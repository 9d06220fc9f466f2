/* strategies.h — how per-strategy images are laid out, for the kernels
 * that write them and the host that names them. For paths of n segments
 * (n = 1 .. strategy_len), bdpt strategy (s, t = n + 1 - s), s = 0 .. n,
 * is layer (n - 1)(n + 2)/2 + s. The portal integrator's intermediate
 * strategies follow, grouped by (n, s, t), summed over the split of the
 * intermediate subpath (s' + t' = n + 1 - s - t >= 2): for each n, t runs
 * 1 .. n-1 and s 0 .. n-1-t. */
#ifndef AJAR_STRATEGIES_H
#define AJAR_STRATEGIES_H

INLINE int bdpt_layer_count(int len) { return len * (len + 3) / 2; }
INLINE int bdpt_layer(int n, int s) { return (n - 1) * (n + 2) / 2 + s; }
INLINE int portal_layer_count(int len) { return (len - 1) * len * (len + 1) / 6; }
INLINE int portal_layer(int n, int s, int t)
{
	return portal_layer_count(n - 1) + (t - 1) * n - (t - 1) * t / 2 + s;
}
#endif
