/* aov_layout.h — the AOV film's channels (aov.h), for the host too. */
#ifndef AJAR_AOV_LAYOUT_H
#define AJAR_AOV_LAYOUT_H

/* Per pixel: albedo 0-2, normal 3-5, depth 6, squared radiance 7-9. */
#define AOV_CHANNELS 10
#define AOV_SQ_SCALE 4096.0f /* 2^12: L^2 up to AOV_SQ_MAX stays far below 2^63 */
#define AOV_SQ_MAX 1.0e9f
#endif
