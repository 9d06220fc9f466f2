/* render_state.h — what a renderer is: struct ajar_renderer and its
 * devices (RenderDevice), each field in the group of the room that owns it
 * (the others read it), and what every room asks of that state
 * (render_state.c): the clock, range lists, the hashes that identify what
 * is rendered. Nothing here is public: include/ajar.h is. */
#ifndef AJAR_RENDER_STATE_H
#define AJAR_RENDER_STATE_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "device/device.h"
#include "device/device_plan.h"
#include "device/upload.h"
#include "prepare/prepare.h"
#include "render/checkpoint_file.h"

#define MAX_RENDER_DEVICES 16

typedef SampleRange Range;

typedef struct {
	Range *r;
	size_t n, cap;
} RangeList;

typedef struct RenderDevice {
	struct ajar_renderer *r;
	/* The device and its program, scene and films (render_device.c). */
	Device dev;
	cl_kernel k_render;
	SceneBuffers bufs;
	cl_uint arg_first;   /* index of the render kernel's first non-scene argument */
	cl_mem accum, splat; /* fixed-point films: own pixel, and atomic splats */
	size_t local;        /* work-group size of render_pass */
	DevicePlan plan;     /* subpath storage and work-items a pass (device_plan) */
	cl_mem scratch;      /* the subpaths when plan.soa, else a one-word stand-in */
	uint32_t passes;     /* passes started */
	/* Its host thread (render_loop.c; render_job.c on the other ranks). */
	pthread_t thread;
	int started; /* thread is running this render */
	/* On rank 0, a device of another rank (render_job.c). */
	int rank;            /* the rank this device renders on (0: here) */
	uint32_t remote;     /* its index there */
	uint32_t job_ranges; /* passes after its first, */
	double job_idle;     /* and the seconds it waited for them there (dealing, messages) */
	/* Its part of the render (render_scheduler.c), under the renderer's lock: */
	int alive;
	int reported;        /* its drop was logged (render_loop.c) */
	RangeList done;      /* ranges its film holds */
	uint64_t spp_kept;   /* sample indices of this device in the image */
	double busy_seconds; /* time in completed passes */
	double per_spp;      /* seconds per sample index, last pass; 0 unknown */
	char error[1024];    /* why it was dropped */
} RenderDevice;

struct ajar_renderer {
	/* What is rendered (render.c: set at creation; a restart changes the seed). */
	SceneData data;
	ajar_options opt; /* resolved, device NULL: what a checkpoint records */
	uint32_t width, height;
	ajar_integrator integrator;
	uint32_t seed, max_depth;
	int nlayers; /* per-strategy images after the splat film */
	int strategy_unweighted, strategy_len;
	char scene_name[256];
	int hashed; /* scene_hash and params_hash are current (render_state.c) */
	uint64_t scene_hash, params_hash;
	/* The devices (render_device.c; render_job.c adds the other ranks'). */
	RenderDevice *devs;
	uint32_t ndev;
	char device_names[1024];
	/* The films on the host (render_film.c). */
	long *film, *film_splat;       /* the reduction */
	long *salvage, *salvage_splat; /* dropped devices' films and a resumed checkpoint's, or NULL */
	/* The schedule (render_scheduler.c), under the lock that every thread
	 * of a render takes: */
	pthread_mutex_t lock;
	pthread_cond_t cond;
	uint32_t spp_done, spp_target;
	double time_limit;
	uint32_t next_first; /* first sample index never handed out */
	RangeList holes;     /* ranges below next_first to render again */
	int out_of_memory;
	RenderDevice *last_dropped;
	/* The render loop (render_loop.c), under the lock but cancel: */
	atomic_int cancel;
	uint32_t in_flight, running;
	uint64_t events; /* passes ended, for the main thread's wake-ups */
	double t0, elapsed;
	/* Checkpoints (render_checkpoint.c): */
	RangeList base;  /* ranges of the checkpoint resumed from, held in salvage */
	char *ckpt_path; /* written during ajar_renderer_render, or NULL */
	double ckpt_every, ckpt_last;
	int pausing; /* under the lock: no device takes a new range */
	/* The noise estimate (render_noise.c), by the calling thread: */
	long *noise_snap[2];         /* image sums at earlier estimates (own pixels + splats) */
	uint32_t noise_snap_spp[2];  /* their sample counts */
	int noise_nsnap;
	double noise;                /* the last estimate, < 0 unknown */
	uint32_t noise_next;         /* samples per pixel at which to estimate next */
	int noise_reached;           /* the render stopped at the target */
	/* Several machines (Open MPI, render_job.c): */
	long *remote, *remote_splat; /* rank 0: the other ranks' films, summed at the last gather */
	int job_lost;                /* rank 0: a rank that stopped answering, or 0 */
	atomic_int job_over;         /* other ranks: the render is over (device threads end) */
};

/* A monotonic clock, in seconds. */
double render_seconds(void);
/* Appends g, merging with the last range when they touch; 0 if out of memory. */
int range_list_push(RangeList *l, Range g);
/* Hashes the prepared scene and the kernels' parameters, once after
 * creation and after each restart. */
void render_ensure_hashes(ajar_renderer *r);

#endif
