/* kernel_host.h — runs the kernels' integrators on the host, one thread,
 * for tests that need to look inside a sample (MIS records, strategy
 * images) or must not depend on an OpenCL device. The same headers are
 * what the device compiles. */
#ifndef AJAR_KERNEL_HOST_H
#define AJAR_KERNEL_HOST_H
#include "integrator/portal.h"
#include "integrator/pt.h"
#include "prepare/prepare.h"

typedef struct {
	Scene *scene;
	SceneData data;
	SceneView view;
} HostScene;

/* Loads `path` (or takes `built` if path is NULL) and prepares it for a
 * width x height image; integrator settings go into the Params. */
void host_scene_open(HostScene *h, const char *path, Scene *built, uint32_t w, uint32_t hgt, int integrator,
		     int max_depth);
/* The same with some of the policy's choices forced (NULL: none). */
void host_scene_open_with(HostScene *h, const char *path, Scene *built, uint32_t w, uint32_t hgt, int integrator,
			  int max_depth, const PolicyOverrides *over);
void host_scene_close(HostScene *h);

/* Renders spp samples per pixel: rgb gets the mean (3 floats per pixel);
 * layers (if not NULL) the per-strategy means for paths up to
 * params->strategy_len segments, 3 doubles per pixel per layer. */
void host_render(HostScene *h, uint32_t spp, uint32_t seed, double *rgb, double *layers);

/* Image mean per channel of the image (layer < 0) or of strategy layer
 * `layer`, from `batches` independent renders (seeds seed0, seed0 + 1, ..)
 * of spp samples: the mean of the batch means and its standard error. */
typedef struct {
	double mean[3], se[3];
} Estimate;
void host_batch_estimate(HostScene *h, uint32_t spp, int layer, int batches, uint32_t seed0, Estimate *est);
/* The same for `count` consecutive layers from `layer` at once (one
 * render per batch): est[0 .. count). */
void host_batch_estimates(HostScene *h, uint32_t spp, int layer, int count, int batches, uint32_t seed0,
			  Estimate *est);
#endif
