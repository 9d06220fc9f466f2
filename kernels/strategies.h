/* strategies.h — how per-strategy images are laid out, for the kernels
 * that write them and the host that names them. For paths of n segments
 * (n = 1 .. strategy_len), bdpt strategy (s, t = n + 1 - s), s = 0 .. n,
 * is layer (n - 1)(n + 2)/2 + s. */
#ifndef AJAR_STRATEGIES_H
#define AJAR_STRATEGIES_H

INLINE int bdpt_layer_count(int len) { return len * (len + 3) / 2; }
INLINE int bdpt_layer(int n, int s) { return (n - 1) * (n + 2) / 2 + s; }
#endif
