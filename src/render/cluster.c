/* cluster.c — Open MPI for several machines (see cluster.h): start-up, the
 * polled waits, messages and the film sum. Without AJAR_MPI (Open MPI not
 * found at build time) one rank and the same entry points. */
#include "render/cluster.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/env_vars.h"
#include "core/error.h"

#ifdef AJAR_MPI
#include <mpi.h>
#include <pthread.h>

static int g_rank, g_size = 1, g_init;
static char g_host[MPI_MAX_PROCESSOR_NAME + 1];
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;

/* Started by a launcher: Open MPI's mpirun sets OMPI_COMM_WORLD_SIZE,
 * PMIx launchers (srun --mpi=pmix) PMIX_RANK. A process started alone
 * never initialises MPI, so it behaves exactly as a build without it. */
static int launched(void)
{
	return env_var(ENV_VAR_MPI_WORLD_SIZE) || env_var(ENV_VAR_PMIX_RANK) || env_var(ENV_VAR_PMI_RANK);
}

int ajar_mpi_available(void) { return 1; }

ajar_status ajar_mpi_init(int *argc, char ***argv)
{
	if (g_init || !launched())
		return AJAR_OK;
	int provided = 0, done = 0, ended = 0;
	MPI_Finalized(&ended);
	if (ended)
		return err_set(AJAR_ERROR_DEVICE, "MPI was finalised: it cannot be initialised again");
	MPI_Initialized(&done);
	if (!done && MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
		return err_set(AJAR_ERROR_DEVICE, "MPI_Init_thread failed");
	if (done)
		MPI_Query_thread(&provided);
	if (provided < MPI_THREAD_SERIALIZED)
		return err_set(AJAR_ERROR_DEVICE, "this MPI library does not allow calls from several threads "
						  "(MPI_THREAD_SERIALIZED)");
	/* Failed calls return an error (reported as a message) instead of
	 * aborting the job inside MPI. */
	MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
	MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
	MPI_Comm_size(MPI_COMM_WORLD, &g_size);
	int len = 0;
	MPI_Get_processor_name(g_host, &len);
	g_host[len] = '\0';
	g_init = 1 + !done; /* 2: ours to finalise */
	return AJAR_OK;
}

void ajar_mpi_finalize(void)
{
	if (g_init == 2)
		MPI_Finalize();
	g_init = 0;
	g_rank = 0;
	g_size = 1;
}

int cluster_rank(void) { return g_rank; }
int cluster_size(void) { return g_size; }
const char *cluster_host(void) { return g_host; }

static int mpi_failed(const char *what, int rc)
{
	char msg[MPI_MAX_ERROR_STRING + 1];
	int len = 0;
	if (MPI_Error_string(rc, msg, &len) != MPI_SUCCESS)
		len = 0;
	msg[len] = '\0';
	err_set(AJAR_ERROR_DEVICE, "rank %d (%s): %s failed: %s", g_rank, g_host, what, len ? msg : "?");
	return -1;
}

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Sleeps a little longer each round, from 50 us up to 1 ms. */
static void nap(long *ns)
{
	struct timespec ts = {0, *ns};
	nanosleep(&ts, NULL);
	if (*ns < 1000000)
		*ns *= 2;
}

/* Whether a wait should give up: cancel was set CLUSTER_STOP_WAIT ago
 * (*deadline, 0 until cancel is first seen, remembers when). */
static int cancel_expired(const atomic_int *cancel, double *deadline)
{
	if (!cancel || !atomic_load(cancel))
		return 0;
	if (*deadline == 0)
		*deadline = now() + CLUSTER_STOP_WAIT;
	return now() > *deadline;
}

/* Polls rq until it completes; 0 if cancel was set and CLUSTER_STOP_WAIT
 * passed without it (the request is then left alone: the job is over). */
static int wait_request(MPI_Request *rq, const char *what, const atomic_int *cancel)
{
	long ns = 50000;
	double deadline = 0;
	for (;;) {
		int flag = 0;
		pthread_mutex_lock(&g_lock);
		int rc = MPI_Test(rq, &flag, MPI_STATUS_IGNORE);
		pthread_mutex_unlock(&g_lock);
		if (rc != MPI_SUCCESS)
			return mpi_failed(what, rc);
		if (flag)
			return 1;
		if (cancel_expired(cancel, &deadline))
			return 0;
		nap(&ns);
	}
}

int cluster_send(int to, int tag, const void *buf, size_t bytes)
{
	MPI_Request rq;
	pthread_mutex_lock(&g_lock);
	int rc = MPI_Isend(buf, (int)bytes, MPI_BYTE, to, tag, MPI_COMM_WORLD, &rq);
	pthread_mutex_unlock(&g_lock);
	if (rc != MPI_SUCCESS)
		return mpi_failed("MPI_Isend", rc);
	return wait_request(&rq, "MPI_Isend", NULL);
}

int cluster_recv(int from, int tag, void *buf, size_t bytes, int *tag_out, const atomic_int *stop,
		 const atomic_int *cancel)
{
	long ns = 50000;
	double deadline = 0;
	int src = from == CLUSTER_ANY ? MPI_ANY_SOURCE : from, tg = tag == CLUSTER_ANY ? MPI_ANY_TAG : tag;
	for (;;) {
		int flag = 0, rc;
		MPI_Status s;
		pthread_mutex_lock(&g_lock);
		rc = MPI_Iprobe(src, tg, MPI_COMM_WORLD, &flag, &s);
		if (rc == MPI_SUCCESS && flag) {
			int count = 0;
			MPI_Get_count(&s, MPI_BYTE, &count);
			if ((size_t)count != bytes) {
				pthread_mutex_unlock(&g_lock);
				err_set(AJAR_ERROR_DEVICE, "rank %d: a message of %d bytes from rank %d (tag %d), %zu expected",
					g_rank, count, s.MPI_SOURCE, s.MPI_TAG, bytes);
				return -1;
			}
			rc = MPI_Recv(buf, count, MPI_BYTE, s.MPI_SOURCE, s.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		}
		pthread_mutex_unlock(&g_lock);
		if (rc != MPI_SUCCESS)
			return mpi_failed("MPI_Recv", rc);
		if (flag) {
			if (tag_out)
				*tag_out = s.MPI_TAG;
			return 1;
		}
		if (stop && atomic_load(stop))
			return 0;
		if (cancel_expired(cancel, &deadline))
			return 0;
		nap(&ns);
	}
}

int cluster_allgather(const void *mine, void *all, size_t bytes, const atomic_int *cancel)
{
	MPI_Request rq;
	pthread_mutex_lock(&g_lock);
	int rc = MPI_Iallgather(mine, (int)bytes, MPI_BYTE, all, (int)bytes, MPI_BYTE, MPI_COMM_WORLD, &rq);
	pthread_mutex_unlock(&g_lock);
	if (rc != MPI_SUCCESS)
		return mpi_failed("MPI_Iallgather", rc);
	return wait_request(&rq, "MPI_Iallgather", cancel);
}

int cluster_bcast(void *buf, size_t bytes, const atomic_int *cancel)
{
	MPI_Request rq;
	pthread_mutex_lock(&g_lock);
	int rc = MPI_Ibcast(buf, (int)bytes, MPI_BYTE, 0, MPI_COMM_WORLD, &rq);
	pthread_mutex_unlock(&g_lock);
	if (rc != MPI_SUCCESS)
		return mpi_failed("MPI_Ibcast", rc);
	return wait_request(&rq, "MPI_Ibcast", cancel);
}

int cluster_sum(long *buf, size_t n, const atomic_int *cancel)
{
	/* In pieces: an MPI count is an int. */
	const size_t piece = (size_t)1 << 24;
	for (size_t at = 0; at < n; at += piece) {
		int count = (int)(n - at < piece ? n - at : piece);
		MPI_Request rq;
		pthread_mutex_lock(&g_lock);
		int rc = g_rank == 0 ? MPI_Ireduce(MPI_IN_PLACE, buf + at, count, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD, &rq)
				     : MPI_Ireduce(buf + at, NULL, count, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD, &rq);
		pthread_mutex_unlock(&g_lock);
		if (rc != MPI_SUCCESS)
			return mpi_failed("MPI_Ireduce", rc);
		if ((rc = wait_request(&rq, "MPI_Ireduce", cancel)) != 1)
			return rc;
	}
	return 1;
}

#else /* no MPI: one rank */

int ajar_mpi_available(void) { return 0; }
ajar_status ajar_mpi_init(int *argc, char ***argv)
{
	(void)argc;
	(void)argv;
	const char *ranks = env_var(ENV_VAR_MPI_WORLD_SIZE);
	if (ranks && atoi(ranks) > 1)
		log_msg(AJAR_LOG_WARNING,
			"this ajar was built without Open MPI: each of the %d processes mpirun started renders the "
			"whole image alone",
			atoi(ranks));
	return AJAR_OK;
}
void ajar_mpi_finalize(void) {}
int cluster_rank(void) { return 0; }
int cluster_size(void) { return 1; }
const char *cluster_host(void) { return ""; }
int cluster_send(int to, int tag, const void *buf, size_t bytes)
{
	(void)to, (void)tag, (void)buf, (void)bytes;
	return err_set(AJAR_ERROR_DEVICE, "built without MPI"), -1;
}
int cluster_recv(int from, int tag, void *buf, size_t bytes, int *tag_out, const atomic_int *stop,
		 const atomic_int *cancel)
{
	(void)from, (void)tag, (void)buf, (void)bytes, (void)tag_out, (void)stop, (void)cancel;
	return err_set(AJAR_ERROR_DEVICE, "built without MPI"), -1;
}
int cluster_allgather(const void *mine, void *all, size_t bytes, const atomic_int *cancel)
{
	(void)cancel;
	memcpy(all, mine, bytes);
	return 1;
}
int cluster_bcast(void *buf, size_t bytes, const atomic_int *cancel)
{
	(void)buf, (void)bytes, (void)cancel;
	return 1;
}
int cluster_sum(long *buf, size_t n, const atomic_int *cancel)
{
	(void)buf, (void)n, (void)cancel;
	return 1;
}
#endif

int ajar_mpi_rank(void) { return cluster_rank(); }
int ajar_mpi_size(void) { return cluster_size(); }

/* Collective: the first non-zero code in rank order, on every rank. */
int ajar_mpi_agree(int code)
{
	if (cluster_size() <= 1)
		return code;
	int *all = calloc((size_t)cluster_size(), sizeof *all);
	if (!all)
		return code ? code : 6;
	int rc = cluster_allgather(&code, all, sizeof code, NULL);
	int agreed = code;
	for (int i = 0; rc == 1 && i < cluster_size(); i++)
		if (all[i]) {
			agreed = all[i];
			break;
		}
	free(all);
	return rc == 1 ? agreed : (code ? code : 3);
}
