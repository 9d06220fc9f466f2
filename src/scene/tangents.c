/* tangents.c — tangents for a normal map where the mesh has none, as glTF
 * asks (the MikkTSpace way, in its main points): each triangle's tangent is
 * the direction of increasing u (from its positions and texture
 * coordinates), its handedness w the sign that makes w (n x t) point along
 * decreasing v (glTF's v runs down the image, the map's +y up it: the
 * stored tangents of NormalTangentMirrorTest agree, test_scene); a vertex
 * averages the tangents of the triangles around it of one handedness,
 * weighted by their angles there and projected onto its normal's plane. A
 * vertex shared by triangles of both handednesses (a mirrored UV seam
 * without split vertices) is split in two. */
#include "scene/tangents.h"

#include <math.h>
#include <stdlib.h>

/* Adds triangle f's tangent, weighted by its angle, to its vertices'
 * sums of its handedness (acc[s][v]); returns the handedness, 1 for w = +1
 * and 0 for w = -1, or -1 for a triangle without a u direction. */
static int add_triangle(const float *pos, const float *nrm, const float *uv, size_t nv, const uint32_t k[3],
			double *acc)
{
#define P(i, c) ((double)pos[3 * (size_t)(i) + (size_t)(c)])
	double e1[3], e2[3], fn[3];
	for (int c = 0; c < 3; c++) {
		e1[c] = P(k[1], c) - P(k[0], c);
		e2[c] = P(k[2], c) - P(k[0], c);
	}
	fn[0] = e1[1] * e2[2] - e1[2] * e2[1];
	fn[1] = e1[2] * e2[0] - e1[0] * e2[2];
	fn[2] = e1[0] * e2[1] - e1[1] * e2[0];
	if (nrm) /* the side the vertex normals say */
		for (int c = 0; c < 3; c++)
			fn[c] = (double)nrm[3 * (size_t)k[0] + (size_t)c] + nrm[3 * (size_t)k[1] + (size_t)c] +
				nrm[3 * (size_t)k[2] + (size_t)c];
	double du1 = uv[2 * (size_t)k[1]] - uv[2 * (size_t)k[0]], dv1 = uv[2 * (size_t)k[1] + 1] - uv[2 * (size_t)k[0] + 1];
	double du2 = uv[2 * (size_t)k[2]] - uv[2 * (size_t)k[0]], dv2 = uv[2 * (size_t)k[2] + 1] - uv[2 * (size_t)k[0] + 1];
	double r = du1 * dv2 - du2 * dv1;
	if (!(fabs(r) > 1e-20))
		return -1;
	double t[3], b[3];
	for (int c = 0; c < 3; c++) {
		t[c] = (e1[c] * dv2 - e2[c] * dv1) / r;
		b[c] = (e2[c] * du1 - e1[c] * du2) / r;
	}
	double nxt[3] = {fn[1] * t[2] - fn[2] * t[1], fn[2] * t[0] - fn[0] * t[2], fn[0] * t[1] - fn[1] * t[0]};
	int s = nxt[0] * b[0] + nxt[1] * b[1] + nxt[2] * b[2] > 0.0 ? 0 : 1;
	for (int j = 0; j < 3; j++) {
		uint32_t a = k[j], pb = k[(j + 1) % 3], pc = k[(j + 2) % 3];
		double x[3], y[3], lx = 0, ly = 0, d = 0;
		for (int c = 0; c < 3; c++) {
			x[c] = P(pb, c) - P(a, c);
			y[c] = P(pc, c) - P(a, c);
			lx += x[c] * x[c];
			ly += y[c] * y[c];
			d += x[c] * y[c];
		}
		if (!(lx > 0.0 && ly > 0.0))
			continue;
		double angle = acos(fmin(fmax(d / sqrt(lx * ly), -1.0), 1.0));
		double n[3] = {fn[0], fn[1], fn[2]};
		if (nrm)
			for (int c = 0; c < 3; c++)
				n[c] = nrm[3 * (size_t)a + (size_t)c];
		double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
		double tn = ln > 0.0 ? (t[0] * n[0] + t[1] * n[1] + t[2] * n[2]) / (ln * ln) : 0.0;
		double p[3] = {t[0] - tn * n[0], t[1] - tn * n[1], t[2] - tn * n[2]};
		double lp = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
		if (!(lp > 0.0))
			continue;
		for (int c = 0; c < 3; c++)
			acc[(size_t)s * 3 * nv + 3 * (size_t)a + (size_t)c] += angle * p[c] / lp;
	}
	return s;
#undef P
}

ajar_status tangents_generate(const float *pos, const float *nrm, const float *uv, size_t nv, uint32_t *tri,
			      size_t ntri, uint32_t *twin, float **tan, size_t *total)
{
	double *acc = calloc(2 * 3 * nv + 1, sizeof *acc);
	signed char *sign = malloc(ntri + 1);
	char *used = calloc(2 * nv + 1, 1);
	float *out = NULL;
	ajar_status st = AJAR_ERROR_OUT_OF_MEMORY;
	if (!acc || !sign || !used)
		goto done;
	for (size_t f = 0; f < ntri; f++) {
		int s = add_triangle(pos, nrm, uv, nv, &tri[3 * f], acc);
		sign[f] = (signed char)(s == 0 ? -1 : 1);
	}
	/* Vertices used with both handednesses get a copy for the negative one. */
	for (size_t f = 0; f < ntri; f++)
		for (int j = 0; j < 3; j++)
			used[(sign[f] > 0 ? nv : 0) + tri[3 * f + (size_t)j]] = 1;
	size_t n = nv;
	for (size_t v = 0; v < nv; v++)
		twin[v] = used[v] && used[nv + v] ? (uint32_t)n++ : UINT32_MAX;
	for (size_t f = 0; f < ntri; f++)
		if (sign[f] < 0)
			for (int j = 0; j < 3; j++)
				if (twin[tri[3 * f + (size_t)j]] != UINT32_MAX)
					tri[3 * f + (size_t)j] = twin[tri[3 * f + (size_t)j]];
	out = calloc(4 * n + 1, sizeof *out);
	if (!out)
		goto done;
	for (size_t v = 0; v < nv; v++)
		for (int s = 0; s < 2; s++) {
			if (!used[(size_t)s * nv + v])
				continue;
			size_t o = s == 0 && twin[v] != UINT32_MAX ? twin[v] : v;
			const double *a = &acc[(size_t)s * 3 * nv + 3 * v];
			double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
			for (int c = 0; c < 3; c++)
				out[4 * o + (size_t)c] = l > 0.0 ? (float)(a[c] / l) : 0.0f;
			out[4 * o + 3] = s ? 1.0f : -1.0f;
		}
	*tan = out;
	*total = n;
	st = AJAR_OK;
done:
	free(acc);
	free(sign);
	free(used);
	return st;
}
