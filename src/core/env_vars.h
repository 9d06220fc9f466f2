/* env_vars.h — the environment variables the library reads, all here: the
 * device-tuning knobs a GPU user may need (their table is in
 * src/device/README.md), where the kernel cache lives, and whether an MPI
 * launcher started the process. Everything else a user or an embedding
 * program chooses is an option of include/ajar.h. */
#ifndef AJAR_ENV_VARS_H
#define AJAR_ENV_VARS_H

typedef enum {
	ENV_VAR_CL_OPTIONS,       /* AJAR_CL_OPTIONS: appended to the OpenCL build options */
	ENV_VAR_SUBPATHS,         /* AJAR_SUBPATHS: private or global subpath storage */
	ENV_VAR_PASS_LANES,       /* AJAR_PASS_LANES: work-items a pixel a pass */
	ENV_VAR_SUBPATH_CAPACITY, /* AJAR_SUBPATH_CAPACITY: work-items the global scratch holds */
	ENV_VAR_KERNEL_FEATURES,  /* AJAR_KERNEL_FEATURES: scene (specialised programs) or all */
	ENV_VAR_CACHE_DIR,        /* AJAR_CACHE_DIR: the kernel cache's folder, or off */
	ENV_VAR_XDG_CACHE_HOME,   /* XDG_CACHE_HOME, HOME: the cache's default folder */
	ENV_VAR_HOME,
	ENV_VAR_MPI_WORLD_SIZE,   /* OMPI_COMM_WORLD_SIZE, PMIX_RANK, PMI_RANK: set by MPI launchers */
	ENV_VAR_PMIX_RANK,
	ENV_VAR_PMI_RANK,
	ENV_VAR_COUNT
} EnvVar;

/* The variable's value, or NULL when it is not set. */
const char *env_var(EnvVar v);
/* Its name, for messages. */
const char *env_var_name(EnvVar v);
#endif
