/* env_vars.c — the one place the library reads its environment (env_vars.h). */
#include "core/env_vars.h"

#include <stdlib.h>

static const char *const names[ENV_VAR_COUNT] = {
	[ENV_VAR_CL_OPTIONS] = "AJAR_CL_OPTIONS",
	[ENV_VAR_SUBPATHS] = "AJAR_SUBPATHS",
	[ENV_VAR_PASS_LANES] = "AJAR_PASS_LANES",
	[ENV_VAR_SUBPATH_CAPACITY] = "AJAR_SUBPATH_CAPACITY",
	[ENV_VAR_KERNEL_FEATURES] = "AJAR_KERNEL_FEATURES",
	[ENV_VAR_CACHE_DIR] = "AJAR_CACHE_DIR",
	[ENV_VAR_XDG_CACHE_HOME] = "XDG_CACHE_HOME",
	[ENV_VAR_HOME] = "HOME",
	[ENV_VAR_MPI_WORLD_SIZE] = "OMPI_COMM_WORLD_SIZE",
	[ENV_VAR_PMIX_RANK] = "PMIX_RANK",
	[ENV_VAR_PMI_RANK] = "PMI_RANK",
};

const char *env_var(EnvVar v) { return v < ENV_VAR_COUNT ? getenv(names[v]) : NULL; }

const char *env_var_name(EnvVar v) { return v < ENV_VAR_COUNT ? names[v] : "?"; }
