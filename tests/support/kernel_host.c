/* kernel_host.c — see kernel_host.h. */
#include "kernel_host.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

void host_scene_open(HostScene *h, const char *path, Scene *built, uint32_t w, uint32_t hgt, int integrator,
		     int max_depth)
{
	host_scene_open_with(h, path, built, w, hgt, integrator, max_depth, NULL);
}

void host_scene_open_with(HostScene *h, const char *path, Scene *built, uint32_t w, uint32_t hgt, int integrator,
			  int max_depth, const PolicyOverrides *over)
{
	memset(h, 0, sizeof *h);
	if (path) {
		if (ajar_scene_load(path, &h->scene) != AJAR_OK)
			fail_msg("%s", ajar_last_error());
	} else {
		h->scene = built;
	}
	ajar_options o;
	ajar_options_default(&o);
	o.integrator = (ajar_integrator)integrator;
	o.max_depth = (uint32_t)max_depth;
	o.mis = AJAR_MIS_POWER;
	/* The kernels compiled here read sky tables of PORTAL_SKY_RES cells a side. */
	PolicyOverrides po = {0};
	if (over)
		po = *over;
	po.sky_res = PORTAL_SKY_RES;
	if (prepare_scene(h->scene, &o, w, hgt, &po, &h->data) != AJAR_OK)
		fail_msg("%s", ajar_last_error());
#define HOST_VIEW(type, name) h->view.name = h->data.name;
	AJAR_SCENE_BUFFERS(HOST_VIEW)
#undef HOST_VIEW
}

void host_scene_close(HostScene *h)
{
	prepare_free(&h->data);
	ajar_scene_destroy(&h->scene);
}

void host_render(HostScene *h, uint32_t spp, uint32_t seed, double *rgb, double *layers)
{
	Params *prm = h->data.params;
	GLOBAL const Camera *cam = &prm->camera;
	uint32_t npix = (uint32_t)(cam->width * cam->height);
	int nlayers = bdpt_layer_count(prm->strategy_len) +
		      (prm->integrator == INTEGRATOR_PORTAL ? portal_layer_count(prm->strategy_len) : 0);
	long *film = calloc((size_t)3 * npix * (1 + (size_t)nlayers), sizeof *film);
	double *eye = calloc((size_t)3 * npix, sizeof *eye);
	PathVertex *lv = malloc(sizeof *lv * SUBPATH_MAX), *ev = malloc(sizeof *ev * SUBPATH_MAX);
	PathVertex *rv = malloc(sizeof *rv * SUBPATH_MAX), *fv = malloc(sizeof *fv * SUBPATH_MAX);
	prm->seed = seed;
	for (uint32_t px = 0; px < npix; px++) {
		for (uint32_t i = 0; i < spp; i++) {
			float qmc[RNG_QMC_FLOATS];
			rng_qmc_table(seed, px, i, qmc);
			Rng rng = rng_init_pixel(seed, px, i, qmc);
			float jx, jy;
			rng_pixel(&rng, &jx, &jy);
			float x = (float)(px % (uint32_t)cam->width) + jx;
			float y = (float)(px / (uint32_t)cam->width) + jy;
			V3 L;
			if (prm->integrator != INTEGRATOR_PT) {
				BdptFilm out = {film, film + 3 * (size_t)npix, px, v3(0, 0, 0)};
				if (prm->integrator == INTEGRATOR_PORTAL)
					portal_sample_pixel(&h->view, x, y, lv, ev, rv, fv, &out, &rng);
				else
					bdpt_sample(&h->view, x, y, lv, ev, &out, &rng);
				L = out.L;
			} else {
				L = pt_radiance(&h->view, cam->pos, camera_ray_dir(cam, x, y), &rng);
			}
			eye[3 * px] += L.x;
			eye[3 * px + 1] += L.y;
			eye[3 * px + 2] += L.z;
		}
	}
	for (size_t i = 0; i < (size_t)3 * npix; i++)
		rgb[i] = (eye[i] + film[i] / (double)FILM_SCALE) / spp;
	if (layers)
		for (size_t i = 0; i < (size_t)3 * npix * nlayers; i++)
			layers[i] = film[3 * (size_t)npix + i] / (double)FILM_SCALE / spp;
	free(film);
	free(eye);
	free(lv);
	free(ev);
	free(rv);
	free(fv);
}

void host_batch_estimates(HostScene *h, uint32_t spp, int layer, int count, int batches, uint32_t seed0,
			  Estimate *est)
{
	Params *prm = h->data.params;
	uint32_t npix = (uint32_t)(prm->camera.width * prm->camera.height);
	int nlayers = bdpt_layer_count(prm->strategy_len) +
		      (prm->integrator == INTEGRATOR_PORTAL ? portal_layer_count(prm->strategy_len) : 0);
	double *rgb = malloc(sizeof(double) * 3 * npix);
	double *lay = nlayers ? malloc(sizeof(double) * 3 * npix * nlayers) : NULL;
	double *s1 = calloc((size_t)3 * count, sizeof(double)), *s2 = calloc((size_t)3 * count, sizeof(double));
	for (int b = 0; b < batches; b++) {
		host_render(h, spp, seed0 + (uint32_t)b, rgb, lay);
		for (int k = 0; k < count; k++) {
			const double *img = layer >= 0 ? lay + (size_t)3 * npix * (layer + k) : rgb;
			for (int c = 0; c < 3; c++) {
				double m = 0;
				for (uint32_t i = 0; i < npix; i++)
					m += img[3 * i + c];
				m /= npix;
				s1[3 * k + c] += m;
				s2[3 * k + c] += m * m;
			}
		}
	}
	for (int k = 0; k < count; k++)
		for (int c = 0; c < 3; c++) {
			double m1 = s1[3 * k + c], m2 = s2[3 * k + c];
			est[k].mean[c] = m1 / batches;
			double var = (m2 - m1 * m1 / batches) / (batches - 1);
			est[k].se[c] = sqrt(fmax(var, 0) / batches);
		}
	free(rgb);
	free(lay);
	free(s1);
	free(s2);
}

void host_batch_estimate(HostScene *h, uint32_t spp, int layer, int batches, uint32_t seed0, Estimate *est)
{
	host_batch_estimates(h, spp, layer, 1, batches, seed0, est);
}
