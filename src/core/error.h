/* error.h — the status-plus-message convention of the whole library.
 *
 * err_set() formats the message, keeps it for ajar_last_error() on this
 * thread, sends it to the log callback and returns the status, so a failing
 * path reads `return err_set(AJAR_ERROR_BAD_INPUT, "%s: meshes[%d]: ...", ...)`. */
#ifndef AJAR_ERROR_H
#define AJAR_ERROR_H
#include "ajar.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define AJAR_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define AJAR_PRINTF(a, b)
#endif

ajar_status err_set(ajar_status status, const char *fmt, ...) AJAR_PRINTF(2, 3);
void err_clear(void);
void log_msg(ajar_log_level level, const char *fmt, ...) AJAR_PRINTF(2, 3);

#ifdef __cplusplus
}
#endif
#endif
