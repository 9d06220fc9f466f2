/* render_options.h — checking ajar_options (render_options.c). */
#ifndef AJAR_RENDER_OPTIONS_H
#define AJAR_RENDER_OPTIONS_H
#include "ajar.h"

/* Validates in into *out, with defaults resolved: max_depth 0 means 64 for
 * pt and AJAR_BIDIR_MAX_DEPTH for the bidirectional integrators. */
ajar_status options_resolve(const ajar_options *in, ajar_options *out);
#endif
