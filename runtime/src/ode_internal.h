/* Private to the ODE module: the integrator object, step-type table and shared helpers. */
#ifndef SICM_ODE_INTERNAL_H
#define SICM_ODE_INTERNAL_H

#include <stddef.h>

#include "sicm/runtime.h"

/* A step type is a small table of functions (a "backend"). ode.c implements
 * the GSL steppers, ode_bs.c Bulirsch-Stoer, ode_cvode.c CVODE, ode_taylor.c
 * Taylor series from generated coefficients, ode_qc.c scmutils'
 * quality-controlled qcrk4 and qcctrap2. The driver
 * in ode.c validates arguments, notices when the caller has moved the
 * state between calls, and keeps statistics of rhs calls; the backend does
 * the stepping.
 *
 *   init    allocate the backend's state into o->backend (o->dim etc. are set).
 *   evolve  advance (*t, y) to t1, which differs from *t. On failure leave the
 *           last accepted point in (*t, y) and return the status from
 *           sicm_ode_fail, which has already composed the message.
 *   reset   forget step size and history (o->h is cleared by the driver).
 *   free    release o->backend. */
struct sicm_ode_step_type {
  const char *name;
  int (*init)(sicm_ode *o);
  int (*evolve)(sicm_ode *o, double *t, double t1, double *y);
  void (*reset)(sicm_ode *o);
  void (*free)(sicm_ode *o);
  const void *data; /* backend-specific: the GSL step type, the CVODE method */
  /* The method's own continuous output, or NULL: if its last step spans
   * exactly [ta, tb], writes into y (unless NULL) the solution at ta + s
   * for s in [0, tb - ta] and returns SICM_SUCCESS; else SICM_EINVAL.
   * Events (ode_events.c) are located on it when it is there. */
  int (*dense)(sicm_ode *o, double ta, double tb, double s, double *y);
};

enum { SICM_ODE_MESSAGE_SIZE = 1024 };

struct sicm_ode {
  const sicm_ode_step_type *type;
  size_t dim;
  sicm_ode_rhs f;
  sicm_ode_jacobian jac; /* NULL: finite differences */
  void *params;
  double abs_tol, rel_tol;
  unsigned long max_steps; /* per evolve call */

  /* Step size to try next, signed; 0 means "choose one". Kept between calls
   * so that short successive evolves resume at the controller's step. */
  double h;

  /* The point the last successful evolve ended at, to notice a caller who
   * moves the state between calls (then the method restarts). */
  int have_last;
  double t_last;
  double *y_last;

  int user_status; /* what the rhs or Jacobian returned when it stopped us */
  /* The first component of the derivative that was NaN or infinite in the
   * last such evaluation (-1: none since evolve began), and its value, for
   * the message of a "non-finite derivative" failure. */
  long bad_component;
  double bad_value;
  sicm_ode_stats stats;
  char message[SICM_ODE_MESSAGE_SIZE];
  void *backend;

  /* The stiffness watch of the explicit methods (sicm_ode_watch_stiffness):
   * accepted steps since its last check and the time they covered, how
   * many checks in a row found the step held by stability, and its scratch
   * (NULL until the first check), which begins with the power iteration's
   * vector (have_vector: valid). */
  /* sicm_ode_set_singularity_probe: what the system derivative divides by,
   * evaluated where an integration fails (NULL: no probe). y_start is the
   * state the current evolve call began at; y_bad the last state at which
   * the derivative was non-finite or met a singular matrix (have_bad). */
  sicm_ode_probe probe;
  const double *probe_params;
  size_t probe_count;
  const char *const *probe_texts;
  double *probe_work; /* y_start, y_bad (dim each), values at both (probe_count each) */
  double t_start, t_bad;
  int have_bad;

  /* sicm_ode_set_taylor: the Taylor coefficients of the solution (NULL: none). */
  sicm_ode_taylor_coefficients taylor;
  sicm_ode_taylor_extended_coefficients taylor_extended; /* the same in long double */
  const double *taylor_params;

  /* sicm_ode_set_events (ode_events.c): the events and their handler; for
   * each event the sign of g where it was last not 0 (0: not seen yet);
   * where the last evolve ended (have_event_last), to tell a resumed
   * integration from a new one; the event that stopped it (-1: none); the
   * integrator that places events on the solution (made at the first
   * event), and scratch. */
  sicm_ode_event *events;
  size_t event_count;
  sicm_ode_event_handler event_handler;
  void *event_data;
  int *event_sign;
  int *event_sign_scratch; /* the signs a screened step ends with, before they are taken */
  int have_event_last;
  double event_t_last;
  double *event_y_last;
  long stopping_event;
  double event_t0; /* the start of the step whose events are being placed */
  sicm_ode *event_solver;
  double *event_work;
  sicm_ode_event_stats event_stats;

  int horizon_set; /* sicm_ode_set_horizon: where the caller is going */
  double horizon;
  unsigned long steps_since_check;
  double span_since_check;
  int stiff_streak;
  int have_vector;
  double *stiffness_work;
};

/* Results of sicm_ode_call_rhs and sicm_ode_call_jacobian, besides
 * SICM_SUCCESS: SICM_EUSER (the user function returned non-zero; its value
 * is in o->user_status) or SICM_EBADFUNC (non-finite argument or result;
 * the caller should retry with a smaller step). */
int sicm_ode_call_rhs(sicm_ode *o, double t, const double *y, double *dydt);
int sicm_ode_call_jacobian(sicm_ode *o, double t, const double *y, double *dfdy, double *dfdt,
                           double *work);

/* sicm_ode_initial_step proposes a first step for a method of the given
 * order from (t, y) with derivative f0 towards t1, by the estimate of
 * Hairer, Norsett and Wanner (I, II.4): make the first step's error estimate
 * about the tolerance judging from the sizes of y, f and f'. Uses one rhs
 * evaluation (work needs 2*dim doubles). Returns the signed step, or 0 with
 * *status set if the rhs failed. */
double sicm_ode_initial_step(sicm_ode *o, double t, const double *y, const double *f0, double t1,
                             int order, double *work, int *status);

/* sicm_ode_rms_scaled returns the root-mean-square of v_i / (abs_tol +
 * rel_tol |y_i|): the size of v against the tolerances. */
double sicm_ode_rms_scaled(const sicm_ode *o, const double *v, const double *y);

/* sicm_ode_error_norm returns max_i |err_i| / (abs_tol + rel_tol |y_i|):
 * the step is acceptable when it is at most 1. */
double sicm_ode_error_norm(const sicm_ode *o, const double *err, const double *y);

/* sicm_ode_fail composes o->message as "NAME: WHAT at t = T with state
 * [y...]: DETAIL", reports it through the error hook, and returns status.
 * detail may be NULL. */
int sicm_ode_fail(sicm_ode *o, int status, double t, const double *y, const char *what,
                  const char *detail);

/* The messages of the usual failures, shared so all backends say the same. */
int sicm_ode_fail_user(sicm_ode *o, double t, const double *y);

/* The derivative f0 at the point (t, y) a step starts from, for the
 * backends that keep it between steps (Bulirsch-Stoer, the qc methods):
 * SICM_SUCCESS, or the failure already reported (the user's status, or a
 * non-finite derivative). */
int sicm_ode_start_derivative(sicm_ode *o, double t, const double *y, double *f0);
int sicm_ode_fail_max_steps(sicm_ode *o, double t, const double *y);

/* Where an explicit method is stable on y' = lambda y: the largest |h lambda|
 * on the negative real axis and on the imaginary axis up to which the
 * method's amplification |R(h lambda)| stays within 1 + 1e-3 per step. */
typedef struct {
  double real, imaginary;
} sicm_ode_stability;

/* sicm_ode_watch_stiffness is called by the explicit backends after each
 * accepted step, of size h, that ended at (t, y) on the way to t1; stability
 * is that of the method as used for the step. Now and then it estimates the
 * fastest rate of the system (a few rhs calls, counted in the statistics)
 * and, when the step has been held at the method's stability limit for a
 * while and t1 is still far, fails with SICM_ESTIFF through sicm_ode_fail,
 * naming an implicit method. Returns SICM_SUCCESS or that status. The
 * implicit methods (msbdf, CVODE) are not watched. */
int sicm_ode_watch_stiffness(sicm_ode *o, double t, const double *y, double h, double t1,
                             sicm_ode_stability stability);

/* sicm_ode_evolve_plain is sicm_ode_evolve without events;
 * sicm_ode_evolve_events (ode_events.c) is it with them, calling the plain
 * one a step at a time. sicm_ode_free_events releases what the events own. */
int sicm_ode_evolve_plain(sicm_ode *o, double *t, double t1, double *y);
int sicm_ode_evolve_events(sicm_ode *o, double *t, double t1, double *y);
void sicm_ode_free_events(sicm_ode *o);

/* All components finite? */
int sicm_ode_finite(size_t n, const double *v);

/* The backends' type tables. */
extern const sicm_ode_step_type sicm_ode_bs_type;
extern const sicm_ode_step_type sicm_ode_cvode_adams_type;
extern const sicm_ode_step_type sicm_ode_cvode_bdf_type;
extern const sicm_ode_step_type sicm_ode_taylor_type;
extern const sicm_ode_step_type sicm_ode_taylor_extended_type;
extern const sicm_ode_step_type sicm_ode_qcrk4_type;
extern const sicm_ode_step_type sicm_ode_qcctrap2_type;

#endif /* SICM_ODE_INTERNAL_H */
