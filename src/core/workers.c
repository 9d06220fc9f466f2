/* workers.c — the thread set of workers.h: each started thread waits for
 * the next run (a generation count under one mutex), runs its part and
 * reports back; runs are rare and long (a BVH node's bins over a million
 * references, a subtree), so one mutex and two condition variables do. */
#include "core/workers.h"

#include <sched.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

typedef struct {
	Workers *w;
	int part;
} Start;

static void *worker_main(void *arg)
{
	Start *s = arg;
	Workers *w = s->w;
	int part = s->part;
	free(s);
	unsigned long seen = 0;
	pthread_mutex_lock(&w->mu);
	for (;;) {
		while (w->gen == seen && !w->quit)
			pthread_cond_wait(&w->go, &w->mu);
		if (w->quit)
			break;
		seen = w->gen;
		WorkFn fn = w->fn;
		void *ctx = w->ctx;
		pthread_mutex_unlock(&w->mu);
		fn(ctx, part, w->n);
		pthread_mutex_lock(&w->mu);
		if (--w->pending == 0)
			pthread_cond_signal(&w->done);
	}
	pthread_mutex_unlock(&w->mu);
	return NULL;
}

int workers_cores(void)
{
	cpu_set_t set;
	if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
		return CPU_COUNT(&set);
	return 1;
}

ajar_status workers_start(Workers *w, int n)
{
	memset(w, 0, sizeof *w);
	w->n = 1;
	pthread_mutex_init(&w->mu, NULL);
	pthread_cond_init(&w->go, NULL);
	pthread_cond_init(&w->done, NULL);
	if (n <= 1)
		return AJAR_OK;
	w->threads = malloc(sizeof *w->threads * (size_t)(n - 1));
	if (!w->threads)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "out of memory for %d threads", n);
	/* Parts are numbered as threads start; one that cannot start leaves
	 * the set smaller, never a part without a thread. */
	for (int i = 1; i < n; i++) {
		Start *s = malloc(sizeof *s);
		if (!s)
			break;
		s->w = w;
		s->part = i;
		if (pthread_create(&w->threads[i - 1], NULL, worker_main, s) != 0) {
			free(s);
			break;
		}
		w->n = i + 1;
	}
	return AJAR_OK;
}

void workers_run(Workers *w, WorkFn fn, void *ctx)
{
	pthread_mutex_lock(&w->mu);
	w->fn = fn;
	w->ctx = ctx;
	w->pending = w->n - 1;
	w->gen++;
	pthread_cond_broadcast(&w->go);
	pthread_mutex_unlock(&w->mu);
	fn(ctx, 0, w->n);
	pthread_mutex_lock(&w->mu);
	while (w->pending > 0)
		pthread_cond_wait(&w->done, &w->mu);
	pthread_mutex_unlock(&w->mu);
}

void workers_stop(Workers *w)
{
	pthread_mutex_lock(&w->mu);
	w->quit = 1;
	pthread_cond_broadcast(&w->go);
	pthread_mutex_unlock(&w->mu);
	for (int i = 0; i < w->n - 1; i++)
		pthread_join(w->threads[i], NULL);
	free(w->threads);
	pthread_cond_destroy(&w->go);
	pthread_cond_destroy(&w->done);
	pthread_mutex_destroy(&w->mu);
	memset(w, 0, sizeof *w);
}
