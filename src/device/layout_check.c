/* layout_check.c — host-side checks of the shared structs (kernels/base/layout.h):
 * sizes as declared, multiples of 16; the device side is checked by the
 * layout_probe kernel in tests/test_layout.c. */
#include <stddef.h>

#include "base/layout.h"

#define AJAR_ASSERT_SIZE(type, size)                                        \
	_Static_assert(sizeof(type) == (size), #type " has the wrong size"); \
	_Static_assert(sizeof(type) % 16 == 0, #type " is not a multiple of 16");
AJAR_LAYOUT_TYPES(AJAR_ASSERT_SIZE)

/* Host offsets in probe order, for the layout test. */
#define AJAR_HOST_SIZE(type, size) (unsigned)sizeof(type),
#define AJAR_HOST_OFFSET(type, field) (unsigned)offsetof(type, field),
const unsigned ajar_layout_host[] = {AJAR_LAYOUT_TYPES(AJAR_HOST_SIZE) AJAR_LAYOUT_FIELDS(AJAR_HOST_OFFSET)};
const unsigned ajar_layout_count = sizeof ajar_layout_host / sizeof ajar_layout_host[0];
