/* device.h — one OpenCL device: discovery and selection, context and queue,
 * program build with a binary cache, buffers. The only module that includes
 * CL/cl.h (with render.c, which drives kernels through it). */
#ifndef AJAR_DEVICE_H
#define AJAR_DEVICE_H
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>
#include <stddef.h>

#include "ajar.h"

typedef struct Device {
	cl_platform_id platform;
	cl_device_id id;
	char name[256];
	char selector[32];
	int is_cpu;
	int nv_options; /* the device takes NVIDIA's build options (cl_nv_compiler_options) */
	cl_context ctx;
	cl_command_queue queue;
	cl_program program;
	double build_seconds; /* source or cached binary to a built program */
	int from_cache;       /* 1 if the program came from Ajar's binary cache */
} Device;

/* Every device of every platform, in selector order ("P:D"). */
ajar_status device_list(ajar_device_info *out, uint32_t capacity, uint32_t *count);
/* Resolves a selector list: NULL/"" (the first CPU device, else the first
 * device), or comma-separated items, each "P:D", "N" (flat index), "cpu",
 * "gpu", a name substring (the first matching device not already chosen)
 * or "all" (every device not already chosen). Up to `cap` devices go to
 * platforms/ids in list order; an item that matches nothing is an error. */
ajar_status device_select(const char *selector, cl_platform_id *platforms, cl_device_id *ids,
			  uint32_t cap, uint32_t *count);
/* The "P:D" selector of a device ("?" if it is not enumerated). */
void device_selector_of(cl_device_id id, char *buf, size_t cap);

ajar_status device_open(Device *d, cl_platform_id platform, cl_device_id id);
void device_close(Device *d);
/* Builds `source` with `options`, reusing a cached binary for this device,
 * driver, source and options when one exists. Build logs go into the error. */
ajar_status device_build(Device *d, const char *source, const char *options);
/* The build options of integrator `integrator` (INTEGRATOR_*) on d:
 * KERNEL_OPTIONS, then -DAJAR_CALLS for bdpt and portal on a device that
 * is not a CPU, a register cap where the device takes NVIDIA's options,
 * and last `extra` (AJAR_CL_OPTIONS, NULL for none), which can undo both. */
void device_build_options(const Device *d, int integrator, const char *extra, char *buf, size_t cap);
/* Where bdpt's and portal's subpaths live on a device and how a pass
 * spreads over it (kernels/gpu.md, "On GPUs: subpaths in global memory").
 * PathVertex, as the host reserves room for it: at most
 * DEVICE_VERTEX_WORDS 32-bit words (kernels/integrator/vertex.h refuses to build
 * otherwise), SUBPATH_MAX vertices a subpath. */
#define DEVICE_VERTEX_WORDS 72
#define DEVICE_SUBPATH_MAX 33
typedef struct {
	int soa;           /* subpaths in a global scratch buffer (-DAJAR_SUBPATH_SOA), else private arrays */
	size_t capacity;   /* work-items the scratch holds (its stride), the most one launch covers */
	unsigned lanes;    /* work-items per pixel: a pass's samples of a pixel are split between them */
	size_t scratch_bytes; /* 0 without scratch */
	unsigned omit;        /* DEVICE_OMIT_*: scene features the program leaves out (the caller sets it) */
	int general;          /* AJAR_KERNEL_FEATURES=all: omit nothing, whatever `omit` says */
	int sky_res;          /* cells a side of the planes' sky tables (-DPORTAL_SKY_RES unless 128; the caller sets it) */
} DevicePlan;
/* Scene features render_pass can be built without (kernel specialisation,
 * kernels/materials.md "Feature-specialised programs"): prepare_scene says
 * which a scene lacks; each becomes a -D option, and the cache keys on it. */
#define DEVICE_OMIT_ALPHA 1u        /* -DAJAR_NO_ALPHA: no TRI_ALPHA triangle */
#define DEVICE_OMIT_BENT_NORMALS 2u /* -DAJAR_NO_BENT_NORMALS: no shading normal tilted from ng, no normal map */
#define DEVICE_OMIT_TEXTURES 4u     /* -DAJAR_NO_TEXTURES: no material reads a texture */
#define DEVICE_OMIT_TRI_EXTRA 8u    /* -DAJAR_NO_TRI_EXTRA: no TRI_EXTRA triangle (TEXCOORD_1, COLOR_0, tangents) */
#define DEVICE_OMIT_PANES 16u       /* -DAJAR_NO_PANES: no TRI_PANE triangle (thin glass that rays cross) */
/* The plan of integrator `integrator` for an image of npix pixels on d:
 * private arrays on CPUs and for pt, the scratch on other devices; one lane
 * per pixel on CPUs, on other devices enough for compute units x
 * max work-group size x 2 work-items in flight (at most 64); a scratch of
 * that many work-items, within half the device's memory and its largest
 * buffer. AJAR_SUBPATHS=private|global, AJAR_SUBPATH_CAPACITY=N and
 * AJAR_PASS_LANES=N override (tests, measurements); AJAR_KERNEL_FEATURES=all
 * sets `general` (empty or "scene": specialise); a malformed value or a
 * scratch that does not fit is an error. */
ajar_status device_plan(const Device *d, int integrator, size_t npix, DevicePlan *p);
/* The options render_pass is built with: device_build_options', the
 * plan's (-DAJAR_SUBPATH_SOA=capacity -DAJAR_SUBPATH_WORDS=n for the
 * scratch, -DAJAR_NO_* for p->omit unless p->general), then `extra`
 * (AJAR_CL_OPTIONS, NULL for none). */
void device_render_options(const Device *d, int integrator, const DevicePlan *p, const char *extra, char *buf,
			   size_t cap);
ajar_status device_kernel(Device *d, const char *name, cl_kernel *out);
ajar_status device_buffer(Device *d, cl_mem_flags flags, size_t bytes, const void *host, cl_mem *out);

/* Names the failing call and the OpenCL error on the device. */
ajar_status cl_fail(const Device *d, const char *what, cl_int err);
const char *cl_error_name(cl_int err);
#define CL_TRY(d, call)                                              \
	do {                                                         \
		cl_int cl_try_err_ = (call);                         \
		if (cl_try_err_ != CL_SUCCESS)                       \
			return cl_fail((d), #call, cl_try_err_);     \
	} while (0)

/* Where compiled kernels are cached: $AJAR_CACHE_DIR, else
 * $XDG_CACHE_HOME/ajar, else ~/.cache/ajar; NULL disables the cache. */
const char *device_cache_dir(char *buf, size_t cap);
#endif
