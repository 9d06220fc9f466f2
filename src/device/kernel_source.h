/* kernel_source.h — the OpenCL C source that embed_kernels generates from
 * kernels/, and the options its programs are built with. */
#ifndef AJAR_KERNEL_SOURCE_H
#define AJAR_KERNEL_SOURCE_H

extern const char ajar_kernel_source[];

/* Followed by the integrator's number (INTEGRATOR_*): one program per
 * integrator, see PARAMS_INTEGRATOR in kernels/base/types.h. Every program also
 * holds the layout and traversal kernels; tests build pt's, the smallest. */
#define KERNEL_OPTIONS "-cl-std=CL1.2 -DAJAR_INTEGRATOR="

#endif
