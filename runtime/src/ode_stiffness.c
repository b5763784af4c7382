/* The stiffness watch of the explicit ODE methods (see sicm_ode_watch_stiffness in ode_internal.h).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ode_internal.h"

/* ---- the stiffness watch of the explicit methods -----------------------
 *
 * An explicit method is stable on y' = lambda y only while h lambda stays in
 * a bounded region around 0. When the system has a fast mode that has died
 * out or was never excited (a stiff spring at rest, a fast reaction in
 * equilibrium), the error control must still keep h |lambda| near the edge
 * of that region, however smooth the solution and loose the tolerance: the
 * step is held by stability, the system is stiff, and an implicit method,
 * whose step follows the smooth solution, takes far fewer steps.
 *
 * Every kStiffCheckInterval accepted steps the watch estimates the dominant
 * eigenvalues of the Jacobian df/dy at the current point: a few steps of
 * power iteration with finite-difference products
 * J v ~ (f(t, y + d v) - f(t, y)) / d, then Rayleigh-Ritz on span{v, J v}
 * (two steps of Arnoldi), which finds a complex pair (a stiff oscillation,
 * lambda near the imaginary axis) as well as a real eigenvalue. The vector
 * is kept from one check to the next, so the iteration converges over the
 * checks while the point moves on. With the mean step h since the last
 * check, a check finds
 *
 *   (1) the step at the stability limit: for one of those eigenvalues,
 *       h |lambda| exceeds kStabilityFraction of the method's stability
 *       boundary in the direction of lambda;
 *   (2) the fast mode quiet: its amplitude, estimated from the curvature
 *       of the solution as |y''| / |lambda|^2, is within a few tolerances,
 *       or within a hundred while the solution turns much more slowly than
 *       lambda (see kNoiseAmplitude).
 *
 * (1) alone cannot tell stiffness from an oscillation the solution consists
 * of (a pendulum, an orbit near periapsis, a stiff spring set swinging): at
 * a loose tolerance their accuracy-limited step comes near the stability
 * boundary too, yet an implicit method would have to follow them with steps
 * just as short. (2) tells them apart, but only where the fast mode starts
 * out quiet: held at the limit of their imaginary-axis stability, rkck and
 * Bulirsch-Stoer pump a stiff oscillation up to hundreds of tolerances
 * within a few hundred steps, which then looks like a swing. So a streak
 * of checks begins where both hold and lasts while (1) holds; after
 * kStiffChecksToStop checks, and only if reaching t1 at the current step
 * would take more than kStiffStepsLeft further steps (a run that will
 * finish soon is left alone), the integration stops with SICM_ESTIFF and a
 * message that says why and names cvode-bdf.
 *
 * The steps left are counted to t1, or to the horizon the caller set
 * (sicm_ode_set_horizon), which a monitor loop that calls evolve over short
 * intervals sets to its end; the streak carries over between calls.
 *
 * Limits. A stiff oscillation that the
 * method pumps before the first check (rkck at tolerance 1e-5 on the spring
 * of the tests) goes unnoticed. A rhs call that fails at a probe point gives
 * no estimate, which ends the streak. */

/* A check every 100 steps costs kPowerSteps + 5 = 7 rhs calls, about 1% of
 * the work of the cheapest watched method (rkf45, 6 calls a step); with 8
 * checks in a row it stops a stiff run after about 800 steps, 6000 to 60000
 * rhs calls depending on the method. */
enum { kStiffCheckInterval = 100, kStiffChecksToStop = 8 };

/* Power-iteration steps per check before the Arnoldi step. The vector is
 * kept between checks, so a few suffice. */
enum { kPowerSteps = 2 };

/* A run that needs fewer further steps than this (seconds of work for small
 * systems) is never stopped, however stiff. */
static const double kStiffStepsLeft = 1e5;

/* Condition (1). Measured h |lambda| / boundary where the controller is held
 * by stability: 0.95 to 1.15 (rk8pd), 2.4 to 3.2 (rkf45, which tolerates
 * slow growth), 1.0 to 1.7 (rkck) and 0.77 to 0.89 (Bulirsch-Stoer) on the
 * stiff spring pendulum of the tests; 1.0 on Robertson's problem and on van
 * der Pol's with mu = 1000; 0.38 to 0.93 on y' = -1000 (y - cos t), where
 * the forcing also costs accuracy. Where accuracy holds the step: at most
 * 0.33 on that pendulum swinging with amplitude 4.5e-6 at tolerance 1e-10,
 * at most 0.31 on a harmonic oscillator at tolerance 1e-8, but up to 1.0 at
 * 1e-3, which is why (2) is needed. */
static const double kStabilityFraction = 0.4;

/* Condition (2). The fast mode's amplitude |y''| / |lambda|^2, in the
 * weights of the error test, is quiet up to kNoiseAmplitude tolerances (the
 * noise error control leaves, as on the slow arc of a relaxation
 * oscillation, where |y'| is that noise), or up to kResolvedAmplitude while
 * the solution turns more slowly than kQuietFraction |lambda|
 * (|y''| < kQuietFraction |lambda| |y'|). Measured at the first check of
 * each stiff run above: 0.03 to 10, and 50 to 65 where rkck and
 * Bulirsch-Stoer pump the spring or at tolerance 1e-8 on the forced problem,
 * always turning below 0.05 |lambda|. On that pendulum swinging at
 * tolerances 1e-5 and below: 190 and more, or 44 while turning faster than
 * 0.13 |lambda|; on harmonic oscillators and pendulums at tolerances 1e-3
 * and below: 240 and more, turning at about |lambda|; on Kepler orbits
 * (e = 0.9) at 1e-4 and below: 80 and more, turning faster than
 * 0.14 |lambda|. */
static const double kNoiseAmplitude = 10.0;
static const double kResolvedAmplitude = 100.0;
static const double kQuietFraction = 0.1;

/* An eigenvalue with Re lambda above this fraction of |lambda| is a growing
 * mode, which no step size makes stable: it says nothing about stiffness.
 * Finite differences leave a purely imaginary pair about 1e-7 off the axis. */
static const double kGrowingFraction = 0.01;

typedef struct {
  double re, im;
} eigenvalue;

/* The watch's scratch, 5 dim doubles, allocated on first use: the power
 * iteration's vector (kept between checks), f(t, y), a probe state, and two
 * work vectors. NULL if memory ran out. */
static double *stiffness_work(sicm_ode *o) {
  if (!o->stiffness_work) o->stiffness_work = malloc(5 * o->dim * sizeof *o->stiffness_work);
  return o->stiffness_work;
}

static double dot(size_t n, const double *a, const double *b) {
  double s = 0;
  for (size_t i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

/* out = (f(t, y + d v) - f0) / d, a directional derivative of f; yt is
 * scratch. Returns the status of the rhs call. */
static int jacobian_times(sicm_ode *o, double t, const double *y, const double *f0, double d,
                          const double *v, double *yt, double *out) {
  for (size_t i = 0; i < o->dim; i++)
    yt[i] = y[i] + d * v[i];
  int s = sicm_ode_call_rhs(o, t, yt, out);
  if (s != SICM_SUCCESS) return s;
  for (size_t i = 0; i < o->dim; i++)
    out[i] = (out[i] - f0[i]) / d;
  return sicm_ode_finite(o->dim, out) ? SICM_SUCCESS : SICM_EBADFUNC;
}

/* v = w / |w|; false if w is zero. */
static int normalize(size_t n, const double *w, double *v) {
  const double norm = sqrt(dot(n, w, w));
  if (!(norm > 0)) return 0;
  for (size_t i = 0; i < n; i++)
    v[i] = w[i] / norm;
  return 1;
}

/* The dominant eigenvalues of df/dy at (t, y), f0 = f(t, y): power
 * iteration from work's vector (left one step further on for the next
 * check), then Rayleigh-Ritz on span{v, J v}, whose 2x2 matrix H has
 * eigenvalues lam[0..*count-1]. d is the finite-difference increment.
 * kPowerSteps + 2 rhs calls. Returns SICM_SUCCESS or the failed call's
 * status; *count = 0 when J v vanishes (f does not depend on y there). */
static int dominant_eigenvalues(sicm_ode *o, double t, const double *y, const double *f0, double d,
                                double *work, eigenvalue lam[2], int *count) {
  const size_t n = o->dim;
  double *v = work, *yt = work + 2 * n, *w = work + 3 * n, *u = work + 4 * n;
  *count = 0;
  for (int k = 0; k < kPowerSteps; k++) {
    int s = jacobian_times(o, t, y, f0, d, v, yt, w);
    if (s != SICM_SUCCESS) return s;
    if (!normalize(n, w, v)) return SICM_SUCCESS;
  }
  int s = jacobian_times(o, t, y, f0, d, v, yt, w);
  if (s != SICM_SUCCESS) return s;
  const double h11 = dot(n, v, w);
  for (size_t i = 0; i < n; i++)
    w[i] -= h11 * v[i];
  const double h21 = sqrt(dot(n, w, w));
  if (!(h21 > 1e-12 * fabs(h11))) { /* v is an eigenvector */
    lam[0] = (eigenvalue){h11, 0};
    *count = h11 != 0;
    return SICM_SUCCESS;
  }
  for (size_t i = 0; i < n; i++)
    w[i] /= h21; /* the second Arnoldi vector */
  s = jacobian_times(o, t, y, f0, d, w, yt, u);
  if (s != SICM_SUCCESS) return s;
  const double h12 = dot(n, v, u), h22 = dot(n, w, u);
  for (size_t i = 0; i < n; i++)
    u[i] = h11 * v[i] + h21 * w[i]; /* J v: the next check starts there */
  normalize(n, u, v);
  const double half_trace = 0.5 * (h11 + h22), det = h11 * h22 - h12 * h21;
  const double disc = half_trace * half_trace - det;
  if (disc >= 0) {
    lam[0] = (eigenvalue){half_trace + sqrt(disc), 0};
    lam[1] = (eigenvalue){half_trace - sqrt(disc), 0};
  } else {
    lam[0] = (eigenvalue){half_trace, sqrt(-disc)};
    lam[1] = (eigenvalue){half_trace, -sqrt(-disc)};
  }
  *count = 2;
  return SICM_SUCCESS;
}

/* y'' at (t, y) along the solution into y2: (f(t + e, y + e f0) - f0) / e,
 * with f0 = f(t, y) and e the time in which y moves by d; zero if y does not
 * move. One rhs call; yt is scratch. Returns the status of that call. */
static int second_derivative(sicm_ode *o, double t, const double *y, const double *f0, double d,
                             double *yt, double *y2) {
  const size_t n = o->dim;
  double speed = 0;
  for (size_t i = 0; i < n; i++)
    speed = fmax(speed, fabs(f0[i]));
  if (speed == 0) {
    memset(y2, 0, n * sizeof *y2);
    return SICM_SUCCESS;
  }
  const double e = (t + d / speed) - t; /* representable in t */
  if (e == 0) return SICM_EBADFUNC;
  for (size_t i = 0; i < n; i++)
    yt[i] = y[i] + e * f0[i];
  int s = sicm_ode_call_rhs(o, t + e, yt, y2);
  if (s != SICM_SUCCESS) return s;
  for (size_t i = 0; i < n; i++)
    y2[i] = (y2[i] - f0[i]) / e;
  return sicm_ode_finite(n, y2) ? SICM_SUCCESS : SICM_EBADFUNC;
}

/* The method's stability boundary |h lambda| in the direction of lambda,
 * interpolated linearly in the angle between the negative real axis and the
 * imaginary axis; 0 for a growing mode. Measured, the GSL steppers'
 * boundaries stay within 15% of their real-axis value up to 80 degrees
 * from that axis and fall to the imaginary-axis value only in the last 10,
 * so the interpolation underestimates them in between: it errs towards
 * calling a step held, which condition (2) and the streak guard. */
static double stability_boundary(sicm_ode_stability s, eigenvalue lam) {
  const double modulus = hypot(lam.re, lam.im);
  if (lam.re > kGrowingFraction * modulus) return 0;
  const double right_angle = atan2(1.0, 0.0);
  const double angle = fmin(atan2(fabs(lam.im), -lam.re), right_angle); /* 0: negative axis */
  return s.real + (s.imaginary - s.real) * angle / right_angle;
}

/* What one check of the watch measured, in the weights of the error test:
 * the eigenvalue lambda of the system's Jacobian nearest the method's
 * stability boundary, as the ratio h |lambda| / boundary, and its rate
 * |lambda|; the speed |y'| of the solution; and its curvature, the larger
 * of |y''| and |y'''| / |lambda| (a fast oscillation passes through zero in
 * one of them when at its peak in the other). */
typedef struct {
  double ratio, rate, speed, curvature;
} stiffness_sample;

/* The rhs calls of one check at (t, y): f0 = f(t, y), the dominant
 * eigenvalues, y'' (into y2) and J y'' ~ y''' (into y3). They do not
 * disturb what the driver remembers of the last failed rhs call. Returns
 * SICM_SUCCESS or the status of a failed call. */
static int probe_system(sicm_ode *o, double t, const double *y, double *work, eigenvalue lam[2],
                        int *count) {
  const size_t n = o->dim;
  double *f0 = work + n, *yt = work + 2 * n, *y2 = work + 3 * n, *y3 = work + 4 * n;
  const long bad_component = o->bad_component;
  const double bad_value = o->bad_value;
  const int user_status = o->user_status;
  double ymax = 0;
  for (size_t i = 0; i < n; i++)
    ymax = fmax(ymax, fabs(y[i]));
  const double floor = o->rel_tol > 0 ? o->abs_tol / o->rel_tol : 1.0;
  const double d = sqrt(DBL_EPSILON) * fmax(ymax, floor);
  int s = sicm_ode_call_rhs(o, t, y, f0);
  if (s == SICM_SUCCESS) s = dominant_eigenvalues(o, t, y, f0, d, work, lam, count);
  if (s == SICM_SUCCESS) s = second_derivative(o, t, y, f0, d, yt, y2);
  memset(y3, 0, n * sizeof *y3);
  const double y2_norm = s == SICM_SUCCESS ? sqrt(dot(n, y2, y2)) : 0;
  if (y2_norm > 0) {
    for (size_t i = 0; i < n; i++)
      y2[i] /= y2_norm;
    s = jacobian_times(o, t, y, f0, d, y2, yt, y3);
    for (size_t i = 0; i < n; i++) {
      y2[i] *= y2_norm;
      y3[i] *= y2_norm;
    }
  }
  o->bad_component = bad_component;
  o->bad_value = bad_value;
  o->user_status = user_status;
  return s;
}

/* Measure a stiffness_sample at (t, y) after steps of mean size h (see the
 * essay above). Returns false when there is no estimate: out of memory, or
 * an rhs call failed at a probe point. */
static int sample_stiffness(sicm_ode *o, double t, const double *y, double h,
                            sicm_ode_stability stability, stiffness_sample *out) {
  double *work = stiffness_work(o);
  if (!work) return 0;
  const size_t n = o->dim;
  if (!o->have_vector) { /* a start with no special direction */
    for (size_t i = 0; i < n; i++)
      work[i] = sin((double)i + 1.0);
    normalize(n, work, work);
  }
  eigenvalue lam[2];
  int count = 0;
  o->have_vector = probe_system(o, t, y, work, lam, &count) == SICM_SUCCESS;
  if (!o->have_vector) return 0;
  *out = (stiffness_sample){0, 0, 0, 0};
  for (int k = 0; k < count; k++) {
    const double modulus = hypot(lam[k].re, lam[k].im);
    const double boundary = stability_boundary(stability, lam[k]);
    if (boundary > 0 && h * modulus / boundary > out->ratio) {
      out->ratio = h * modulus / boundary;
      out->rate = modulus;
    }
  }
  if (out->rate == 0) return 1; /* no eigenvalue the method must keep stable */
  out->speed = sicm_ode_rms_scaled(o, work + n, y);
  out->curvature = fmax(sicm_ode_rms_scaled(o, work + 3 * n, y),
                        sicm_ode_rms_scaled(o, work + 4 * n, y) / out->rate);
  return 1;
}

/* Condition (2) of the essay above, on a sample that passed (1). */
static int fast_mode_quiet(const stiffness_sample *x) {
  const double amplitude = x->curvature / (x->rate * x->rate);
  return amplitude <= kNoiseAmplitude ||
         (amplitude <= kResolvedAmplitude && x->curvature < kQuietFraction * x->rate * x->speed);
}

/* x to two significant digits, as the messages write rough numbers: 2.1e-3. */
enum { kRoughSize = 48 };
static void format_rough(char buf[kRoughSize], double x) {
  char raw[16];
  snprintf(raw, sizeof raw, "%.1e", x);
  char *e = strchr(raw, 'e');
  if (!e) {
    snprintf(buf, kRoughSize, "%s", raw);
    return;
  }
  *e = '\0';
  snprintf(buf, kRoughSize, "%se%d", raw, atoi(e + 1));
}

static int fail_stiff(sicm_ode *o, double t, const double *y, double h, double rate, double t1,
                      double steps_left) {
  char hbuf[kRoughSize], rbuf[kRoughSize], nbuf[kRoughSize], tbuf[SICM_DOUBLE_BUFSIZE];
  char detail[512];
  format_rough(hbuf, h);
  format_rough(rbuf, rate);
  format_rough(nbuf, steps_left);
  sicm_format_double(tbuf, t1);
  snprintf(detail, sizeof detail,
           "the step size is held near h = %s by the stability of the method, not by the "
           "tolerance (fastest rate of the system about %s, h times rate about %.2g); reaching "
           "t = %s would take about %s more steps; use 'cvode-bdf, an implicit method made "
           "for stiff systems",
           hbuf, rbuf, h * rate, tbuf, nbuf);
  return sicm_ode_fail(o, SICM_ESTIFF, t, y, "stiff system", detail);
}

int sicm_ode_watch_stiffness(sicm_ode *o, double t, const double *y, double h, double t1,
                             sicm_ode_stability stability) {
  o->span_since_check += fabs(h);
  if (++o->steps_since_check < kStiffCheckInterval) return SICM_SUCCESS;
  /* The mean step: a controller at the stability limit alternates long
   * steps with short ones. */
  h = o->span_since_check / (double)o->steps_since_check;
  o->steps_since_check = 0;
  o->span_since_check = 0;
  stiffness_sample x = {0};
  if (!sample_stiffness(o, t, y, h, stability, &x) || !(x.ratio > kStabilityFraction))
    o->stiff_streak = 0;
  else if (o->stiff_streak > 0 || fast_mode_quiet(&x)) /* a streak begins where it is quiet */
    o->stiff_streak++;
  /* The horizon, when the caller will go on past t1 in the same direction. */
  if (o->horizon_set && (o->horizon - t1) * (t1 - t) > 0) t1 = o->horizon;
  const double steps_left = fabs(t1 - t) / h;
  if (o->stiff_streak < kStiffChecksToStop || !(steps_left > kStiffStepsLeft)) return SICM_SUCCESS;
  return fail_stiff(o, t, y, h, x.rate, t1, steps_left);
}
