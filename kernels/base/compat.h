/* compat.h — lets the kernel headers compile both as OpenCL C and as host C11.
 *
 * Everything under kernels/ except ajar.cl includes only this file for
 * portability. The host compiles the same math for unit tests and
 * sanitizers (as Cycles does with its kernel), so only the address-space
 * qualifiers and a few builtins differ between the two worlds. */
#ifndef AJAR_COMPAT_H
#define AJAR_COMPAT_H

#ifdef __OPENCL_C_VERSION__
#define AJAR_DEVICE 1
#define GLOBAL __global
/* Light paths splat into the image with 64-bit atomic adds (bdpt.h). */
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
#define u2f(u) as_float(u)
#define f2u(f) as_uint(f)
#else
#include <stdint.h>
#include <string.h>
#include <tgmath.h> /* sqrt(float) must stay float, as in OpenCL */
typedef unsigned int uint;
typedef unsigned long ulong;
#define GLOBAL
static inline float u2f(uint u) { float f; memcpy(&f, &u, 4); return f; }
static inline uint f2u(float f) { uint u; memcpy(&u, &f, 4); return u; }
static inline int max(int a, int b) { return a > b ? a : b; }
static inline int min(int a, int b) { return a < b ? a : b; }
static inline uint clz(uint x) { return x ? (uint)__builtin_clz(x) : 32u; }
/* Host tests run kernels on one thread: a plain add is the atomic. */
static inline long atom_add(long *p, long v) { long old = *p; *p += v; return old; }
#endif

/* static on the device too: OpenCL C 1.2 follows C99, where a plain
 * `inline` definition provides no symbol, so a compiler that keeps a call
 * (NVIDIA's with -cl-opt-disable) fails to link. */
#define INLINE static inline
#define HOT_INLINE static inline __attribute__((always_inline))
/* The large functions: traversal, subpaths, connections, MIS. With
 * -DAJAR_CALLS they stay calls on the device. NVIDIA's OpenCL compiler did
 * not finish bdpt's or portal's program in 5 minutes with everything
 * inlined, and builds them in under half a minute this way (src/device/README.md, "Build options").
 * The host adds it for bdpt and portal on devices that are not CPUs; on
 * PoCL it costs 0-3%, so CPUs inline. */
#if defined(AJAR_DEVICE) && defined(AJAR_CALLS)
#define CALLED static __attribute__((noinline))
#else
#define CALLED static inline
#endif

/* Read-only tables at program scope (bsdf_tables.h): __constant on the
 * device; the host declares them static const. */
#ifdef AJAR_DEVICE
#define CONSTANT __constant
#else
#define CONSTANT const
#endif

#define AJAR_PI 3.14159265358979323846f
#define AJAR_INV_PI 0.31830988618379067154f
#define AJAR_INV_2PI 0.15915494309189533577f
#define AJAR_INF 3.402823466e+38f

#endif
