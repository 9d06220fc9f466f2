/* error.c — per-thread last error, the log callback, status names. */
#include "core/error.h"

#include <stdarg.h>
#include <stdio.h>

static _Thread_local char last_error[2048];
static ajar_log_fn log_fn;
static void *log_user;

const char *ajar_last_error(void) { return last_error; }

void ajar_set_log_callback(ajar_log_fn fn, void *user)
{
	log_fn = fn;
	log_user = user;
}

const char *ajar_status_name(ajar_status status)
{
	switch (status) {
	case AJAR_OK: return "ok";
	case AJAR_ERROR_INVALID_ARGUMENT: return "invalid argument";
	case AJAR_ERROR_BAD_INPUT: return "bad input";
	case AJAR_ERROR_IO: return "i/o error";
	case AJAR_ERROR_DEVICE: return "device error";
	case AJAR_ERROR_OUT_OF_MEMORY: return "out of memory";
	case AJAR_ERROR_CANCELLED: return "cancelled";
	}
	return "unknown status";
}

const char *ajar_version(void) { return AJAR_VERSION_STRING; }

ajar_status err_set(ajar_status status, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(last_error, sizeof last_error, fmt, ap);
	va_end(ap);
	if (log_fn)
		log_fn(AJAR_LOG_ERROR, last_error, log_user);
	return status;
}

void err_clear(void) { last_error[0] = '\0'; }

void log_msg(ajar_log_level level, const char *fmt, ...)
{
	char buf[2048];
	va_list ap;
	if (!log_fn)
		return;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
	log_fn(level, buf, log_user);
}
