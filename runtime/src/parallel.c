/* Parallel sweeps: the members of parallel-map and parallel-for-each run on a
 * pool of threads and, under MPI, across ranks, and what they print and plot
 * comes out in member order, as a serial run prints it (see
 * sicm_parallel_map in sicm/program.h).
 *
 * Threads are POSIX threads, not C11 <threads.h>: the default thread count is
 * the CPU affinity mask's (sched_getaffinity; under mpirun a rank is bound
 * to its share of the cores), a forked child must find the pool empty
 * (pthread_atfork), and <threads.h> is missing from older C libraries and
 * from macOS, while pthreads are everywhere the runtime builds.
 *
 * The pool. Pool threads are started by the first sweep that needs them and
 * then kept, idle on a condition variable, because a program may sweep
 * inside a loop thousands of times. The calling thread works too: --threads
 * N is N - 1 pool threads. Members are claimed from an atomic counter in
 * increasing index order, so that when member k fails every member before k
 * has been started; a member after the lowest failure so far is not
 * started, and every started member runs to its end, so the members before
 * the first failure have all run.
 *
 * Logs. A running member's prints and plot marks are appended to its log, a
 * growable byte string of records (text; a point; a segment), found through
 * a thread-local pointer that program.c consults. After the sweep the
 * calling thread replays the logs in member order through program.c's real
 * output, and if a member failed, replays the members before it and its own
 * log, then reports its error (sicm_program_fail's text, formatted in the
 * member, which left it by longjmp) and exits with status 70.
 *
 * MPI (runtime/mpi/parallel_mpi.c installs it): member i runs on rank
 * i % size, each rank's members on its own threads; then every rank sends
 * every rank its members' states, outputs, logs and errors in one
 * all-gather, every rank fills out[] for all members, rank 0 replays the
 * logs, and on a failure every rank exits 70 (only rank 0 saying why). In
 * the exchanged logs a plot is its frame number, the same on every rank. */
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT */
#include <pthread.h>
#include <sched.h>
#include <setjmp.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <gsl/gsl_errno.h>

#include "parallel_internal.h"
#include "sicm/runtime.h"

/* ---- the settings: threads and ranks -------------------------------------- */

static int threads;                                      /* 0 until decided */
static sicm_parallel_mpi mpi = {0, 1, NULL, NULL, NULL}; /* one rank without MPI */
static const char kWho[] = "parallel-map";               /* what the sweep's own failures name */
static const double kProgressAfter = 1.0;                /* seconds before a progress line shows */
static const double kProgressEvery = 0.1;                /* seconds between its updates */

/* The cores this process may run on. */
static int default_threads(void) {
#ifdef CPU_COUNT
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
#endif
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? (int)n : 1;
}

void sicm_parallel_set_threads(int n) {
  threads = n < 1 ? 1 : n;
}

int sicm_parallel_threads(void) {
  if (threads == 0) threads = default_threads();
  return threads;
}

void sicm_parallel_use_mpi(const sicm_parallel_mpi *m) {
  mpi = *m;
  sicm_program_set_quiet(mpi.rank != 0);
}

/* The member the calling thread runs, NULL outside members (below). */
typedef struct member_run member_run;
static _Thread_local member_run *running;

int sicm_parallel_rank0_value(int value) {
  return mpi.size > 1 && !running ? mpi.broadcast(value) : value;
}

void sicm_parallel_failing(void) {
  if (mpi.failing) mpi.failing();
}

/* ---- logs ------------------------------------------------------------------ */

enum { kText = 'T', kPoint = 'P', kLine = 'L', kClear = 'C' };

/* A record: its tag, then for kText a uint64 length and the bytes, for
 * kPoint a uint64 plot reference, the series' name (a uint64 length, 0 for
 * the unnamed series, and the bytes) and x, y, for kLine the reference, the
 * name and x0, y0, x1, y1, for kClear the reference and an empty name.
 * Fields are unaligned (memcpy). Consecutive texts
 * are merged. */
typedef struct {
  unsigned char *bytes;
  size_t len, cap;
  size_t text_len_at; /* where the last record's length is, if it is a text; else 0 */
} byte_log;

enum { kNotRun, kDone, kFailed };

typedef struct {
  byte_log log;
  char *error; /* kFailed: sicm_program_fail's whole text; NULL if memory ran out */
  int state;
} member;

typedef struct {
  const sicm_site *site;
  const sicm_closure *fns;
  size_t nfns;
  const double *in;
  size_t in_width;
  double *out;
  size_t out_width;
  size_t first, stride; /* this rank's members are first, first + stride, ... */
  size_t count;         /* how many of them */
  member *members;      /* count of them, by local index */
  atomic_size_t next;   /* the next local index to claim */
  atomic_size_t stop;   /* the lowest local index that failed; SIZE_MAX if none */
  atomic_size_t done;   /* members finished */
  /* The progress line on a terminal. */
  int progress;
  double start, last_shown;
  int shown_width;
  pthread_mutex_t progress_lock;
} sweep;

struct member_run {
  member *m;
  jmp_buf leave; /* where sicm_program_fail in the member goes */
};

/* Room for `more` bytes after the first len of *bytes (capacity *cap,
 * doubled as needed); 0 if memory runs out. */
static int grow(unsigned char **bytes, size_t len, size_t *cap, size_t more) {
  if (more <= *cap - len) return 1;
  if (more > SIZE_MAX - len) return 0;
  size_t want = *cap ? *cap : 256;
  while (want < len + more)
    want = want > SIZE_MAX / 2 ? len + more : 2 * want;
  unsigned char *grown = realloc(*bytes, want);
  if (!grown) return 0;
  *bytes = grown;
  *cap = want;
  return 1;
}

/* Append len bytes to the running member's log; out of memory, the member
 * fails (reported at the sweep's site). */
static void log_put(const void *data, size_t len) {
  byte_log *log = &running->m->log;
  if (!grow(&log->bytes, log->len, &log->cap, len)) sicm_parallel_member_failed(NULL);
  memcpy(log->bytes + log->len, data, len);
  log->len += len;
}

static void log_u64(uint64_t v) {
  log_put(&v, sizeof v);
}

int sicm_parallel_log_text(const char *s, size_t len) {
  if (!running) return 0;
  byte_log *log = &running->m->log;
  if (log->text_len_at) {
    uint64_t total;
    memcpy(&total, log->bytes + log->text_len_at, sizeof total);
    log_put(s, len);
    total += len;
    memcpy(log->bytes + log->text_len_at, &total, sizeof total);
    return 1;
  }
  const unsigned char tag = kText;
  log_put(&tag, 1);
  const size_t at = log->len;
  log_u64(len);
  log_put(s, len);
  log->text_len_at = at; /* set last: a failed put leaves no half record to extend */
  return 1;
}

static void log_mark(unsigned char tag, sicm_plot *plot, const char *series, const double *xs,
                     size_t count) {
  running->m->log.text_len_at = 0;
  log_put(&tag, 1);
  log_u64((uint64_t)(uintptr_t)plot);
  const size_t name_len = series ? strlen(series) : 0;
  log_u64(name_len);
  log_put(series ? series : "", name_len);
  log_put(xs, count * sizeof *xs);
}

int sicm_parallel_log_point(sicm_plot *plot, const char *series, double x, double y) {
  if (!running) return 0;
  const double xs[2] = {x, y};
  log_mark(kPoint, plot, series, xs, 2);
  return 1;
}

int sicm_parallel_log_line(sicm_plot *plot, const char *series, double x0, double y0, double x1,
                           double y1) {
  if (!running) return 0;
  const double xs[4] = {x0, y0, x1, y1};
  log_mark(kLine, plot, series, xs, 4);
  return 1;
}

int sicm_parallel_log_clear(sicm_plot *plot) {
  if (!running) return 0;
  log_mark(kClear, plot, NULL, NULL, 0);
  return 1;
}

void sicm_parallel_member_failed(char *message) {
  if (!running) return;
  running->m->error = message;
  longjmp(running->leave, 1);
}

/* Walk a log's records: replay them (replay != 0) or turn their plot
 * pointers into frame numbers (for another rank). numbered: the references
 * are frame numbers already. */
static void walk_log(const sicm_site *site, unsigned char *bytes, size_t len, int replay,
                     int numbered) {
  size_t at = 0;
  while (at < len) {
    const unsigned char tag = bytes[at++];
    uint64_t v;
    memcpy(&v, bytes + at, sizeof v);
    at += sizeof v;
    if (tag == kText) {
      if (replay) sicm_program_write((const char *)bytes + at, (size_t)v);
      at += (size_t)v;
      continue;
    }
    const size_t ref_at = at - sizeof v;
    uint64_t name_len;
    memcpy(&name_len, bytes + at, sizeof name_len);
    at += sizeof name_len;
    /* The name is copied out to end it with a NUL (the log has none). */
    char *series = NULL;
    if (replay && name_len > 0) {
      series = malloc((size_t)name_len + 1);
      if (!series) sicm_program_fail(site, kWho, "out of memory for what the members plot");
      memcpy(series, bytes + at, (size_t)name_len);
      series[name_len] = '\0';
    }
    at += (size_t)name_len;
    double xs[4];
    const size_t count = tag == kPoint ? 2 : tag == kLine ? 4 : 0;
    memcpy(xs, bytes + at, count * sizeof *xs);
    at += count * sizeof *xs;
    if (!replay) {
      /* A plot not made by sicm_program_frame has no number: dropped. */
      const size_t number = sicm_program_frame_number((sicm_plot *)(uintptr_t)v);
      const uint64_t ref = number == SIZE_MAX ? UINT64_MAX : (uint64_t)number;
      memcpy(bytes + ref_at, &ref, sizeof ref);
      continue;
    }
    sicm_plot *plot = numbered ? (v == UINT64_MAX ? NULL : sicm_program_frame_at((size_t)v))
                               : (sicm_plot *)(uintptr_t)v;
    if (plot && tag == kClear)
      sicm_program_plot_clear(site, plot);
    else if (plot && tag == kPoint)
      sicm_program_plot_series_point(site, plot, series, xs[0], xs[1]);
    else if (plot)
      sicm_program_plot_series_line(site, plot, series, xs[0], xs[1], xs[2], xs[3]);
    free(series);
  }
}

/* The end of a sweep whose first failing member's log has been replayed:
 * that member's error (NULL: there was no memory for it), then exit 70. */
static void report_failure(const sweep *s, const char *error) {
  if (!error) sicm_program_fail(s->site, kWho, "out of memory for what the members print");
  sicm_program_fail_message(error);
}

/* ---- running members ------------------------------------------------------- */

static void call_member(const sweep *s, size_t i) {
  const sicm_closure *f = &s->fns[s->nfns == 1 ? 0 : i];
  f->fn(s->in ? s->in + i * s->in_width : NULL, s->out ? s->out + i * s->out_width : NULL, f->p);
}

/* Lower s->stop to j if j is below it. */
static void stop_at(sweep *s, size_t j) {
  size_t seen = atomic_load(&s->stop);
  while (j < seen && !atomic_compare_exchange_weak(&s->stop, &seen, j)) {
  }
}

static void run_member(sweep *s, size_t j) {
  member_run run;
  run.m = &s->members[j];
  running = &run;
  if (setjmp(run.leave) == 0) {
    call_member(s, s->first + j * s->stride);
    s->members[j].state = kDone;
  } else {
    s->members[j].state = kFailed;
    stop_at(s, j);
  }
  running = NULL;
}

static void show_progress(sweep *s) {
  const double now = sicm_stats_clock();
  if (now - s->start < kProgressAfter) return;
  if (pthread_mutex_trylock(&s->progress_lock) != 0) return; /* another thread is at it */
  if (now - s->last_shown >= kProgressEvery) {
    int width = fprintf(stderr, "\rparallel-map: %zu/%zu members", atomic_load(&s->done), s->count);
    if (width > s->shown_width) s->shown_width = width;
    s->last_shown = now;
  }
  pthread_mutex_unlock(&s->progress_lock);
}

static void erase_progress(const sweep *s) {
  if (s->shown_width > 0) fprintf(stderr, "\r%*s\r", s->shown_width, "");
}

/* What each thread of a sweep does: claim members until none is left. */
static void work(sweep *s) {
  for (;;) {
    const size_t j = atomic_fetch_add(&s->next, 1);
    if (j >= s->count || j > atomic_load(&s->stop)) return;
    run_member(s, j);
    atomic_fetch_add(&s->done, 1);
    if (s->progress) show_progress(s);
  }
}

/* ---- the pool -------------------------------------------------------------- */

static pthread_mutex_t pool_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t pool_wake = PTHREAD_COND_INITIALIZER;
static pthread_cond_t pool_idle = PTHREAD_COND_INITIALIZER;
static int pool_threads;  /* started */
static sweep *pool_sweep; /* the sweep in progress, NULL between sweeps */
static int pool_wanted;   /* how many times pool threads join it */
static int pool_joined;   /* how many times they have */
static int pool_busy;     /* joins not yet finished */
static pthread_once_t fork_once = PTHREAD_ONCE_INIT;

/* A pool thread may join a sweep twice if it is quicker than another is to
 * wake; that is harmless (work returns when nothing is left), and the sweep
 * ends when all pool_wanted joins have finished. */
static void *pool_thread(void *unused) {
  (void)unused;
  pthread_mutex_lock(&pool_lock);
  for (;;) {
    while (!pool_sweep || pool_joined == pool_wanted)
      pthread_cond_wait(&pool_wake, &pool_lock);
    sweep *s = pool_sweep;
    ++pool_joined;
    pthread_mutex_unlock(&pool_lock);
    work(s);
    pthread_mutex_lock(&pool_lock);
    if (--pool_busy == 0) pthread_cond_signal(&pool_idle);
  }
  return NULL;
}

/* A forked child has only the thread that forked: its pool is empty. */
static void pool_after_fork(void) {
  pthread_mutex_init(&pool_lock, NULL);
  pthread_cond_init(&pool_wake, NULL);
  pthread_cond_init(&pool_idle, NULL);
  pool_threads = 0;
  pool_sweep = NULL;
  pool_wanted = pool_joined = pool_busy = 0;
}

static void watch_forks(void) {
  pthread_atfork(NULL, NULL, pool_after_fork);
}

/* Run the sweep on the calling thread and `helpers` pool threads (fewer if
 * no more can be started). */
static void run_on_pool(sweep *s, int helpers) {
  pthread_once(&fork_once, watch_forks);
  pthread_mutex_lock(&pool_lock);
  while (pool_threads < helpers) {
    pthread_t t;
    if (pthread_create(&t, NULL, pool_thread, NULL) != 0) break;
    pthread_detach(t);
    ++pool_threads;
  }
  if (helpers > pool_threads) helpers = pool_threads;
  pool_sweep = s;
  pool_wanted = pool_busy = helpers;
  pool_joined = 0;
  pthread_cond_broadcast(&pool_wake);
  pthread_mutex_unlock(&pool_lock);
  work(s);
  pthread_mutex_lock(&pool_lock);
  while (pool_busy > 0)
    pthread_cond_wait(&pool_idle, &pool_lock);
  pool_sweep = NULL;
  pthread_mutex_unlock(&pool_lock);
}

/* ---- the exchange between MPI ranks --------------------------------------- */

/* A rank's block: for each of its members, in order, a state byte; for a
 * member that ran, its outputs (out_width doubles), its log (uint64 length,
 * bytes, plots as frame numbers); for one that failed, its log and its error
 * (uint64 length, UINT64_MAX for none, bytes). */
typedef struct {
  unsigned char *bytes;
  size_t len, cap;
  int failed; /* out of memory */
} block;

static void block_put(block *b, const void *data, size_t len) {
  /* Nothing to add: data may be NULL then (an empty list's items), and
   * memcpy from NULL is undefined even for 0 bytes. */
  if (b->failed || len == 0) return;
  if (!grow(&b->bytes, b->len, &b->cap, len)) {
    b->failed = 1;
    return;
  }
  memcpy(b->bytes + b->len, data, len);
  b->len += len;
}

static void block_u64(block *b, uint64_t v) {
  block_put(b, &v, sizeof v);
}

static void pack(const sweep *s, block *b) {
  const size_t stop = atomic_load(&s->stop);
  for (size_t j = 0; j < s->count; ++j) {
    member *m = &s->members[j];
    const unsigned char state = j > stop ? kNotRun : (unsigned char)m->state;
    block_put(b, &state, 1);
    if (state == kNotRun) continue;
    if (state == kDone && s->out_width)
      block_put(b, s->out + (s->first + j * s->stride) * s->out_width,
                s->out_width * sizeof *s->out);
    walk_log(s->site, m->log.bytes, m->log.len, 0, 0);
    block_u64(b, m->log.len);
    block_put(b, m->log.bytes, m->log.len);
    if (state == kFailed) {
      block_u64(b, m->error ? strlen(m->error) : UINT64_MAX);
      if (m->error) block_put(b, m->error, strlen(m->error));
    }
  }
}

/* One member as read from a block. */
typedef struct {
  int state;
  const double *out; /* unaligned: memcpy from it */
  unsigned char *log;
  size_t log_len;
  const char *error;
  size_t error_len; /* SIZE_MAX: no error text */
} received;

static uint64_t read_u64(const unsigned char **at) {
  uint64_t v;
  memcpy(&v, *at, sizeof v);
  *at += sizeof v;
  return v;
}

/* Read every rank's block into got[0..n-1] (member i from rank i % size). */
static void unpack(const sweep *s, size_t n, unsigned char *all, const size_t *lens,
                   received *got) {
  const size_t size = (size_t)mpi.size;
  unsigned char *start = all;
  for (size_t r = 0; r < size; ++r) {
    const unsigned char *at = start;
    for (size_t i = r; i < n; i += size) {
      received *g = &got[i];
      memset(g, 0, sizeof *g);
      g->state = *at++;
      if (g->state == kNotRun) continue;
      if (g->state == kDone && s->out_width) {
        g->out = (const double *)at;
        at += s->out_width * sizeof(double);
      }
      g->log_len = (size_t)read_u64(&at);
      g->log = (unsigned char *)at;
      at += g->log_len;
      if (g->state == kFailed) {
        const uint64_t len = read_u64(&at);
        g->error_len = len == UINT64_MAX ? SIZE_MAX : (size_t)len;
        if (len != UINT64_MAX) {
          g->error = (const char *)at;
          at += len;
        }
      }
    }
    start += lens[r];
  }
}

/* After the members of every rank have run: exchange, fill out[], replay on
 * rank 0, and fail everywhere if a member failed. */
static void finish_across_ranks(sweep *s, size_t n) {
  size_t *lens = malloc((size_t)mpi.size * sizeof *lens);
  if (!lens) sicm_program_fail(s->site, kWho, "out of memory");
  block mine = {NULL, 0, 0, 0};
  pack(s, &mine);
  received *got = malloc(n * sizeof *got);
  /* Out of memory here: an empty block (a rank with members never sends
   * one) tells every rank, so that all fail together. */
  if (mine.failed || !got) mine.len = 0;
  void *all = mpi.allgather(mine.bytes, mine.len, lens);
  free(mine.bytes);
  int lost = !all || !got;
  for (int r = 0; !lost && r < mpi.size; ++r)
    if (lens[r] == 0 && (size_t)r < n) lost = 1;
  if (lost) sicm_program_fail(s->site, kWho, "out of memory for the members' results");
  unpack(s, n, all, lens, got);
  size_t failed = n;
  for (size_t i = 0; i < n && failed == n; ++i)
    if (got[i].state == kFailed) failed = i;
  for (size_t i = 0; i < n && i < failed; ++i)
    if (s->out_width) memcpy(s->out + i * s->out_width, got[i].out, s->out_width * sizeof *s->out);
  if (mpi.rank == 0)
    for (size_t i = 0; i < n && i <= failed; ++i)
      walk_log(s->site, got[i].log, got[i].log_len, 1, 1);
  if (failed < n) {
    const received *g = &got[failed];
    char *error = NULL;
    if (g->error_len != SIZE_MAX && (error = malloc(g->error_len + 1))) {
      memcpy(error, g->error, g->error_len);
      error[g->error_len] = '\0';
    }
    report_failure(s, error);
  }
  free(all);
  free(got);
  free(lens);
}

/* ---- the sweep ------------------------------------------------------------- */

/* Members one after another on this thread, unbuffered (serial sweeps,
 * sweeps inside members, and one thread on one rank). */
static void run_in_order(const sweep *s, size_t n) {
  for (size_t i = 0; i < n; ++i)
    call_member(s, i);
}

void sicm_parallel_map(const sicm_site *site, const sicm_closure *fns, size_t nfns, size_t n,
                       const double *in, size_t in_width, double *out, size_t out_width,
                       int serial) {
  if (n == 0) return;
  sweep s = {.site = site,
             .fns = fns,
             .nfns = nfns,
             .in = in_width ? in : NULL,
             .in_width = in_width,
             .out = out_width ? out : NULL,
             .out_width = out_width};
  if (serial || running || (sicm_parallel_threads() == 1 && mpi.size == 1)) {
    /* Inside a member, the members of a nested sweep go into its log. */
    run_in_order(&s, n);
    return;
  }
  s.first = (size_t)mpi.rank;
  s.stride = (size_t)mpi.size;
  s.count = n > s.first ? (n - s.first + s.stride - 1) / s.stride : 0;
  s.members = calloc(s.count ? s.count : 1, sizeof *s.members);
  if (!s.members) sicm_program_fail(site, kWho, "out of memory");
  atomic_init(&s.next, 0);
  atomic_init(&s.stop, SIZE_MAX);
  atomic_init(&s.done, 0);
  s.progress = mpi.rank == 0 && !sicm_program_quiet() && isatty(2);
  s.start = s.last_shown = sicm_stats_clock();
  pthread_mutex_init(&s.progress_lock, NULL);
  /* Switched off before any thread enters GSL (see sicm/error.h). */
  gsl_set_error_handler_off();

  const size_t nthreads = (size_t)sicm_parallel_threads();
  const size_t workers = s.count < nthreads ? s.count : nthreads;
  if (workers > 1)
    run_on_pool(&s, (int)workers - 1);
  else
    work(&s);
  erase_progress(&s);
  pthread_mutex_destroy(&s.progress_lock);

  if (mpi.size > 1) {
    finish_across_ranks(&s, n);
  } else {
    const size_t failed = atomic_load(&s.stop);
    for (size_t j = 0; j < s.count && j <= failed; ++j)
      walk_log(site, s.members[j].log.bytes, s.members[j].log.len, 1, 0);
    if (failed != SIZE_MAX) report_failure(&s, s.members[failed].error);
  }
  for (size_t j = 0; j < s.count; ++j) {
    free(s.members[j].log.bytes);
    free(s.members[j].error);
  }
  free(s.members);
}
