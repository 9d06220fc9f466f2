/* gltf_transform.c — the glTF loader's matrices: a node's T R S, their
 * products down the node tree, the normal matrix, and vertex arrays moved
 * to world space by them (in double, rounded to float once). */
#include "scene/gltf_parts.h"
#include "scene/gltf_loader.h"

#include <math.h>

/* gltf_trs_matrix where the loader reads T R S (a node, a GPU instance):
 * a zero quaternion is refused, naming `what`. */
ajar_status gltf_trs(const GltfLoader *L, const char *what, const double t[3], const double q[4], const double s[3],
		     double m[16])
{
	if (!gltf_trs_matrix(t, q, s, m))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: rotation is a zero quaternion", what);
	return AJAR_OK;
}

void gltf_mat_identity(double m[16])
{
	for (int i = 0; i < 16; i++)
		m[i] = (i % 5 == 0) ? 1.0 : 0.0;
}

void gltf_mat_mul(const double a[16], const double b[16], double r[16])
{
	for (int c = 0; c < 4; c++)
		for (int row = 0; row < 4; row++) {
			double sum = 0.0;
			for (int k = 0; k < 4; k++)
				sum += a[4 * k + row] * b[4 * c + k];
			r[4 * c + row] = sum;
		}
}

int gltf_trs_matrix(const double t[3], const double q[4], const double s[3], double m[16])
{
	double ql = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
	if (!(ql > 0.0) || !isfinite(ql))
		return 0;
	double x = q[0] / ql, y = q[1] / ql, z = q[2] / ql, w = q[3] / ql;
	double r[3][3] = {
		{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
		{2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
		{2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
	};
	for (int c = 0; c < 3; c++) {
		for (int row = 0; row < 3; row++)
			m[4 * c + row] = r[row][c] * s[c];
		m[4 * c + 3] = 0.0;
	}
	m[12] = t[0];
	m[13] = t[1];
	m[14] = t[2];
	m[15] = 1.0;
	return 1;
}

double gltf_normal_matrix(const double m[16], double nm[3][3])
{
	double a[3][3];
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++)
			a[r][c] = m[4 * c + r];
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) {
			int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
			nm[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
		}
	double det = a[0][0] * nm[0][0] + a[0][1] * nm[0][1] + a[0][2] * nm[0][2];
	if (det != 0.0)
		for (int r = 0; r < 3; r++)
			for (int c = 0; c < 3; c++)
				nm[r][c] /= det;
	return det;
}

void gltf_transform_points(const double world[16], float *pos, size_t nv)
{
	for (size_t v = 0; v < nv; v++) {
		double p[3] = {pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]};
		for (int r = 0; r < 3; r++)
			pos[3 * v + (size_t)r] =
				(float)(world[r] * p[0] + world[4 + r] * p[1] + world[8 + r] * p[2] + world[12 + r]);
	}
}

void gltf_transform_normals(const double nm[3][3], float *nrm, size_t nv)
{
	for (size_t v = 0; v < nv; v++) {
		double n[3] = {nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]};
		for (int r = 0; r < 3; r++)
			nrm[3 * v + (size_t)r] = (float)(nm[r][0] * n[0] + nm[r][1] * n[1] + nm[r][2] * n[2]);
	}
}

void gltf_transform_tangents(const double world[16], float *tan, size_t nv, int flip)
{
	for (size_t v = 0; v < nv; v++) {
		double t[3] = {tan[4 * v], tan[4 * v + 1], tan[4 * v + 2]};
		for (int r = 0; r < 3; r++)
			tan[4 * v + (size_t)r] = (float)(world[r] * t[0] + world[4 + r] * t[1] + world[8 + r] * t[2]);
		if (flip)
			tan[4 * v + 3] = -tan[4 * v + 3];
	}
}
