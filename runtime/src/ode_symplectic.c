/* Symplectic fixed-step integrators for separable Hamiltonians: Verlet and Yoshida compositions.
 *
 * Every method is a symmetric composition S(w_1 h) S(w_2 h) ... S(w_s h) of
 * the kick-drift-kick leapfrog S(h): p -= h/2 V_q; q += h T_p; p -= h/2 V_q.
 * Consecutive half kicks at the same (t, q) are merged, so a step of an
 * s-stage method costs s force evaluations (plus one at the very start of a
 * call). Since each stage is the exact flow of T or of V, the composition is
 * symplectic; being symmetric, its order is even.
 *
 * The weights: Yoshida, "Construction of higher order symplectic
 * integrators", Phys. Lett. A 150 (1990) 262. Order 4 is the triple jump
 * w1 = 1/(2 - 2^(1/3)), w0 = 1 - 2 w1, computed here from the closed form.
 * Orders 6 and 8 use his "solution A" weights w_1..w_m, printed with 15
 * significant digits, and w_0 = 1 - 2 (w_1 + ... + w_m) so that the weights
 * sum to 1 exactly; the sequence is w_m ... w_1 w_0 w_1 ... w_m. The printed
 * digits satisfy the order conditions to about 1e-15, which shows only far
 * below any useful step size. The orders are verified by a convergence test
 * (tests/unit/ode_test.cpp), not taken on trust. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ode_internal.h"
#include "sicm/runtime.h"

enum { kMaxStages = 15, kMaxStateShown = 8 };

struct sicm_symplectic_type {
  const char *name;
  int order;
  int stages;
  int half;            /* orders 6, 8: number of published weights w_1..w_half */
  double published[7]; /* w_1..w_half; w_0 is derived */
};

/* The full symmetric weight sequence of T, into w[0..T->stages-1]. */
static void weights(const sicm_symplectic_type *T, double *w) {
  if (T->stages == 1) {
    w[0] = 1.0;
    return;
  }
  if (T->order == 4) {
    const double c = cbrt(2.0), w1 = 1.0 / (2.0 - c);
    w[0] = w[2] = w1;
    w[1] = 1.0 - 2.0 * w1; /* = -c / (2 - c) */
    return;
  }
  const int m = T->half;
  double sum = 0;
  for (int i = 0; i < m; i++)
    sum += T->published[i];
  /* published[i] is w_{i+1}; the sequence is w_m .. w_1 w_0 w_1 .. w_m */
  w[m] = 1.0 - 2.0 * sum;
  for (int i = 0; i < m; i++)
    w[m - 1 - i] = w[m + 1 + i] = T->published[i];
}

static const sicm_symplectic_type verlet = {"verlet", 2, 1, 0, {0}};
static const sicm_symplectic_type yoshida4 = {"yoshida4", 4, 3, 0, {0}};
static const sicm_symplectic_type yoshida6 = {
    "yoshida6", 6, 7, 3, {-1.17767998417887, 0.235573213359357, 0.784513610477560}};
static const sicm_symplectic_type yoshida8 = {
    "yoshida8",
    8,
    15,
    7,
    {-1.61582374150097, -2.44699182370524, -0.716989419708120e-2, 2.44002732616735,
     0.157739928123617, 1.82020630970714, 1.04242620869991}};

const sicm_symplectic_type *const sicm_symplectic_verlet = &verlet;
const sicm_symplectic_type *const sicm_symplectic_yoshida4 = &yoshida4;
const sicm_symplectic_type *const sicm_symplectic_yoshida6 = &yoshida6;
const sicm_symplectic_type *const sicm_symplectic_yoshida8 = &yoshida8;

const char *sicm_symplectic_name(const sicm_symplectic_type *T) {
  return T->name;
}
int sicm_symplectic_order(const sicm_symplectic_type *T) {
  return T->order;
}

static int all_finite(size_t n, const double *v) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

static void append_vector(char *buf, size_t size, size_t n, const double *v) {
  char num[SICM_DOUBLE_BUFSIZE];
  size_t len = strlen(buf);
  for (size_t i = 0; i < n && i < kMaxStateShown && len + 1 < size; i++) {
    sicm_format_double(num, v[i]);
    snprintf(buf + len, size - len, "%s%s", i == 0 ? "[" : ", ", num);
    len = strlen(buf);
  }
  if (n > kMaxStateShown && len + 1 < size) snprintf(buf + len, size - len, ", ...");
  len = strlen(buf);
  if (len + 1 < size) snprintf(buf + len, size - len, "]");
}

/* Report "NAME: WHAT at t = T with state q = [..], p = [..]: DETAIL". */
static int fail(const sicm_symplectic_type *T, int status, size_t ndof, double t, const double *q,
                const double *p, const char *what, const char *detail) {
  char msg[768], tb[SICM_DOUBLE_BUFSIZE];
  sicm_format_double(tb, t);
  snprintf(msg, sizeof msg, "%s: %s at t = %s with state q = ", T->name, what, tb);
  append_vector(msg, sizeof msg, ndof, q);
  size_t len = strlen(msg);
  snprintf(msg + len, sizeof msg - len, ", p = ");
  append_vector(msg, sizeof msg, ndof, p);
  len = strlen(msg);
  snprintf(msg + len, sizeof msg - len, ": %s", detail);
  return sicm_error(status, "%s", msg);
}

/* x += dx by compensated summation (Hairer, Lubich & Wanner, Geometric
 * Numerical Integration, VIII.5): *err holds what rounding has so far left
 * out of x and goes in with the next increment, so that the roundings of
 * millions of small increments to a large x do not random-walk (over 6e7
 * yoshida4 steps of a Kepler orbit they moved the angular momentum, which
 * the methods conserve exactly, by 1.6e-12; compensated, by 2e-16). A
 * Kepler step costs 10 to 15% more. x stays the rounded value of the sum. */
static void add_compensated(double *x, double *err, double dx) {
  const double before = *x;
  *err += dx;
  *x = before + *err;
  *err += before - *x;
}

/* Scratch of a run of steps: the callbacks' results, and the compensations
 * of q and p (add_compensated), carried from step to step. */
typedef struct {
  double *force, *velocity;
  double *q_err, *p_err;
} step_scratch;

/* One composed step of size dt from time t: q, p advance in place. On entry
 * *pending is the coefficient (times dt) of a kick still owed at (t, q); on
 * exit it is the coefficient owed at the end of the step. The first force
 * evaluation also yields the proper state at t (the owed kick alone
 * applied), which is stored in proper_p (q itself is proper) for error
 * recovery; *have_proper says whether that happened. */
static int step(const double *w, int stages, size_t ndof, sicm_force dVdq, sicm_velocity dTdp,
                void *params, double t, double dt, double *q, double *p, const step_scratch *sc,
                double *pending, double *proper_p, int *have_proper) {
  double tau = t;
  *have_proper = 0;
  for (int s = 0; s < stages; s++) {
    const double kick = (*pending + 0.5 * w[s]) * dt, drift = w[s] * dt;
    if (dVdq(tau, q, sc->force, params)) return SICM_EUSER;
    if (s == 0) {
      for (size_t i = 0; i < ndof; i++)
        proper_p[i] = p[i] - *pending * dt * sc->force[i];
      *have_proper = 1;
    }
    for (size_t i = 0; i < ndof; i++)
      add_compensated(&p[i], &sc->p_err[i], -kick * sc->force[i]);
    if (dTdp(p, sc->velocity, params)) return SICM_EUSER;
    for (size_t i = 0; i < ndof; i++)
      add_compensated(&q[i], &sc->q_err[i], drift * sc->velocity[i]);
    tau += drift;
    *pending = 0.5 * w[s];
  }
  return SICM_SUCCESS;
}

/* How a run of steps ended, for the caller to report in its own terms. */
typedef struct {
  const char *what, *detail; /* set when the run failed */
  unsigned long long steps;  /* steps completed */
} run_outcome;

/* Advance (q, p) from *t to t1 in equal steps of at most |h|, as
 * sicm_symplectic_evolve documents, without reporting a failure: on one, q,
 * p and *t are the last proper state and out says what went wrong. The
 * arguments have been checked. carry (2 ndof doubles: q's compensation,
 * then p's), if not NULL, holds the compensations from the caller's last
 * run, which ended at this (q, p), and gets them at the end of this one: a
 * monitor loop's many short runs are then summed as one long run (else each
 * run's last rounding is kept, 6e6 times over 10^4 Kepler orbits watched
 * every 1/100). */
static int run_steps(const sicm_symplectic_type *T, size_t ndof, sicm_force dVdq,
                     sicm_velocity dTdp, void *params, double *t, double t1, double h, double *q,
                     double *p, double *carry, run_outcome *out);

int sicm_symplectic_evolve(const sicm_symplectic_type *T, size_t ndof, sicm_force dVdq,
                           sicm_velocity dTdp, void *params, double *t, double t1, double h,
                           double *q, double *p) {
  if (!T || !dVdq || !dTdp || ndof == 0)
    return sicm_error(SICM_EINVAL, "sicm_symplectic_evolve: missing method, callback or "
                                   "degrees of freedom");
  if (!isfinite(h) || h == 0 || !isfinite(*t) || !isfinite(t1))
    return sicm_error(SICM_EINVAL,
                      "sicm_symplectic_evolve (%s): step %g and times %g, %g must be finite "
                      "and the step non-zero",
                      T->name, h, *t, t1);
  if (!all_finite(ndof, q) || !all_finite(ndof, p))
    return fail(T, SICM_EINVAL, ndof, *t, q, p, "non-finite state",
                "the initial state has NaN or infinite components");
  if (*t == t1) return SICM_SUCCESS;
  run_outcome out = {0};
  int status = run_steps(T, ndof, dVdq, dTdp, params, t, t1, h, q, p, NULL, &out);
  if (status == SICM_ENOMEM)
    return sicm_error(status, "sicm_symplectic_evolve (%s): %s", T->name, out.detail);
  if (status != SICM_SUCCESS) return fail(T, status, ndof, *t, q, p, out.what, out.detail);
  return SICM_SUCCESS;
}

static int run_steps(const sicm_symplectic_type *T, size_t ndof, sicm_force dVdq,
                     sicm_velocity dTdp, void *params, double *t, double t1, double h, double *q,
                     double *p, double *carry, run_outcome *out) {
  const double t0 = *t, span = t1 - t0;
  /* The smallest step count with |dt| <= |h|, forgiving rounding in span/h
   * so that h dividing the interval gives exactly span/h steps. */
  double ratio = fabs(span / h), whole = round(ratio);
  double count = fabs(ratio - whole) <= 1e-9 * ratio ? whole : ceil(ratio);
  if (count < 1) count = 1;
  if (count > 1e15) {
    out->what = "too many steps";
    out->detail = "the interval needs more than 1e15 steps of the given size";
    return SICM_EINVAL;
  }
  const unsigned long long nsteps = (unsigned long long)count;
  const double dt = span / count;

  double w[kMaxStages];
  weights(T, w);
  /* sc: scratch for the callbacks and the compensations, which start at 0.
   * good_q, good_p, good_t: the last proper state known, which the caller
   * gets back if a step fails. start_q: q at the start of the current step. */
  double *scratch = calloc(7 * ndof, sizeof *scratch);
  if (!scratch) {
    out->what = out->detail = "out of memory";
    return SICM_ENOMEM;
  }
  double *q_err = carry ? carry : scratch + 2 * ndof, *p_err = q_err + ndof;
  const step_scratch sc = {scratch, scratch + ndof, q_err, p_err};
  double *good_q = scratch + 4 * ndof, *good_p = good_q + ndof, *start_q = good_p + ndof;
  memcpy(good_q, q, ndof * sizeof *q);
  memcpy(good_p, p, ndof * sizeof *p);
  double good_t = t0, pending = 0;
  int status = SICM_SUCCESS;
  for (unsigned long long i = 0; i < nsteps && status == SICM_SUCCESS; i++) {
    const double tstart = t0 + (double)i * dt;
    int have_proper = 0;
    memcpy(start_q, q, ndof * sizeof *q);
    status = step(w, T->stages, ndof, dVdq, dTdp, params, tstart, dt, q, p, &sc, &pending, good_p,
                  &have_proper);
    if (have_proper) { /* good_p was just set to the proper momentum at tstart */
      memcpy(good_q, start_q, ndof * sizeof *q);
      good_t = tstart;
    }
    if (status == SICM_SUCCESS && !(all_finite(ndof, q) && all_finite(ndof, p)))
      status = SICM_EBADFUNC;
    if (status == SICM_SUCCESS) out->steps++;
  }
  if (status == SICM_SUCCESS) { /* pay the last half kick at t1 */
    if (dVdq(t1, q, sc.force, params) == 0) {
      for (size_t k = 0; k < ndof; k++)
        add_compensated(&p[k], &sc.p_err[k], -pending * dt * sc.force[k]);
      *t = t1;
    } else {
      status = SICM_EUSER;
    }
  }
  if (status != SICM_SUCCESS) {
    memcpy(q, good_q, ndof * sizeof *q);
    memcpy(p, good_p, ndof * sizeof *p);
    *t = good_t;
    memset(q_err, 0, 2 * ndof * sizeof *q_err); /* they belonged to the lost steps */
    if (status == SICM_EUSER) {
      out->what = "stopped by the system";
      out->detail = "a force or velocity function returned non-zero";
    } else {
      out->what = "non-finite state";
      out->detail = "a step produced NaN or infinity (is the step too long for the force?)";
    }
  }
  free(scratch);
  return status;
}

/* ---- the same methods as sicm_ode step types ------------------------------
 * So that evolve and state-advancer can use them like any integrator, each
 * method is also a sicm_ode_step_type working on the book's states
 * y = (t, q_1..q_n, p_1..p_n) through the ordinary right-hand side: the
 * velocity dT/dp is the q part of f(t, y) and the force -dV/dq its p part.
 * That is right only for a separable system, where the q part of f does not
 * depend on t or q and the p part not on p; the first evolve checks this at
 * the starting point (bitwise: a separable system computes the same numbers
 * whatever the other half holds) and refuses a system that fails it. A
 * Lagrangian state (t, q, qdot) with a constant mass matrix passes too; for
 * it the map is symplectic in (q, M qdot). The step size is the abs_tol
 * given to sicm_ode_alloc. */

typedef struct {
  const sicm_symplectic_type *method;
  sicm_ode *o;
  double *work; /* the state the right-hand side is called at */
  double *dydt;
  size_t ndof;
  int call_status; /* what the last right-hand side call returned */
  int checked;     /* separability verified */
  double *carry;   /* run_steps' compensations, kept while the caller goes on */
} fixed_step;

static fixed_step *fixed_of(sicm_ode *o) {
  return (fixed_step *)o->backend;
}

static int fixed_init(sicm_ode *o) {
  fixed_step *b = calloc(1, sizeof *b);
  if (!b) return SICM_ENOMEM;
  b->method = (const sicm_symplectic_type *)o->type->data;
  b->o = o;
  b->work = malloc(2 * o->dim * sizeof *b->work);
  b->carry = calloc(o->dim, sizeof *b->carry); /* 2 ndof + 1 */
  if (!b->work || !b->carry) {
    free(b->work);
    free(b->carry);
    free(b);
    return SICM_ENOMEM;
  }
  b->dydt = b->work + o->dim;
  b->ndof = (o->dim - 1) / 2;
  o->backend = b;
  return SICM_SUCCESS;
}

/* The caller moved the state: the compensations belong to the old one. */
static void fixed_reset(sicm_ode *o) {
  fixed_step *b = fixed_of(o);
  memset(b->carry, 0, o->dim * sizeof *b->carry);
}

static void fixed_free(sicm_ode *o) {
  fixed_step *b = fixed_of(o);
  free(b->work);
  free(b->carry);
  free(b);
  o->backend = NULL;
}

/* -dV/dq at (t, q) is the p part of f; work keeps the last p, which a
 * separable system does not read. */
static int fixed_force(double t, const double *q, double *dVdq, void *params) {
  fixed_step *b = params;
  b->work[0] = t;
  memcpy(b->work + 1, q, b->ndof * sizeof *q);
  b->call_status = sicm_ode_call_rhs(b->o, t, b->work, b->dydt);
  if (b->call_status != SICM_SUCCESS) return 1;
  for (size_t i = 0; i < b->ndof; i++)
    dVdq[i] = -b->dydt[1 + b->ndof + i];
  return 0;
}

/* dT/dp at p is the q part of f, whatever t and q work holds. */
static int fixed_velocity(const double *p, double *dTdp, void *params) {
  fixed_step *b = params;
  memcpy(b->work + 1 + b->ndof, p, b->ndof * sizeof *p);
  b->call_status = sicm_ode_call_rhs(b->o, b->work[0], b->work, b->dydt);
  if (b->call_status != SICM_SUCCESS) return 1;
  memcpy(dTdp, b->dydt + 1, b->ndof * sizeof *dTdp);
  return 0;
}

/* A point near y whose half [from, from + n) is moved by about a tenth of
 * its size (and the time too when move_time). */
static void displaced(const double *y, size_t dim, size_t from, size_t n, int move_time,
                      double *out) {
  memcpy(out, y, dim * sizeof *y);
  if (move_time) out[0] += 0.1 * (1.0 + fabs(y[0]));
  for (size_t i = from; i < from + n; i++)
    out[i] += 0.1 * (1.0 + fabs(y[i]));
}

/* Is the system separable at (t, y)? Returns SICM_SUCCESS or a failure
 * already reported. */
static int check_separable(sicm_ode *o, double t, const double *y) {
  fixed_step *b = fixed_of(o);
  const size_t n = b->ndof, dim = o->dim;
  double *f0 = malloc(2 * dim * sizeof *f0);
  if (!f0) return sicm_ode_fail(o, SICM_ENOMEM, t, y, "out of memory", NULL);
  double *moved = f0 + dim;
  const char *why = NULL;
  int s = sicm_ode_call_rhs(o, t, y, f0);
  if (s == SICM_SUCCESS && f0[0] != 1.0)
    why = "the state's first component must be the time, whose rate is 1";
  if (s == SICM_SUCCESS && !why) { /* dq/dt must not depend on t or q */
    displaced(y, dim, 1, n, 1, moved);
    s = sicm_ode_call_rhs(o, moved[0], moved, b->dydt);
    if (s == SICM_SUCCESS && memcmp(f0 + 1, b->dydt + 1, n * sizeof *f0) != 0)
      why = "dq/dt changes with q or t, so the Hamiltonian is not T(p) + V(t, q)";
  }
  if (s == SICM_SUCCESS && !why) { /* dp/dt must not depend on p */
    displaced(y, dim, 1 + n, n, 0, moved);
    s = sicm_ode_call_rhs(o, t, moved, b->dydt);
    if (s == SICM_SUCCESS && memcmp(f0 + 1 + n, b->dydt + 1 + n, n * sizeof *f0) != 0)
      why = "dp/dt changes with p, so the Hamiltonian is not T(p) + V(t, q)";
  }
  free(f0);
  if (s == SICM_EUSER) return sicm_ode_fail_user(o, t, y);
  if (s != SICM_SUCCESS)
    return sicm_ode_fail(o, s, t, y, "non-finite derivative",
                         "the system derivative is NaN or infinite at the starting point");
  if (why) return sicm_ode_fail(o, SICM_EINVAL, t, y, "the system is not separable", why);
  return SICM_SUCCESS;
}

static int fixed_evolve(sicm_ode *o, double *t, double t1, double *y) {
  fixed_step *b = fixed_of(o);
  if (o->dim < 3 || o->dim % 2 == 0)
    return sicm_ode_fail(o, SICM_EINVAL, *t, y, "unsuitable state",
                         "a symplectic method needs a state (t, q, p) with as many momenta "
                         "or velocities as coordinates");
  if (!b->checked) {
    int s = check_separable(o, *t, y);
    if (s != SICM_SUCCESS) return s;
    b->checked = 1;
  }
  const double h = o->abs_tol;
  const double steps = ceil(fabs(t1 - *t) / h);
  if (steps > (double)o->max_steps) {
    char detail[200];
    snprintf(detail, sizeof detail,
             "%.0f steps of %g are needed and the limit is %lu (for %s the tolerance argument "
             "is the step size)",
             steps, h, o->max_steps, b->method->name);
    return sicm_ode_fail(o, SICM_EMAXITER, *t, y, "too many steps", detail);
  }
  memcpy(b->work, y, o->dim * sizeof *y);
  b->work[0] = *t;
  run_outcome out = {0};
  double *q = y + 1, *p = y + 1 + b->ndof;
  int s =
      run_steps(b->method, b->ndof, fixed_force, fixed_velocity, b, t, t1, h, q, p, b->carry, &out);
  o->stats.steps += (unsigned long)out.steps;
  y[0] = *t;
  if (s == SICM_SUCCESS) return SICM_SUCCESS;
  if (s == SICM_EUSER && b->call_status == SICM_EUSER) return sicm_ode_fail_user(o, *t, y);
  if (s == SICM_EUSER) /* the right-hand side was NaN or infinite */
    return sicm_ode_fail(o, SICM_EBADFUNC, *t, y, "non-finite derivative",
                         "the system derivative became NaN or infinite (is the step too long?)");
  return sicm_ode_fail(o, s, *t, y, out.what, out.detail);
}

static const sicm_ode_step_type verlet_type = {"verlet",   fixed_init, fixed_evolve, fixed_reset,
                                               fixed_free, &verlet,    NULL};
static const sicm_ode_step_type yoshida4_type = {"yoshida4", fixed_init, fixed_evolve, fixed_reset,
                                                 fixed_free, &yoshida4,  NULL};
static const sicm_ode_step_type yoshida6_type = {"yoshida6", fixed_init, fixed_evolve, fixed_reset,
                                                 fixed_free, &yoshida6,  NULL};
static const sicm_ode_step_type yoshida8_type = {"yoshida8", fixed_init, fixed_evolve, fixed_reset,
                                                 fixed_free, &yoshida8,  NULL};

const sicm_ode_step_type *const sicm_ode_step_verlet = &verlet_type;
const sicm_ode_step_type *const sicm_ode_step_yoshida4 = &yoshida4_type;
const sicm_ode_step_type *const sicm_ode_step_yoshida6 = &yoshida6_type;
const sicm_ode_step_type *const sicm_ode_step_yoshida8 = &yoshida8_type;
