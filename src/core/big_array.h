/* big_array.h — page-aligned arrays that grow in place: the scene's
 * triangles, texels and BVH nodes, which devices on the CPU read where they
 * are (CL_MEM_USE_HOST_PTR) and which reach gigabytes. On Linux they are
 * anonymous mappings grown by mremap (no copy, no transient double), else
 * aligned_alloc and a copy. The caller keeps each array's size in bytes. */
#ifndef AJAR_BIG_ARRAY_H
#define AJAR_BIG_ARRAY_H
#include <stddef.h>

/* Alignment of every big array: a page, more than any device asks. */
#define BIG_ARRAY_ALIGN 4096

/* An array of `bytes` (> 0), zero-filled, or NULL. */
void *big_alloc(size_t bytes);
/* p (old_bytes, or NULL with 0) resized to new_bytes (> 0), its contents
 * kept up to the smaller size, the rest zero; NULL if out of memory (p is
 * then unchanged). */
void *big_resize(void *p, size_t old_bytes, size_t new_bytes);
void big_free(void *p, size_t bytes);
/* Asks for huge pages under bytes [from, to) of p, for an array that will
 * be written whole soon (the BVH build's references and nodes): one fault
 * per 2 MiB instead of per 4 KiB. A hint; nothing where unsupported. */
void big_advise_huge(void *p, size_t from, size_t to);
#endif
