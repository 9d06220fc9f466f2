/* mis_oracle.h — the MIS densities of a path computed from the path alone
 * (design.md, "Path sampling and MIS"), to check the kernels' bookkeeping:
 * pf and pr of every vertex, the portal crossings of an edge, and the
 * pair density of the portal strategies. */
#ifndef AJAR_MIS_ORACLE_H
#define AJAR_MIS_ORACLE_H
#include "kernel_host.h"

float oracle_convert(const PathVertex *from, const PathVertex *to, float pdf_w);
V3 oracle_dir(const PathVertex *from, const PathVertex *to);
float oracle_bsdf(const SceneView *sc, const PathVertex *v, const PathVertex *from, const PathVertex *to);
/* x[0] light (emitter point or environment), x[k-1] camera; delta[i]: x[i]
 * scattered through a delta lobe on this path. */
void oracle(const SceneView *sc, const PathVertex *x, const int *delta, int k, MisVertex *mv);
/* Whether bdpt strategy s can produce the path. */
int strategy_valid(const MisVertex *v, int k, int s);
/* Whether an edge near vertex i is shorter than 1% of the scene radius. */
int near_contact(const PathVertex *x, int k, int i, float radius);
double rel_diff(float a, float b);
/* The portal crossings of edge a = x_m, b = x_{m+1} (either may be the
 * environment): returns their number; lp[c] = log p_pair of crossing c
 * (p_A, the direction density, G) and pts[c] its point, for c < max. */
int oracle_pair_logs(const SceneView *sc, const PathVertex *a, const PathVertex *b, double *lp, double (*pts)[3],
		     int max);
#endif
