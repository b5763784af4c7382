/* SUNDIALS CVODE backends: variable-order Adams (fixed point) and BDF (Newton, dense LU).
 *
 * Each integrator object owns its own SUNDIALS context, so there is no
 * global state. CVODE is set up once at allocation (CVodeInit needs a start
 * point; it is given a dummy one and every real start goes through
 * CVodeReInit). Each evolve sets CVODE's stop time to t1 and asks for the
 * solution there, so CVODE never steps past t1 and keeps its step size,
 * order and history between calls. CVODE's messages are captured instead of
 * printed, and its return flags are turned into our statuses with the
 * state at the last step it completed. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "ode_internal.h"

typedef struct {
  SUNContext ctx;
  void *mem;
  N_Vector y;
  N_Vector dense;         /* CVodeGetDky's output, for cv_dense */
  SUNMatrix A;            /* BDF only */
  SUNLinearSolver ls;     /* BDF only */
  SUNNonlinearSolver nls; /* Adams only */
  double *jac;            /* dim*dim row-major, for the user's Jacobian */
  double *dfdt;
  int need_reinit;
  int saw_nonfinite;
  long seen_steps, seen_fails, seen_jacs; /* CVODE counters already added to stats */
  char cv_message[256];                   /* CVODE's last error message */
} cv_backend;

static int is_bdf(const sicm_ode *o) {
  return *(const int *)o->type->data == CV_BDF;
}

static int cv_status(sicm_ode *o, int s) {
  if (s == SICM_SUCCESS) return 0;
  if (s == SICM_EUSER) return -1; /* unrecoverable: CVODE stops */
  ((cv_backend *)o->backend)->saw_nonfinite = 1;
  return 1; /* recoverable: CVODE retries with a smaller step */
}

static int cv_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void *user_data) {
  sicm_ode *o = user_data;
  return cv_status(o, sicm_ode_call_rhs(o, t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot)));
}

static int cv_jacobian(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J, void *user_data,
                       N_Vector tmp1, N_Vector tmp2, N_Vector tmp3) {
  (void)fy, (void)tmp1, (void)tmp2, (void)tmp3;
  sicm_ode *o = user_data;
  cv_backend *b = o->backend;
  const size_t n = o->dim;
  int s = sicm_ode_call_jacobian(o, t, N_VGetArrayPointer(y), b->jac, b->dfdt, NULL);
  if (s != SICM_SUCCESS) return cv_status(o, s);
  for (size_t j = 0; j < n; j++) { /* SUNDIALS dense matrices are column-major */
    sunrealtype *col = SUNDenseMatrix_Column(J, (sunindextype)j);
    for (size_t i = 0; i < n; i++)
      col[i] = b->jac[i * n + j];
  }
  return 0;
}

static void cv_error_handler(int error_code, const char *module, const char *function, char *msg,
                             void *data) {
  (void)module;
  if (error_code == CV_WARNING) return; /* e.g. "t + h = t": the failure that follows says it */
  cv_backend *b = data;
  snprintf(b->cv_message, sizeof b->cv_message, "%s: %s", function, msg);
}

static int cv_init(sicm_ode *o) {
  cv_backend *b = calloc(1, sizeof *b);
  if (!b) return SICM_ENOMEM;
  o->backend = b;
  const size_t n = o->dim;
  if (SUNContext_Create(NULL, &b->ctx) != 0) return SICM_EFAILED;
  b->y = N_VNew_Serial((sunindextype)n, b->ctx);
  b->dense = N_VNew_Serial((sunindextype)n, b->ctx);
  b->mem = CVodeCreate(is_bdf(o) ? CV_BDF : CV_ADAMS, b->ctx);
  if (!b->y || !b->dense || !b->mem) return SICM_ENOMEM;
  N_VConst(0.0, b->y);
  int s = CVodeInit(b->mem, cv_rhs, 0.0, b->y);
  s = s ? s : CVodeSetErrHandlerFn(b->mem, cv_error_handler, b);
  s = s ? s : CVodeSetUserData(b->mem, o);
  s = s ? s : CVodeSStolerances(b->mem, o->rel_tol, o->abs_tol);
  if (s) return SICM_EFAILED;
  if (is_bdf(o)) {
    b->A = SUNDenseMatrix((sunindextype)n, (sunindextype)n, b->ctx);
    b->ls = b->A ? SUNLinSol_Dense(b->y, b->A, b->ctx) : NULL;
    b->jac = malloc(n * n * sizeof *b->jac);
    b->dfdt = malloc(n * sizeof *b->dfdt);
    if (!b->ls || !b->jac || !b->dfdt) return SICM_ENOMEM;
    if (CVodeSetLinearSolver(b->mem, b->ls, b->A)) return SICM_EFAILED;
  } else {
    b->nls = SUNNonlinSol_FixedPoint(b->y, 0, b->ctx);
    if (!b->nls) return SICM_ENOMEM;
    if (CVodeSetNonlinearSolver(b->mem, b->nls)) return SICM_EFAILED;
  }
  b->need_reinit = 1;
  return SICM_SUCCESS;
}

static void cv_free(sicm_ode *o) {
  cv_backend *b = o->backend;
  if (!b) return;
  if (b->mem) CVodeFree(&b->mem);
  if (b->nls) SUNNonlinSolFree(b->nls);
  if (b->ls) SUNLinSolFree(b->ls);
  if (b->A) SUNMatDestroy(b->A);
  if (b->y) N_VDestroy(b->y);
  if (b->dense) N_VDestroy(b->dense);
  if (b->ctx) SUNContext_Free(&b->ctx);
  free(b->jac);
  free(b->dfdt);
  free(b);
}

static void cv_reset(sicm_ode *o) {
  ((cv_backend *)o->backend)->need_reinit = 1;
}

/* Add CVODE's counters since the last look to our statistics (rhs calls are
 * counted by cv_rhs itself; Jacobians here only when CVODE differences them,
 * since sicm_ode_call_jacobian counts the user's). */
static void cv_collect_stats(sicm_ode *o, cv_backend *b) {
  long steps = 0, etf = 0, cvf = 0, jacs = 0;
  CVodeGetNumSteps(b->mem, &steps);
  CVodeGetNumErrTestFails(b->mem, &etf);
  CVodeGetNumNonlinSolvConvFails(b->mem, &cvf);
  if (is_bdf(o)) CVodeGetNumJacEvals(b->mem, &jacs);
  o->stats.steps += (unsigned long)(steps - b->seen_steps);
  o->stats.rejected_steps += (unsigned long)(etf + cvf - b->seen_fails);
  if (!o->jac) o->stats.jacobian_evals += (unsigned long)(jacs - b->seen_jacs);
  b->seen_steps = steps;
  b->seen_fails = etf + cvf;
  b->seen_jacs = jacs;
}

static int cv_fail(sicm_ode *o, cv_backend *b, int flag, double t, const double *y) {
  const char *detail = b->cv_message[0] ? b->cv_message : NULL;
  if (o->user_status != 0) return sicm_ode_fail_user(o, t, y);
  switch (flag) {
  case CV_TOO_MUCH_WORK: return sicm_ode_fail_max_steps(o, t, y);
  case CV_TOO_MUCH_ACC: return sicm_ode_fail(o, SICM_ETOL, t, y, "tolerance too small", detail);
  case CV_ERR_FAILURE: return sicm_ode_fail(o, SICM_ESTEP, t, y, "step size too small", detail);
  case CV_FIRST_RHSFUNC_ERR:
  case CV_REPTD_RHSFUNC_ERR:
  case CV_RHSFUNC_FAIL:
  case CV_UNREC_RHSFUNC_ERR:
    return sicm_ode_fail(o, SICM_EBADFUNC, t, y, "non-finite derivative", detail);
  case CV_CONV_FAILURE:
  case CV_LSETUP_FAIL:
  case CV_LSOLVE_FAIL:
  case CV_NLS_FAIL:
    if (b->saw_nonfinite)
      return sicm_ode_fail(o, SICM_EBADFUNC, t, y, "non-finite derivative", detail);
    return sicm_ode_fail(o, SICM_ECONV, t, y, "nonlinear solver failed to converge", detail);
  }
  return sicm_ode_fail(o, SICM_EFAILED, t, y, "CVODE failure", detail);
}

static int cv_evolve(sicm_ode *o, double *t, double t1, double *y) {
  cv_backend *b = o->backend;
  const size_t n = o->dim;
  double *yv = N_VGetArrayPointer(b->y);
  if (b->need_reinit) {
    memcpy(yv, y, n * sizeof *y);
    if (CVodeReInit(b->mem, *t, b->y) ||
        (is_bdf(o) && CVodeSetJacFn(b->mem, o->jac ? cv_jacobian : NULL)))
      return sicm_ode_fail(o, SICM_EFAILED, *t, y, "CVODE failure", b->cv_message);
    b->seen_steps = b->seen_fails = b->seen_jacs = 0;
    b->need_reinit = 0;
  }
  CVodeSetMaxNumSteps(b->mem, (long)o->max_steps);
  CVodeSetStopTime(b->mem, t1);
  /* Without a minimum step CVODE keeps taking steps that no longer move t
   * (it only warns "t + h = t") until the step limit; the resolution of t is
   * the floor the other backends use too. */
  CVodeSetMinStep(b->mem, 16 * DBL_EPSILON * fmax(fabs(*t), fabs(t1)));
  b->cv_message[0] = 0;
  b->saw_nonfinite = 0;
  o->user_status = 0;
  sunrealtype tret = *t;
  int flag = CVode(b->mem, t1, b->y, &tret, CV_NORMAL);
  cv_collect_stats(o, b);
  sunrealtype hcur = 0;
  CVodeGetCurrentStep(b->mem, &hcur);
  o->h = hcur; /* for the driver: the direction CVODE's history belongs to */
  if (flag < 0) {
    /* CVODE leaves the last point it reached in (tret, y). */
    *t = tret;
    memcpy(y, yv, n * sizeof *y);
    return cv_fail(o, b, flag, *t, y);
  }
  memcpy(y, yv, n * sizeof *y);
  *t = t1;
  return SICM_SUCCESS;
}

/* CVODE's own continuous output (the step type's dense): the
 * interpolating polynomial of its last internal step, as accurate as the
 * step, when that step spans [ta, tb] (an evolve to tb stops there: the
 * stop time), so that events are located on it, as on a Taylor step. */
static int cv_dense(sicm_ode *o, double ta, double tb, double s, double *y) {
  cv_backend *b = o->backend;
  if (b->need_reinit) return SICM_EINVAL;
  sunrealtype tn = 0, hu = 0;
  if (CVodeGetCurrentTime(b->mem, &tn) || CVodeGetLastStep(b->mem, &hu) || tn != tb ||
      fabs((tn - hu) - ta) > 4 * DBL_EPSILON * fmax(fabs(ta), fabs(tb)))
    return SICM_EINVAL;
  if (!y) return SICM_SUCCESS;
  /* Within the step: ta + s may round a hair outside it. */
  double t = ta + s;
  const double lo = fmin(tn - hu, tn), hi = fmax(tn - hu, tn);
  t = fmin(fmax(t, lo), hi);
  if (CVodeGetDky(b->mem, t, 0, b->dense)) return SICM_EINVAL;
  memcpy(y, N_VGetArrayPointer(b->dense), o->dim * sizeof *y);
  return SICM_SUCCESS;
}

static const int kAdams = CV_ADAMS, kBdf = CV_BDF;

const sicm_ode_step_type sicm_ode_cvode_adams_type = {"cvode-adams", cv_init, cv_evolve, cv_reset,
                                                      cv_free,       &kAdams, cv_dense};
const sicm_ode_step_type sicm_ode_cvode_bdf_type = {"cvode-bdf", cv_init, cv_evolve, cv_reset,
                                                    cv_free,     &kBdf,   cv_dense};
