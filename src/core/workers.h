/* workers.h — a fixed set of threads that run one function in parts, for
 * the host's parallel loops (the BVH build). Part 0 runs on the calling
 * thread, so a set of one thread starts none and runs everything inline. */
#ifndef AJAR_WORKERS_H
#define AJAR_WORKERS_H
#include <pthread.h>

#include "ajar.h"

typedef void (*WorkFn)(void *ctx, int part, int nparts);

typedef struct {
	int n;                 /* threads, the caller's included */
	pthread_t *threads;    /* n - 1 started */
	pthread_mutex_t mu;
	pthread_cond_t go, done;
	unsigned long gen;     /* bumped for every run */
	int pending;           /* started threads still in the current run */
	int quit;
	WorkFn fn;
	void *ctx;
} Workers;

/* The processors this process may run on (its affinity mask), at least 1. */
int workers_cores(void);
/* Starts n - 1 threads (n >= 1); if some cannot start, fewer: w->n says. */
ajar_status workers_start(Workers *w, int n);
/* fn(ctx, part, w->n) for every part at once; returns when all are done. */
void workers_run(Workers *w, WorkFn fn, void *ctx);
void workers_stop(Workers *w);
#endif
