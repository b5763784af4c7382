/* MPI for the parallel sweeps: sicm_mpi_start, and the rank, size and
 * collective calls it gives the sweeps (runtime/src/parallel.c).
 *
 * Compiled apart from the runtime, by the MPI wrapper compiler (mpicc), into
 * libsicmrt_mpi.a: runtime/src/ is compiled by the plain C compiler, without
 * mpi.h, and programs built without --mpi must not need the MPI libraries.
 *
 * Only the thread that called sicm_mpi_start (the program's main thread)
 * calls MPI, and only between sweeps: the pool threads never do, hence
 * MPI_THREAD_FUNNELED. MPI_Finalize runs at exit, after whatever the exit
 * finishes first (plots), so a normal end and a failure's exit(70) both end
 * MPI cleanly: every rank of a failing sweep exits 70 at the same point, and
 * so does every rank of a failure outside sweeps, since all ranks run the
 * same serial code (a frame whose files rank 0 cannot create fails on every
 * rank, see program.c).
 *
 * A rank may still fail alone (memory), and then MPI_Finalize waits for the
 * others, which wait for it in their next collective call: a failing rank
 * gives MPI_Finalize a grace period, then leaves with _exit(70), and mpirun
 * ends the job with status 70. Rank 0's grace is short: its message is out
 * by then, and the others would only fail the same way. A quiet rank's is
 * long: leaving first, it would have mpirun kill rank 0 before rank 0 has
 * said why. */
#define _POSIX_C_SOURCE 200809L /* sigaction */
#include <limits.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <mpi.h>

#include "../src/parallel_internal.h"
#include "sicm/runtime.h"

/* Allgatherv counts and displacements are ints: blocks whose total is
 * larger are broadcast rank by rank in pieces of this many bytes. */
enum { kPiece = 1 << 30 };

/* Seconds a failing rank waits in MPI_Finalize for the others. */
enum { kRank0Grace = 3, kQuietGrace = 300 };

static int rank;
static int failing;

static void note_failing(void) {
  failing = 1;
}

static void give_up(int sig) {
  (void)sig;
  _exit(70);
}

static void finalize_at_exit(void) {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) return;
  /* What this rank printed reaches mpirun before MPI is gone. */
  fflush(stdout);
  fflush(stderr);
  if (failing) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = give_up;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGALRM, &sa, NULL);
    alarm(rank == 0 ? kRank0Grace : kQuietGrace);
  }
  MPI_Finalize();
  alarm(0);
}

/* Every rank: 1 if all ranks say ok. */
static int all_ok(int ok) {
  int all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all;
}

static void *allgather(const void *block, size_t len, size_t *lens) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  uint64_t mine = len, *all_lens = malloc((size_t)size * sizeof *all_lens);
  int *counts = malloc((size_t)size * sizeof *counts),
      *displs = malloc((size_t)size * sizeof *displs);
  if (!all_ok(all_lens && counts && displs)) {
    free(all_lens), free(counts), free(displs);
    return NULL;
  }
  MPI_Allgather(&mine, 1, MPI_UINT64_T, all_lens, 1, MPI_UINT64_T, MPI_COMM_WORLD);
  uint64_t total = 0;
  for (int r = 0; r < size; ++r) {
    lens[r] = (size_t)all_lens[r];
    total += all_lens[r];
  }
  unsigned char *all = total <= SIZE_MAX ? malloc(total ? (size_t)total : 1) : NULL;
  if (!all_ok(all != NULL)) {
    free(all), free(all_lens), free(counts), free(displs);
    return NULL;
  }
  if (total <= INT_MAX) {
    int at = 0;
    for (int r = 0; r < size; ++r) {
      counts[r] = (int)all_lens[r];
      displs[r] = at;
      at += counts[r];
    }
    MPI_Allgatherv(block, (int)len, MPI_BYTE, all, counts, displs, MPI_BYTE, MPI_COMM_WORLD);
  } else {
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    size_t at = 0;
    for (int r = 0; r < size; ++r) {
      unsigned char *from_r = all + at;
      if (rank == r && len) memcpy(from_r, block, len);
      for (size_t done = 0; done < lens[r]; done += kPiece) {
        const size_t piece = lens[r] - done < (size_t)kPiece ? lens[r] - done : (size_t)kPiece;
        MPI_Bcast(from_r + done, (int)piece, MPI_BYTE, r, MPI_COMM_WORLD);
      }
      at += lens[r];
    }
  }
  free(all_lens), free(counts), free(displs);
  return all;
}

static int broadcast(int value) {
  MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return value;
}

/* Was this process started by an MPI launcher (mpirun, mpiexec, srun)? Each
 * sets its rank in the environment. Without one, MPI would start as a
 * singleton, which costs Open MPI about 0.4 s here and gives one rank: the
 * program runs as one process without it. */
static int launched_by_mpi(void) {
  static const char *const vars[] = {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK",
                                     "SLURM_PROCID", "MPI_LOCALRANKID"};
  for (size_t i = 0; i < sizeof vars / sizeof vars[0]; ++i)
    if (getenv(vars[i])) return 1;
  return 0;
}

void sicm_mpi_start(int *argc, char ***argv) {
  if (!launched_by_mpi()) return;
  /* An MPI that provides less would still see calls from one thread only. */
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  atexit(finalize_at_exit);
  sicm_parallel_mpi m = {0, 1, allgather, broadcast, note_failing};
  MPI_Comm_rank(MPI_COMM_WORLD, &m.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &m.size);
  rank = m.rank;
  sicm_parallel_use_mpi(&m);
}
