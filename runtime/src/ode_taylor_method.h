/* The Taylor method written once over a floating type, for ode_taylor.c to
 * instantiate in double (taylor) and long double (taylor-extended).
 *
 * Before including, define:
 *   REAL          the type of the state and the coefficients
 *   NAME(x)       x with this precision's prefix (taylor_x, taylor_ext_x)
 *   COEFFICIENTS  an expression of o: the coefficient function, or NULL
 *   FABS          fabs or fabsl
 *   TAYLOR_METHOD_NAME, SET_COEFFICIENTS  the method's and its setter's names, for messages
 * It defines NAME(init), NAME(evolve), NAME(reset), NAME(free) for a step
 * type table, and undefines nothing (ode_taylor.c does).
 *
 * The method keeps its own copy of the state, in REAL, at its own time,
 * which may be ahead of the caller (dense output): a step is as long as the
 * series allows, up to the horizon the caller set (sicm_ode_set_horizon) or
 * else up to t1, and the caller's t1 inside the step in hand is answered by
 * evaluating that step's polynomial there. A caller who comes back with the
 * state it was given continues from the method's own state, so neither the
 * stops of a monitor loop nor the rounding to double of the extended state
 * shorten a step or lose accuracy; any other state starts afresh. */

typedef struct {
  int order;
  double safety; /* exp(-0.7 / (order - 1)), the step's factor */
  REAL *c;       /* (order + 1) * dim: the expansion at the start of the step in hand */
  REAL *y;       /* the method's own state, at time t */
  REAL *comp;    /* its rounding error, carried (compensated summation) */
  REAL t;
  REAL t0;       /* the step in hand covers [t0, t] (have_step) */
  int have_step; /* c holds the expansion at t0 */
  int synced;    /* y, t valid and t_out, y_out what the caller was given */
  double t_out;
  double *y_out;
} NAME(state);

static int NAME(init)(sicm_ode *o) {
  NAME(state) *s = calloc(1, sizeof *s);
  if (!s) return SICM_ENOMEM;
  o->backend = s;
  s->order = taylor_order(o);
  s->safety = exp(-0.7 / (s->order - 1));
  s->c = malloc((size_t)(s->order + 1) * o->dim * sizeof *s->c);
  s->y = malloc(o->dim * sizeof *s->y);
  s->comp = malloc(o->dim * sizeof *s->comp);
  s->y_out = malloc(o->dim * sizeof *s->y_out);
  return s->c && s->y && s->comp && s->y_out ? SICM_SUCCESS : SICM_ENOMEM;
}

static void NAME(reset)(sicm_ode *o) {
  NAME(state) *s = o->backend;
  s->synced = 0;
  s->have_step = 0;
}

static void NAME(free)(sicm_ode *o) {
  NAME(state) *s = o->backend;
  free(s->c);
  free(s->y);
  free(s->comp);
  free(s->y_out);
  free(s);
}

/* The step size the coefficients allow (positive; INFINITY when the series
 * ends before order p - 1, as for a polynomial solution; NaN when a
 * coefficient of the last two orders is not finite): Jorba and Zou's
 * h = min over k = p-1, p of rho_k^(-1/k), times exp(-0.7/(p-1)), where
 * rho_k = max_i |c_k,i| / (abs_tol + rel_tol |y_i|). */
static double NAME(step_for)(const sicm_ode *o, const NAME(state) * s) {
  const int p = s->order;
  const REAL *c1 = s->c + (size_t)(p - 1) * o->dim, *c2 = s->c + (size_t)p * o->dim;
  REAL rho1 = 0, rho2 = 0;
  for (size_t i = 0; i < o->dim; i++) {
    /* One division a component for both orders. */
    const REAL weight = 1 / (o->abs_tol + o->rel_tol * FABS(s->y[i]));
    const REAL r1 = FABS(c1[i]) * weight, r2 = FABS(c2[i]) * weight;
    /* Not fmax, a call that drops NaN: these comparisons keep it. */
    rho1 = r1 > rho1 || r1 != r1 ? r1 : rho1;
    rho2 = r2 > rho2 || r2 != r2 ? r2 : rho2;
  }
  if (!isfinite(rho1) || !isfinite(rho2)) return NAN;
  double h = INFINITY;
  if (rho1 > 0) h = pow((double)rho1, -1.0 / (p - 1));
  if (rho2 > 0) h = fmin(h, pow((double)rho2, -1.0 / p));
  return h * s->safety;
}

static int NAME(finite)(size_t n, const REAL *v) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

/* The caller's view of the method's own state. */
static void NAME(report)(const sicm_ode *o, const NAME(state) * s, double *t, double *y) {
  for (size_t i = 0; i < o->dim; i++)
    y[i] = (double)s->y[i];
  *t = (double)s->t;
}

/* The failure of a step whose coefficients or new state are not finite,
 * reported at the own state (the start of the step). */
static int NAME(fail_non_finite)(sicm_ode *o, NAME(state) * s, double *t, double *y) {
  NAME(report)(o, s, t, y);
  if (!NAME(finite)((size_t)(s->order + 1) * o->dim, s->c))
    return sicm_ode_fail(o, SICM_EBADFUNC, *t, y, "non-finite derivative",
                         "the Taylor coefficients of the solution are NaN or infinite here");
  return sicm_ode_fail(o, SICM_EBADFUNC, *t, y, "non-finite state",
                       "a Taylor step gave NaN or infinite components");
}

/* One step from the own state (t, y) towards `limit`: expand, choose h,
 * advance. Returns SICM_SUCCESS or a failure (reported at the own state). */
static int NAME(step)(sicm_ode *o, NAME(state) * s, REAL limit, double *t, double *y) {
  const size_t dim = o->dim;
  const int p = s->order;
  s->have_step = 0;
  COEFFICIENTS(s->y, p, s->c, o->taylor_params);
  o->stats.rhs_evals++;
  /* The coefficients are not checked one by one here: a non-finite one
   * makes the step size NaN (the last two orders) or the new state
   * non-finite (the others, through Horner's sums), and only then are they
   * looked at, to say which. */
  const double h_series = NAME(step_for)(o, s);
  if (h_series != h_series) return NAME(fail_non_finite)(o, s, t, y);
  const REAL dir = limit > s->t ? 1 : -1;
  REAL h = dir * h_series;
  /* The step the series allows, even when this one is cut short at the
   * limit: a caller that chooses its own spans (events: ode_events.c) asks
   * for the next one as long. */
  o->h = (double)h;
  const int final = FABS(h) >= FABS(limit - s->t);
  if (final) h = limit - s->t;
  /* The step the time will actually take: t + h rounds, and a state
   * advanced by the unrounded h would drift in phase from its time by an
   * ulp of t a step (3e-14 over ten periods of an oscillator). */
  if (!final) h = (s->t + h) - s->t;
  if (s->t + h == s->t) {
    if (!NAME(finite)((size_t)(p + 1) * dim, s->c)) return NAME(fail_non_finite)(o, s, t, y);
    char detail[160];
    snprintf(detail, sizeof detail,
             "the series allows only h = %.3g, below the resolution of t; the solution may be "
             "singular here",
             (double)FABS(h));
    NAME(report)(o, s, t, y);
    return sicm_ode_fail(o, SICM_ESTEP, *t, y, "step size too small", detail);
  }
  /* y += sum_{k>=1} c_k h^k by Horner, the increment added with Kahan's
   * compensation carried from step to step: the rounding of y, a few ulps
   * a step, would otherwise accumulate over the many steps of a long run. */
  for (size_t i = 0; i < dim; i++) {
    REAL v = s->c[(size_t)p * dim + i];
    for (int k = p - 1; k >= 1; k--)
      v = v * h + s->c[(size_t)k * dim + i];
    const REAL increment = v * h + s->comp[i];
    const REAL sum = s->y[i] + increment;
    s->comp[i] = (s->y[i] - sum) + increment;
    s->y[i] = sum;
  }
  if (!NAME(finite)(dim, s->y)) {
    for (size_t i = 0; i < dim; i++) /* back to the last accepted point */
      s->y[i] = s->c[i];
    return NAME(fail_non_finite)(o, s, t, y);
  }
  s->t0 = s->t;
  s->t = final ? limit : s->t + h;
  s->have_step = 1;
  o->stats.steps++;
  return SICM_SUCCESS;
}

/* The step in hand's polynomial at s after ta, when the step spans exactly
 * [ta, tb] (the step type's dense output: events are located on it). */
static int NAME(dense)(sicm_ode *o, double ta, double tb, double s, double *y) {
  NAME(state) *st = o->backend;
  if (!st->have_step || (double)st->t0 != ta || (double)st->t != tb) return SICM_EINVAL;
  if (!y) return SICM_SUCCESS;
  const REAL tau = (REAL)ta - st->t0 + (REAL)s;
  const int p = st->order;
  for (size_t i = 0; i < o->dim; i++) {
    REAL v = st->c[(size_t)p * o->dim + i];
    for (int k = p - 1; k >= 0; k--)
      v = v * tau + st->c[(size_t)k * o->dim + i];
    y[i] = (double)v;
  }
  return SICM_SUCCESS;
}

static int NAME(evolve)(sicm_ode *o, double *t, double t1, double *y) {
  NAME(state) *s = o->backend;
  const size_t dim = o->dim;
  if (!COEFFICIENTS)
    return sicm_ode_fail(o, SICM_EINVAL, *t, y, "no Taylor coefficients",
                         "the " TAYLOR_METHOD_NAME
                         " method needs a coefficient function (" SET_COEFFICIENTS
                         "), which the compiler makes from a compiled system derivative");
  if (!s->synced || *t != s->t_out || memcmp(y, s->y_out, dim * sizeof *y) != 0) {
    for (size_t i = 0; i < dim; i++) {
      s->y[i] = y[i];
      s->comp[i] = 0;
    }
    s->t = *t;
    s->have_step = 0;
    s->synced = 1;
  }
  const double dir = t1 > *t ? 1.0 : -1.0;
  /* Steps may run on to the horizon, never past it nor back from it. */
  REAL limit = t1;
  if (o->horizon_set && (o->horizon - t1) * dir > 0) limit = o->horizon;
  unsigned long steps = 0;
  for (;;) {
    if (s->t == (REAL)t1) {
      NAME(report)(o, s, t, y);
      break;
    }
    if (s->have_step && (t1 - s->t0) * dir >= 0 && (s->t - t1) * dir > 0) {
      /* t1 inside the step in hand: its polynomial there. */
      const REAL tau = (REAL)t1 - s->t0;
      const int p = s->order;
      for (size_t i = 0; i < dim; i++) {
        REAL v = s->c[(size_t)p * dim + i];
        for (int k = p - 1; k >= 0; k--)
          v = v * tau + s->c[(size_t)k * dim + i];
        y[i] = (double)v;
      }
      break;
    }
    if (steps++ >= o->max_steps) {
      NAME(report)(o, s, t, y);
      s->synced = 0;
      return sicm_ode_fail_max_steps(o, *t, y);
    }
    int status = NAME(step)(o, s, limit, t, y);
    if (status != SICM_SUCCESS) {
      s->synced = 0;
      return status;
    }
  }
  *t = t1;
  s->t_out = t1;
  memcpy(s->y_out, y, dim * sizeof *y);
  return SICM_SUCCESS;
}
