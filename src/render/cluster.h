/* cluster.h — the ranks of an Open MPI job, as render_job.c uses them: who we
 * are, small messages, and the integer sum of films at rank 0.
 *
 * Built with Open MPI (the Makefile defines AJAR_MPI for cluster.c alone
 * when it finds it) or without it, when there is always one rank and
 * every call below is a no-op for it. MPI is initialised only when the
 * process was started by mpirun (ajar_mpi_init), so a program run alone
 * behaves exactly as without MPI.
 *
 * Every wait polls with short sleeps instead of spinning in MPI (a rank
 * spinning would take a core from the renderer next to it), with the MPI
 * calls serialised by one lock (MPI_THREAD_SERIALIZED). `cancel`, when not
 * NULL, bounds a wait: once it is set, a peer that does not answer within
 * CLUSTER_STOP_WAIT seconds is given up (it was killed or its machine
 * failed; generous, since a first pass may include a minute of the
 * driver's compiling). The calls return 1 when done, 0 when given up, -1 on an MPI
 * error (message in ajar_last_error). */
#ifndef AJAR_CLUSTER_H
#define AJAR_CLUSTER_H
#include <stdatomic.h>
#include <stddef.h>

#include "ajar.h"

#define CLUSTER_STOP_WAIT 60.0
#define CLUSTER_ANY (-1)

int cluster_rank(void);
int cluster_size(void);
/* This rank's host name ("" without MPI). */
const char *cluster_host(void);

/* Sends a small message (at most a few KiB) to rank `to`. */
int cluster_send(int to, int tag, const void *buf, size_t bytes);
/* Receives the next message from `from` with tag `tag` (CLUSTER_ANY: any
 * tag; *tag_out says which) into buf (exactly `bytes`); returns 0 without
 * one once `stop` (if not NULL) is set. */
int cluster_recv(int from, int tag, void *buf, size_t bytes, int *tag_out, const atomic_int *stop,
		 const atomic_int *cancel);
/* Every rank's `bytes` bytes, in rank order, to every rank. */
int cluster_allgather(const void *mine, void *all, size_t bytes, const atomic_int *cancel);
/* Rank 0's `bytes` bytes to every rank. */
int cluster_bcast(void *buf, size_t bytes, const atomic_int *cancel);
/* Sums buf (n longs) over every rank into rank 0's buf (others' are
 * left as they were): integer sums, exact in any order. */
int cluster_sum(long *buf, size_t n, const atomic_int *cancel);
#endif
