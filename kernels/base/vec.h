/* vec.h — three-float vectors as plain structs, never OpenCL's float3.
 *
 * float3 has 16-byte size and alignment on devices and no fixed layout in
 * C, so host/device structs store V3 (12 bytes, 4-byte aligned) and the
 * math uses small functions that compile identically in both languages. */
#ifndef AJAR_VEC_H
#define AJAR_VEC_H
#include "base/compat.h"

typedef struct { float x, y, z; } V3;

INLINE V3 v3(float x, float y, float z) { V3 r; r.x = x; r.y = y; r.z = z; return r; }
INLINE V3 v3_add(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
INLINE V3 v3_sub(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
INLINE V3 v3_mul(V3 a, V3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
INLINE V3 v3_scale(V3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
INLINE V3 v3_madd(V3 a, V3 b, float s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
INLINE V3 v3_neg(V3 a) { return v3(-a.x, -a.y, -a.z); }
INLINE float v3_dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
INLINE V3 v3_cross(V3 a, V3 b)
{
	return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
INLINE float v3_len2(V3 a) { return v3_dot(a, a); }
INLINE float v3_len(V3 a) { return sqrt(v3_dot(a, a)); }
INLINE V3 v3_norm(V3 a) { return v3_scale(a, 1.0f / sqrt(v3_dot(a, a))); }
INLINE V3 v3_min(V3 a, V3 b) { return v3(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)); }
INLINE V3 v3_max(V3 a, V3 b) { return v3(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)); }
INLINE float v3_maxc(V3 a) { return fmax(a.x, fmax(a.y, a.z)); }
INLINE float v3_avg(V3 a) { return (a.x + a.y + a.z) * (1.0f / 3.0f); }
INLINE float v3_lum(V3 a) { return 0.2126f * a.x + 0.7152f * a.y + 0.0722f * a.z; }
INLINE int v3_is_zero(V3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
INLINE float v3_comp(V3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

/* Orthonormal basis around unit n (Duff et al. 2017, branchless). */
INLINE void v3_basis(V3 n, V3 *t, V3 *b)
{
	float sign = n.z >= 0.0f ? 1.0f : -1.0f;
	float a = -1.0f / (sign + n.z);
	float c = n.x * n.y * a;
	*t = v3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
	*b = v3(c, sign + n.y * n.y * a, -n.y);
}
INLINE V3 v3_to_local(V3 v, V3 t, V3 b, V3 n) { return v3(v3_dot(v, t), v3_dot(v, b), v3_dot(v, n)); }
INLINE V3 v3_from_local(V3 v, V3 t, V3 b, V3 n)
{
	return v3_add(v3_add(v3_scale(t, v.x), v3_scale(b, v.y)), v3_scale(n, v.z));
}
#endif
