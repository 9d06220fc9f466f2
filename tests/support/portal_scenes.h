/* portal_scenes.h — the scenes the portal tests (tests/unit/test_portal_*.c)
 * share, built from the shipped ones or from scratch, and how they open
 * one where the policy would render portal as bdpt. */
#ifndef AJAR_PORTAL_SCENES_H
#define AJAR_PORTAL_SCENES_H
#include "kernel_host.h"

/* `path` with a directional light at `dir` and, if `inside`, a point light
 * at p and a spot at q pointing down; `sky` 0 removes the environment. */
Scene *punctual_scene(const char *path, const float dir[3], int inside, const float p[3], const float q[3], int sky);
/* window-room with the sun through its window and, if `inside`, a point
 * light and a spot in the room; `sky` 0 removes the environment. */
Scene *sun_window_room(int inside, int sky);
/* door-ajar lit only by punctual lights: a sun outside its house, a point
 * light and a spot where its emitter was (its emission set to 0), no sky. */
Scene *door_ajar_lamps(void);
/* A room lit by a ceiling light, with a window portal and, outside, a
 * white wall facing it and a mirror: light leaves through the window,
 * bounces outside and comes back in (portal - surface - portal). */
Scene *round_trip_scene(void);
/* window-room under a sky with a sun: a gradient and a small disc of
 * radiance sun_l (the sky's is below 1), high (the patch on the floor) or
 * low (on the far wall), its light through the window (which faces -z). */
Scene *sun_room(int low, float sun_l);

/* `path` as an exporter hands it over: its marked portals taken out, so a
 * prepared scene finds its own (src/prepare/portal_find.c). */
Scene *without_portals(const char *path);

/* The sky's strategy set with light subpaths, the default where portal now
 * renders as bdpt: a forced set keeps the intermediate strategies. */
extern const PolicyOverrides SKY_SET;

/* Opens a scene where portal renders as bdpt by default (light subpaths
 * bring the light in: a sky image with a sun, punctual lights on the
 * camera's side; src/prepare/policy.c) with the sky's set forced, which
 * keeps the intermediate strategies these tests check. */
void open_portal_kept(HostScene *h, const char *path, Scene *built, uint32_t w, uint32_t hgt, int depth);
#endif
