/* fuzz_stb.c — stb_image and stb_image_write compiled into the harnesses
 * from the header Debian's libstb is built from, so the fuzzer sees their
 * branches (libstb.so is not instrumented); the product links libstb. */
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image.h>
#include <stb_image_write.h>
