/* Private to the runtime: what the parallel sweeps (parallel.c) share with
 * the program's printing, plots and failures (program.c) and with the MPI
 * layer (runtime/mpi/parallel_mpi.c), and nothing else uses.
 *
 * A member of a sweep that runs on a pool thread or on another MPI rank must
 * not act on stdout or on a plot file: what it prints and plots is appended
 * to its own log, replayed in member order once the sweep is over, so the
 * output is the serial run's byte for byte. program.c asks the
 * sicm_parallel_log_* functions first and acts only when they decline. */
#ifndef SICM_PARALLEL_INTERNAL_H
#define SICM_PARALLEL_INTERNAL_H

#include <stddef.h>

#include "sicm/runtime.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- parallel.c, for program.c ------------------------------------------ */

/* When the calling thread runs a member of a buffered sweep, append the
 * text (len bytes), the point or the segment to the member's log and return
 * 1; otherwise return 0 and do nothing. */
int sicm_parallel_log_text(const char *s, size_t len);
int sicm_parallel_log_point(sicm_plot *plot, const char *series, double x, double y);
int sicm_parallel_log_line(sicm_plot *plot, const char *series, double x0, double y0, double x1,
                           double y1);
int sicm_parallel_log_clear(sicm_plot *plot);

/* When the calling thread runs a member of a buffered sweep, record
 * `message` (sicm_program_fail's whole stderr text, malloc'd, which the
 * sweep then owns; NULL when there was no memory to format it) as the
 * member's failure and leave the member: does not return. Otherwise
 * returns at once. */
void sicm_parallel_member_failed(char *message);

/* ---- parallel.c, for the MPI layer --------------------------------------- */

/* What an MPI run gives the sweeps: this process's rank among size, an
 * all-gather of byte blocks of any length and a broadcast from rank 0, and
 * what to do before a failure's exit. allgather and broadcast are
 * collective calls, made by every rank at the same point of the program.
 * allgather: every rank gives its block (len bytes); it returns one
 * malloc'd buffer (the caller frees it) holding every rank's block in rank
 * order, their lengths in lens[0..size-1]; NULL on every rank if memory runs
 * out on one. broadcast: rank 0's value, on every rank. failing: this rank
 * is about to exit with status 70 (perhaps alone). */
typedef struct {
  int rank, size;
  void *(*allgather)(const void *block, size_t len, size_t *lens);
  int (*broadcast)(int value);
  void (*failing)(void);
} sicm_parallel_mpi;

/* Install the MPI run (the struct is copied): sweeps then spread their
 * members over the ranks, and every rank but 0 is made quiet
 * (sicm_program_set_quiet). Called once, by sicm_mpi_start. */
void sicm_parallel_use_mpi(const sicm_parallel_mpi *mpi);

/* For program.c's frames, which only rank 0 creates: rank 0's value (a
 * collective call under MPI, made outside members); the value itself in a
 * program without MPI and inside a member. */
int sicm_parallel_rank0_value(int value);

/* For program.c, before it exits with status 70: tells the MPI layer
 * (nothing without MPI). */
void sicm_parallel_failing(void);

/* ---- program.c, for parallel.c and the MPI layer ------------------------- */

/* A quiet program (an MPI rank other than 0) prints nothing on stdout or
 * stderr, creates no plot file (frames are sicm_plot_open_silent plots) and
 * fails without a message, with the same exit status. */
void sicm_program_set_quiet(int quiet);
int sicm_program_quiet(void);

/* The real output of a member's logged text: len bytes to stdout (nothing
 * when quiet). */
void sicm_program_write(const char *s, size_t len);

/* The real end of a member's failure: flush stdout, write `message` (as
 * sicm_parallel_member_failed received it) on stderr unless quiet, finish
 * every plot and exit with status 70. */
void sicm_program_fail_message(const char *message)
#if defined(__GNUC__)
    __attribute__((noreturn))
#endif
    ;

/* The frames sicm_program_frame has made, numbered from 0 in the order they
 * were made: every rank of an MPI run makes the same frames in the same
 * order, so a number names one frame on every rank where a pointer would
 * not. sicm_program_frame_number is SIZE_MAX for a plot it did not make;
 * sicm_program_frame_at is NULL for a number past the last frame. */
size_t sicm_program_frame_number(const sicm_plot *plot);
sicm_plot *sicm_program_frame_at(size_t number);

#ifdef __cplusplus
}
#endif

#endif /* SICM_PARALLEL_INTERNAL_H */
