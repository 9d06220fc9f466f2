/* image_overrides.h — what only tests set in the image module, never the
 * product (as render/render_overrides.h for the renderer): a call made
 * when an output's temporary file is written and closed, just before it is
 * renamed onto its name, so a test can act while an output is in flight
 * (tests/support/ajar_faults.c sends the CLI signals there). NULL: none. */
#ifndef AJAR_IMAGE_OVERRIDES_H
#define AJAR_IMAGE_OVERRIDES_H

extern void (*image_tmp_hook)(const char *tmp_path);
#endif
