/* big_array.c — see big_array.h. A mapping's pages cost memory only once
 * written, so a capacity that doubles ahead of its contents is free. */
#include "core/big_array.h"

#include <stdlib.h>
#include <string.h>

#ifdef __linux__
#include <sys/mman.h>

static size_t pages(size_t bytes) { return (bytes + BIG_ARRAY_ALIGN - 1) / BIG_ARRAY_ALIGN * BIG_ARRAY_ALIGN; }

void *big_alloc(size_t bytes)
{
	void *p = mmap(NULL, pages(bytes), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
	return p == MAP_FAILED ? NULL : p;
}

void *big_resize(void *p, size_t old_bytes, size_t new_bytes)
{
	if (!p)
		return big_alloc(new_bytes);
	size_t a = pages(old_bytes), b = pages(new_bytes);
	if (a == b)
		return p;
	void *q = mremap(p, a, b, MREMAP_MAYMOVE);
	return q == MAP_FAILED ? NULL : q;
}

void big_free(void *p, size_t bytes)
{
	if (p)
		munmap(p, pages(bytes));
}

void big_advise_huge(void *p, size_t from, size_t to)
{
#ifdef MADV_HUGEPAGE
	size_t a = pages(from), b = to / BIG_ARRAY_ALIGN * BIG_ARRAY_ALIGN; /* whole pages inside */
	if (p && b > a)
		madvise((char *)p + a, b - a, MADV_HUGEPAGE);
#else
	(void)p;
	(void)from;
	(void)to;
#endif
}
#else
void *big_alloc(size_t bytes)
{
	size_t n = (bytes + BIG_ARRAY_ALIGN - 1) / BIG_ARRAY_ALIGN * BIG_ARRAY_ALIGN;
	void *p = aligned_alloc(BIG_ARRAY_ALIGN, n);
	if (p)
		memset(p, 0, n);
	return p;
}

void *big_resize(void *p, size_t old_bytes, size_t new_bytes)
{
	void *q = big_alloc(new_bytes);
	if (!q)
		return NULL;
	if (p)
		memcpy(q, p, old_bytes < new_bytes ? old_bytes : new_bytes);
	free(p);
	return q;
}

void big_free(void *p, size_t bytes)
{
	(void)bytes;
	free(p);
}

void big_advise_huge(void *p, size_t from, size_t to)
{
	(void)p;
	(void)from;
	(void)to;
}
#endif
