/* Times the state derivative of a sicm-built program against the hand-written one, per call.
 *
 * bench/kernel_vs_hand.c's method, for bench/scale's generated systems. Built and run by
 * bench/scale, once per system and size, with
 *   -DLEAVES=n            the number of state leaves (the time first)
 *   -DGEN_KERNEL=name     an external wrapper bench/scale appends to the C `sicm build --keep-c`
 *                         kept, calling the kernel the program hands to state-advancer
 *   -DHAND_KERNEL=name    hand_kernel of hand_chain.c or hand_nbody.c (-DHAND_KERNEL_ONLY)
 * Each is its own translation unit, compiled with the same flags as this file, so neither is
 * inlined here and both are called through the kernel ABI
 * void f(const double *in, double *out, const double *p).
 *
 * First the two are compared at random states near the initial state, where the integration
 * goes: the time in [0, 100), every other leaf y0[i] + [-SPREAD, SPREAD). The largest difference
 * relative to max(1, |value|) is reported; above 1e-6 the two compute different things (a layout
 * that does not match, a wrong kernel) and nothing is timed. Then each is called n times in a
 * row from y0, the derivative fed back by an Euler step of 1e-6 so no call can be hoisted, n
 * chosen so that one series takes about MS milliseconds, in ROUNDS rounds alternating which
 * goes first.
 *
 * usage: rhs_harness MS ROUNDS SPREAD y0[0] ... y0[LEAVES-1]
 * prints one tab-separated line: gen ns/call, hand ns/call (medians), the median of the round
 * ratios gen/hand, their min and max, the largest relative difference in the check, n.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void kernel_fn(const double *in, double *out, const double *p);
kernel_fn GEN_KERNEL, HAND_KERNEL;

enum { kChecks = 200, kMaxRounds = 101 };
static const double kAgreement = 1e-6;
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

/* The largest |gen - hand| / max(1, |hand|) over kChecks states near y0. */
static double max_difference(const double *y0, double spread) {
  unsigned long long seed = 0x9e3779b97f4a7c15ULL;
  double worst = 0, in[LEAVES], g[LEAVES], h[LEAVES];
  for (int k = 0; k < kChecks; k++) {
    in[0] = uniform(&seed, 0, 100);
    for (int i = 1; i < LEAVES; i++)
      in[i] = y0[i] + uniform(&seed, -spread, spread);
    GEN_KERNEL(in, g, NULL);
    HAND_KERNEL(in, h, NULL);
    for (int i = 0; i < LEAVES; i++) {
      double d = fabs(g[i] - h[i]) / fmax(1.0, fabs(h[i]));
      if (!(d <= worst)) worst = d; /* a NaN wins */
    }
  }
  return worst;
}

/* Nanoseconds per call of f over n calls from y0; the final state goes to sink. */
static double time_calls(kernel_fn *f, long n, const double *y0, double *sink) {
  double y[LEAVES], dy[LEAVES];
  memcpy(y, y0, sizeof y);
  double start = now();
  for (long k = 0; k < n; k++) {
    f(y, dy, NULL);
    for (int i = 0; i < LEAVES; i++)
      y[i] += kStep * dy[i];
  }
  double elapsed = now() - start;
  for (int i = 0; i < LEAVES; i++)
    *sink += y[i];
  return 1e9 * elapsed / (double)n;
}

/* Calls per series for about ms milliseconds of the slower kernel, after warming both up. */
static long calls_for(double ms, const double *y0, double *sink) {
  double slower = 0;
  kernel_fn *fs[] = {GEN_KERNEL, HAND_KERNEL};
  for (int i = 0; i < 2; i++) {
    long n = 1;
    double ns;
    while ((ns = time_calls(fs[i], n, y0, sink)) * (double)n < 5e6 && n < (1L << 40))
      n *= 2;
    slower = fmax(slower, ns);
  }
  long n = (long)(ms * 1e6 / slower);
  return n < 1 ? 1 : n;
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
  if (argc != 4 + LEAVES) {
    fprintf(stderr, "usage: %s MS ROUNDS SPREAD y0[0] ... y0[%d]\n", argv[0], LEAVES - 1);
    return 2;
  }
  double ms = atof(argv[1]), spread = atof(argv[3]);
  int rounds = atoi(argv[2]);
  if (!(ms > 0) || rounds < 1 || rounds > kMaxRounds) {
    fprintf(stderr, "%s: MS must be > 0 and ROUNDS in [1, %d]\n", argv[0], kMaxRounds);
    return 2;
  }
  double y0[LEAVES];
  for (int i = 0; i < LEAVES; i++)
    y0[i] = atof(argv[4 + i]);

  double worst = max_difference(y0, spread);
  if (!(worst <= kAgreement)) {
    fprintf(stderr, "the derivatives disagree: relative difference %.3g > %.0e\n", worst,
            kAgreement);
    return 1;
  }

  double sink = 0, gen[kMaxRounds], hand[kMaxRounds], ratio[kMaxRounds];
  long n = calls_for(ms, y0, &sink);
  for (int r = 0; r < rounds; r++) {
    if (r % 2 == 0) {
      gen[r] = time_calls(GEN_KERNEL, n, y0, &sink);
      hand[r] = time_calls(HAND_KERNEL, n, y0, &sink);
    } else {
      hand[r] = time_calls(HAND_KERNEL, n, y0, &sink);
      gen[r] = time_calls(GEN_KERNEL, n, y0, &sink);
    }
    ratio[r] = gen[r] / hand[r];
  }
  double lo = ratio[0], hi = ratio[0];
  for (int r = 1; r < rounds; r++)
    lo = fmin(lo, ratio[r]), hi = fmax(hi, ratio[r]);
  if (!isfinite(sink)) fprintf(stderr, "%s: the state blew up\n", argv[0]);
  printf("%.2f\t%.2f\t%.3f\t%.3f\t%.3f\t%.2g\t%ld\n", median(gen, rounds), median(hand, rounds),
         median(ratio, rounds), lo, hi, worst, n);
  return 0;
}
