/* camera.h — the pinhole camera: primary rays, and the inverse mapping from
 * a direction to the raster with the camera's importance (for light paths
 * that connect to the camera, t = 1).
 *
 * The image plane sits at distance 1 along `forward` and spans
 * [-a, a] x [-h, h] with h = tan(yfov/2), a = h * aspect. Raster (px, py)
 * has y down; each pixel is a unit square (the box filter). */
#ifndef AJAR_CAMERA_H
#define AJAR_CAMERA_H
#include "base/types.h"

INLINE V3 camera_ray_dir(GLOBAL const Camera *c, float px, float py)
{
	float h = c->tan_half_fov_y, a = h * c->aspect;
	float sx = (2.0f * px / (float)c->width - 1.0f) * a;
	float sy = (1.0f - 2.0f * py / (float)c->height) * h;
	return v3_norm(v3_add(c->forward, v3_add(v3_scale(c->right, sx), v3_scale(c->up, sy))));
}

/* Raster position of unit direction d leaving the camera; 0 if it misses
 * the image. *cos_theta is d's cosine with the view direction. */
INLINE int camera_raster(GLOBAL const Camera *c, V3 d, float *px, float *py, float *cos_theta)
{
	float cz = v3_dot(d, c->forward);
	*cos_theta = cz;
	if (cz <= 0.0f)
		return 0;
	float h = c->tan_half_fov_y, a = h * c->aspect;
	float sx = v3_dot(d, c->right) / cz, sy = v3_dot(d, c->up) / cz;
	*px = (sx / a + 1.0f) * 0.5f * (float)c->width;
	*py = (1.0f - sy / h) * 0.5f * (float)c->height;
	return *px >= 0.0f && *px < (float)c->width && *py >= 0.0f && *py < (float)c->height;
}

/* Solid-angle density of the primary ray direction d when the raster
 * position is uniform over the whole image: 1 / (A cos^3), with A the image
 * plane's area at distance 1. Per pixel (uniform within one pixel) it is
 * W*H times larger. */
INLINE float camera_pdf_w(GLOBAL const Camera *c, float cos_theta)
{
	float h = c->tan_half_fov_y, a = h * c->aspect;
	float area = 4.0f * a * h;
	return 1.0f / (area * cos_theta * cos_theta * cos_theta);
}
#endif
