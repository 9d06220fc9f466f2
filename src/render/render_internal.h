/* render_internal.h — the renderer's state, shared by the files that make
 * up ajar_renderer_*: render.c (setup, device threads, the render loop,
 * reduction), render_scheduler.c (which device renders which sample
 * range), render_checkpoint.c (writing and resuming checkpoints) and
 * render_job.c (one render on several machines, Open MPI). Nothing here is
 * public: include/ajar.h is. */
#ifndef AJAR_RENDER_INTERNAL_H
#define AJAR_RENDER_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "render/checkpoint_file.h"
#include "device/device_plan.h"
#include "prepare/prepare.h"
#include "device/upload.h"

#define MAX_RENDER_DEVICES 16

typedef SampleRange Range;

typedef struct {
	Range *r;
	size_t n, cap;
} RangeList;

typedef struct RenderDevice {
	struct ajar_renderer *r;
	Device dev;
	cl_kernel k_render;
	SceneBuffers bufs;
	cl_uint arg_first; /* index of the render kernel's first non-scene argument */
	cl_mem accum, splat; /* fixed-point films: own pixel, and atomic splats */
	size_t local;        /* work-group size of render_pass */
	DevicePlan plan;     /* subpath storage and work-items a pass (device_plan) */
	cl_mem scratch;      /* the subpaths when plan.soa, else a one-word stand-in */
	pthread_t thread;
	int started;              /* thread is running this render */
	uint32_t passes;          /* passes started */
	int rank;                 /* on rank 0: the rank this device renders on (0: here) */
	uint32_t remote;          /* its index there; see render_job.c */
	uint32_t job_ranges;      /* on rank 0, for a device of another rank: passes after its first, */
	double job_idle;          /* and the seconds it waited for them there (dealing, messages) */
	/* Under the renderer's lock: */
	int alive, reported;
	RangeList done;      /* ranges its film holds */
	uint64_t spp_kept;   /* sample indices of this device in the image */
	double busy_seconds; /* time in completed passes */
	double per_spp;      /* seconds per sample index, last pass; 0 unknown */
	char error[1024];    /* why it was dropped */
} RenderDevice;

struct ajar_renderer {
	SceneData data;
	RenderDevice *devs;
	uint32_t ndev;
	uint32_t width, height;
	double time_limit, elapsed;
	ajar_integrator integrator;
	uint32_t seed, max_depth;
	char scene_name[256];
	char device_names[1024];
	atomic_int cancel;
	int nlayers;                   /* per-strategy images after the splat film */
	int strategy_unweighted, strategy_len;
	long *film, *film_splat;       /* host reduction */
	long *salvage, *salvage_splat; /* films read back from dropped devices, or NULL */
	pthread_mutex_t lock;
	pthread_cond_t cond;
	/* Under the lock: */
	uint32_t spp_done, spp_target;
	uint32_t next_first; /* first sample index never handed out */
	RangeList holes;     /* ranges below next_first to render again */
	uint32_t in_flight, running;
	uint64_t events; /* passes ended, for the main thread's wake-ups */
	int out_of_memory;
	RenderDevice *last_dropped;
	double t0;
	/* Checkpoints (render_checkpoint.c): */
	ajar_options opt;     /* resolved, device NULL: what a checkpoint records */
	RangeList base;       /* ranges of the checkpoint resumed from, held in salvage */
	char *ckpt_path;      /* written during ajar_renderer_render, or NULL */
	double ckpt_every, ckpt_last;
	int pausing;          /* under the lock: no device takes a new range */
	int hashed;
	uint64_t scene_hash, params_hash;
	/* Several machines (Open MPI, render_job.c): */
	long *remote, *remote_splat; /* rank 0: the other ranks' films, summed at the last gather */
	int job_lost;                /* rank 0: a rank that stopped answering, or 0 */
	atomic_int job_over;         /* other ranks: the render is over (device threads end) */
};

/* render.c */
double render_seconds(void); /* monotonic clock */
int range_list_push(RangeList *l, Range g);
size_t render_aov_offset(const ajar_renderer *r);
size_t render_splat_count(const ajar_renderer *r);
ajar_status renderer_new(const ajar_scene *scene, const ajar_options *opt, const PolicyOverrides *over,
			 Checkpoint *ck, const char *ck_path, ajar_renderer **out);
int render_run_pass(RenderDevice *rd, Range g, int *film_ok);
int render_read_films(RenderDevice *rd, long **accum, long **splat);
int render_salvage_add(ajar_renderer *r, const long *accum, const long *splat);
void render_drop_device(ajar_renderer *r, RenderDevice *rd, Range g, const long *accum, const long *splat,
			int kept_there);
ajar_status render_reduce(ajar_renderer *r);

/* render_scheduler.c: all under r->lock */
double scheduler_time_left(const ajar_renderer *r);
uint64_t scheduler_work_left(const ajar_renderer *r);
int scheduler_stopping(const ajar_renderer *r);
int scheduler_take_range(ajar_renderer *r, RenderDevice *rd, Range *g);

/* render_checkpoint.c */
void render_ensure_hashes(ajar_renderer *r);
void render_checkpoint_during(ajar_renderer *r);
void options_from_checkpoint(const Checkpoint *c, ajar_options *o);
ajar_status render_checkpoint_check(ajar_renderer *r, const Checkpoint *c, const char *path);
ajar_status render_checkpoint_apply(ajar_renderer *r, Checkpoint *c, const char *path);
ajar_status resume_options(ajar_options *want, const ajar_options *o, const char *path);

/* render_job.c */
ajar_status job_join(ajar_renderer *r, ajar_status st);
ajar_status job_resume(const ajar_scene *scene, const char *path, const ajar_options *o, ajar_renderer **out);
void *job_proxy_thread(void *arg);
ajar_status job_gather(ajar_renderer *r);
ajar_status job_end(ajar_renderer *r, ajar_status st);
ajar_status job_serve(ajar_renderer *r);

#endif
