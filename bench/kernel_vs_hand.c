/* Times a sicm-compiled state-derivative kernel against hand-written C of the same derivative.
 *
 * Built and run by bench/kernel-vs-hand, once per system, with
 *   -DDIM=n                 the number of state leaves (t first)
 *   -DGEN_KERNEL=name       the kernel `sicm emit-c` printed, renamed by the driver
 *   -DHAND_KERNEL=name      the hand-written version (bench/kernels/hand_*.c)
 *   -DGEN_PARAMS={...}      the p[] the generated kernel takes (its captured numbers, which
 *                           `sicm emit-kernels` prints above it; the hand-written one has
 *                           its numbers as constants and is given no p[])
 * Both are compiled as separate translation units with the same flags as this file, so
 * neither is inlined here and both are called as the runtime calls a kernel: through the
 * ABI void f(const double *in, double *out, const double *p).
 *
 * First the two are checked against each other at random states (they must agree to 1e-12,
 * relative to the size of the value, or the timing means nothing). Then each is called N
 * times in a row, the derivative fed back into the state by a tiny Euler step so that no call
 * can be hoisted or skipped, in R rounds; the order alternates between rounds because the
 * machines are noisy and a ratio taken round by round is steadier than two separate series.
 *
 * usage: kernel_vs_hand N ROUNDS y0[0] ... y0[DIM-1]
 * prints one tab-separated line: gen ns/call, hand ns/call (medians), median of the round
 * ratios gen/hand, their min and max, the largest relative difference seen in the check.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void kernel_fn(const double *in, double *out, const double *p);
kernel_fn GEN_KERNEL, HAND_KERNEL;
static const double gen_params[] = GEN_PARAMS;

enum { kChecks = 1000, kMaxRounds = 101 };
static const double kAgreement = 1e-12;
/* Small enough that N Euler steps stay near the initial state's energy, so that every round
 * sees the same kind of arguments (sin and cos cost more on huge ones). */
static const double kStep = 1e-6;

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* A uniform double in [lo, hi) from a xorshift64 state, so the check is reproducible. */
static double uniform(unsigned long long *s, double lo, double hi) {
  *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
  return lo + (hi - lo) * (double)(*s >> 11) / 9007199254740992.0;
}

/* The largest |gen - hand| / max(1, |hand|) over kChecks random states: the time in
 * [0, 100), angles and velocities in [-3, 3). */
static double max_difference(void) {
  unsigned long long seed = 0x9e3779b97f4a7c15ULL;
  double worst = 0, in[DIM], g[DIM], h[DIM];
  for (int k = 0; k < kChecks; k++) {
    in[0] = uniform(&seed, 0, 100);
    for (int i = 1; i < DIM; i++)
      in[i] = uniform(&seed, -3, 3);
    GEN_KERNEL(in, g, gen_params);
    HAND_KERNEL(in, h, NULL);
    for (int i = 0; i < DIM; i++) {
      double d = fabs(g[i] - h[i]) / fmax(1.0, fabs(h[i]));
      if (!(d <= worst)) worst = d; /* a NaN wins */
    }
  }
  return worst;
}

/* Nanoseconds per call of f over n calls from y0; the final state goes to sink. */
static double time_calls(kernel_fn *f, const double *p, long n, const double *y0, double *sink) {
  double y[DIM], dy[DIM];
  memcpy(y, y0, sizeof y);
  double start = now();
  for (long k = 0; k < n; k++) {
    f(y, dy, p);
    for (int i = 0; i < DIM; i++)
      y[i] += kStep * dy[i];
  }
  double elapsed = now() - start;
  for (int i = 0; i < DIM; i++)
    *sink += y[i];
  return 1e9 * elapsed / (double)n;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, n, sizeof *v, by_value);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int main(int argc, char **argv) {
  if (argc != 3 + DIM) {
    fprintf(stderr, "usage: %s N ROUNDS y0[0] ... y0[%d]\n", argv[0], DIM - 1);
    return 2;
  }
  long n = atol(argv[1]);
  int rounds = atoi(argv[2]);
  if (n < 1 || rounds < 1 || rounds > kMaxRounds) {
    fprintf(stderr, "%s: N must be >= 1 and ROUNDS in [1, %d]\n", argv[0], kMaxRounds);
    return 2;
  }
  double y0[DIM];
  for (int i = 0; i < DIM; i++)
    y0[i] = atof(argv[3 + i]);

  double worst = max_difference();
  if (!(worst <= kAgreement)) {
    fprintf(stderr, "%s: the kernels disagree: relative difference %.3g > %.0e\n", argv[0], worst,
            kAgreement);
    return 1;
  }

  double sink = 0, gen[kMaxRounds], hand[kMaxRounds], ratio[kMaxRounds];
  time_calls(GEN_KERNEL, gen_params, n / 10 + 1, y0,
             &sink); /* warm-up: caches, branch predictors, clock */
  time_calls(HAND_KERNEL, NULL, n / 10 + 1, y0, &sink);
  for (int r = 0; r < rounds; r++) {
    if (r % 2 == 0) {
      gen[r] = time_calls(GEN_KERNEL, gen_params, n, y0, &sink);
      hand[r] = time_calls(HAND_KERNEL, NULL, n, y0, &sink);
    } else {
      hand[r] = time_calls(HAND_KERNEL, NULL, n, y0, &sink);
      gen[r] = time_calls(GEN_KERNEL, gen_params, n, y0, &sink);
    }
    ratio[r] = gen[r] / hand[r];
  }
  double lo = ratio[0], hi = ratio[0];
  for (int r = 1; r < rounds; r++)
    lo = fmin(lo, ratio[r]), hi = fmax(hi, ratio[r]);
  /* The sink makes the final states observable; it is finite for any sane run. */
  if (!isfinite(sink)) fprintf(stderr, "%s: the state blew up\n", argv[0]);
  printf("%.2f\t%.2f\t%.3f\t%.3f\t%.3f\t%.2g\n", median(gen, rounds), median(hand, rounds),
         median(ratio, rounds), lo, hi, worst);
  return 0;
}
