/* sicm runtime: ODE integrators (adaptive steppers and fixed-step symplectic maps). */
#ifndef SICM_ODE_H
#define SICM_ODE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the system ---------------------------------------------------------
 * A system of first-order equations dy/dt = f(t, y) of dimension dim.
 *
 * sicm_ode_rhs stores f(t, y) in dydt[0..dim-1] and returns 0. Any other
 * return value stops the integration at once: sicm_ode_evolve then returns
 * SICM_EUSER and leaves t and y at the last accepted step. The integrator
 * checks the values it receives: a non-finite derivative makes it retry with
 * a smaller step, and if no step size helps it fails with SICM_ESTEP or
 * SICM_EBADFUNC.
 *
 * sicm_ode_jacobian stores the Jacobian of f in dfdy, row-major
 * (dfdy[i*dim + j] = df_i/dy_j), and df/dt in dfdt[0..dim-1]; both arrays
 * are always supplied. Its return value means what sicm_ode_rhs's does. */
typedef int (*sicm_ode_rhs)(double t, const double *y, double *dydt, void *params);
typedef int (*sicm_ode_jacobian)(double t, const double *y, double *dfdy, double *dfdt,
                                 void *params);

/* ---- step types -----------------------------------------------------------
 * The algorithm is chosen by a constant type, as in GSL:
 *
 *   sicm_ode_step_rk8pd        Dormand-Prince 8(7), GSL. Explicit, high order;
 *                              the best general choice for smooth non-stiff
 *                              problems at tight tolerances.
 *   sicm_ode_step_rkf45        Runge-Kutta-Fehlberg 4(5), GSL.
 *   sicm_ode_step_rkck         Cash-Karp 4(5), GSL.
 *   sicm_ode_step_msbdf        Variable-order (1-5) BDF, GSL, for stiff problems;
 *                              uses the Jacobian (finite differences if none is set).
 *                              This is Gear's method: scmutils' gear and
 *                              explicit-gear, one method there (variable-order (1-4)
 *                              BDF with Newton iteration on the Jacobian), run as it.
 *   sicm_ode_step_bs           Bulirsch-Stoer: Gragg's modified midpoint rule with
 *                              polynomial extrapolation, adaptive order and step
 *                              (Deuflhard; Hairer-Norsett-Wanner). The default of
 *                              scmutils and SICM; very efficient at tight
 *                              tolerances on smooth non-stiff problems.
 *   sicm_ode_step_qcrk4        scmutils' qcrk4: classical RK4 made adaptive by step
 *                              doubling (a step h against two of h/2) with local
 *                              extrapolation (the two half steps plus their difference
 *                              from the whole step over 15: order 5). Explicit; 11 rhs
 *                              evaluations a step. Error measured as scmutils does,
 *                              relative (see Tolerances below).
 *   sicm_ode_step_qcctrap2     scmutils' qcctrap2: the trapezoid rule, solved by
 *                              corrector (fixed-point) iteration from an Euler
 *                              predictor, with the same step doubling and
 *                              extrapolation (order 3). Implicit, but the iteration
 *                              converges only for h |lambda| < 2, so it is no help
 *                              on stiff problems. Error measured as for qcrk4.
 *   sicm_ode_step_cvode_adams  SUNDIALS CVODE, variable-order (1-12) Adams-Moulton
 *                              with fixed-point iteration; non-stiff.
 *   sicm_ode_step_cvode_bdf    SUNDIALS CVODE, variable-order (1-5) BDF with Newton
 *                              iteration and a dense linear solver; stiff. Uses the
 *                              Jacobian if set, difference quotients otherwise.
 *   sicm_ode_step_verlet       The symplectic methods below (Stormer-Verlet and
 *   sicm_ode_step_yoshida4     Yoshida's compositions of orders 4, 6, 8) as step
 *   sicm_ode_step_yoshida6     types, for separable systems in the book's states
 *   sicm_ode_step_yoshida8     y = (t, q_1..q_n, p_1..p_n) (or velocities instead
 *                              of momenta, with a constant mass matrix). Fixed
 *                              step: abs_tol given to sicm_ode_alloc is the step
 *                              size, not a tolerance; each evolve covers its
 *                              interval in equal steps of at most that size.
 *                              The velocity is the q part of the right-hand side
 *                              and the force its p part, so the first evolve
 *                              checks, at its starting point, that the q part
 *                              does not depend on t or q nor the p part on p,
 *                              and fails with SICM_EINVAL ("the system is not
 *                              separable") otherwise.
 *   sicm_ode_step_taylor       Taylor series of high order from a coefficient
 *                              function (sicm_ode_set_taylor), which the compiler
 *                              generates from the system derivative's code. Order
 *                              and step from the tolerance (Jorba-Zou): order
 *                              p = ceil(-ln(tol)/2) + 1, tol the smaller non-zero
 *                              tolerance; step from the sizes of the last two
 *                              coefficients. Explicit; no stiffness watch. One
 *                              Taylor expansion counts as one rhs evaluation in
 *                              the statistics (it costs a few). Steps run on to
 *                              the horizon (sicm_ode_set_horizon) and a t1 inside
 *                              a step is answered from its polynomial (dense
 *                              output).
 *   sicm_ode_step_taylor_extended  The same in long double (64-bit significand
 *                              on x86), from a coefficient function in long
 *                              double (sicm_ode_set_taylor_extended); its state
 *                              stays in long double between calls that pass back
 *                              the state they were given. For references and
 *                              errors below double rounding over long runs. */
typedef struct sicm_ode_step_type sicm_ode_step_type;

extern const sicm_ode_step_type *const sicm_ode_step_rk8pd;
extern const sicm_ode_step_type *const sicm_ode_step_rkf45;
extern const sicm_ode_step_type *const sicm_ode_step_rkck;
extern const sicm_ode_step_type *const sicm_ode_step_msbdf;
extern const sicm_ode_step_type *const sicm_ode_step_bs;
extern const sicm_ode_step_type *const sicm_ode_step_qcrk4;
extern const sicm_ode_step_type *const sicm_ode_step_qcctrap2;
extern const sicm_ode_step_type *const sicm_ode_step_cvode_adams;
extern const sicm_ode_step_type *const sicm_ode_step_cvode_bdf;
extern const sicm_ode_step_type *const sicm_ode_step_verlet;
extern const sicm_ode_step_type *const sicm_ode_step_yoshida4;
extern const sicm_ode_step_type *const sicm_ode_step_yoshida6;
extern const sicm_ode_step_type *const sicm_ode_step_yoshida8;
extern const sicm_ode_step_type *const sicm_ode_step_taylor;
extern const sicm_ode_step_type *const sicm_ode_step_taylor_extended;

/* sicm_ode_step_type_name returns the type's short name ("rk8pd", "bs",
 * "cvode-bdf", ...), as used in messages. */
const char *sicm_ode_step_type_name(const sicm_ode_step_type *T);

/* ---- the integrator -------------------------------------------------------
 * An integrator object holds the system, the tolerances, the algorithm's
 * state (step size, order, multistep history) and statistics. It is not
 * tied to a time or state: each call of sicm_ode_evolve says where to start.
 *
 * Tolerances. A step is accepted when the estimate e_i of its local error
 * satisfies, for every component i,
 *
 *     |e_i| <= abs_tol + rel_tol * |y_i|
 *
 * where y_i is the component at the end of the step. This is the test of
 * Bulirsch-Stoer and of the GSL Runge-Kutta steppers (GSL's controller lets
 * the largest ratio reach 1.1 before rejecting). The multistep methods
 * (msbdf, CVODE) apply the same weights to the root-mean-square over the
 * components of e_i / (abs_tol + rel_tol |y_i|), which is at most the
 * maximum, so their test is slightly looser, and their error estimates are
 * less conservative: at equal tolerances their global errors are typically
 * 10 to 100 times those of the one-step methods. qcrk4 and qcctrap2 measure
 * as scmutils does: the difference d_i of a step taken whole and in two
 * halves, relative to the mean size m_i of the two results, is accepted when
 * for every component
 *
 *     |d_i| <= 2 rel_tol (m_i + 1e-10)
 *
 * (1e-10 is scmutils' size below which the measure turns absolute); abs_tol
 * is not used unless rel_tol is 0, when the test is |d_i| <= 2 abs_tol. The
 * extrapolated result is far more accurate than d_i, so at equal tolerances
 * their errors are far smaller than the other methods'. The tolerances bound the
 * error committed in one step, not the global error, which accumulates over
 * the steps (and can grow exponentially for unstable or chaotic systems).
 *
 * scmutils' `evolve` and `state-advancer` take a single "local error"
 * number: the interpreter passes it as both abs_tol and rel_tol.
 *
 * All functions that return int return SICM_SUCCESS (0) or one of the codes of
 * sicm/error.h; every failure is also reported through the error hook. */
typedef struct sicm_ode sicm_ode;

/* Statistics accumulated over the object's lifetime (sicm_ode_reset does not
 * clear them). steps counts accepted steps; rejected_steps counts step
 * attempts that were discarded and retried with a smaller step (error test
 * failures, non-finite values, and for CVODE nonlinear convergence failures);
 * rhs_evals counts every call of the right-hand side, including those made
 * to estimate Jacobians by finite differences and to choose the first step;
 * jacobian_evals counts Jacobian evaluations, analytic or by differences. */
typedef struct {
  unsigned long steps;
  unsigned long rejected_steps;
  unsigned long rhs_evals;
  unsigned long jacobian_evals;
} sicm_ode_stats;

/* sicm_ode_alloc creates an integrator of type T for a system of dimension
 * dim >= 1 with right-hand side f, whose last argument will be params.
 * abs_tol and rel_tol must be non-negative and not both zero. Returns NULL
 * (and reports through the error hook) for invalid arguments or when memory
 * runs out. */
sicm_ode *sicm_ode_alloc(const sicm_ode_step_type *T, size_t dim, sicm_ode_rhs f, void *params,
                         double abs_tol, double rel_tol);

/* sicm_ode_free releases o and everything it owns; NULL is allowed. */
void sicm_ode_free(sicm_ode *o);

/* sicm_ode_set_jacobian gives the integrator an analytic Jacobian (NULL
 * goes back to finite differences). Only the implicit methods, msbdf and
 * cvode-bdf, use it; for the others it is accepted and ignored. It takes
 * effect at the next sicm_ode_evolve, which restarts the method. Returns
 * SICM_SUCCESS. */
int sicm_ode_set_jacobian(sicm_ode *o, sicm_ode_jacobian jac);

/* sicm_ode_set_max_steps limits the number of steps one call of
 * sicm_ode_evolve may take (default 500000); exceeding it fails with
 * SICM_EMAXITER. max_steps must be positive. */
int sicm_ode_set_max_steps(sicm_ode *o, unsigned long max_steps);

/* sicm_ode_evolve advances the solution from (*t, y) to exactly t1 with
 * adaptive steps (t1 may lie before *t: integration runs backwards), and on
 * success sets *t = t1 and y to the solution there.
 *
 * The step size, order and multistep history are kept between calls, so a
 * loop that calls sicm_ode_evolve repeatedly in small increments of t (a
 * monitor printing or plotting the state) costs little more than one long
 * call: steps are shortened only to land on each t1, and the next call
 * resumes with the step size the error control had reached. If the caller
 * changes *t or y between calls (for instance restarts from a new initial
 * condition), the object notices and restarts its method from scratch; see
 * also sicm_ode_reset.
 *
 * On failure the return value is non-zero, *t and y hold the last point
 * reached (the last accepted step), and sicm_ode_last_error(o) describes
 * the failure, naming the method, the time, the state vector and the reason
 * (step size too small, non-finite state or derivative, too many steps,
 * stopped by the right-hand side), e.g.
 *
 *   rk8pd: step size too small at t = 1.00000000000716 with state [1101882664230043.6]:
 *   the error test fails even for the shortest step the resolution of t allows
 *   (h = 1.03e-16); the solution may be singular here
 *
 * (times and components are printed as the compiler prints numbers; at most
 * 16 components are shown).
 *
 * The explicit methods (rk8pd, rkf45, rkck, bs, qcrk4) and qcctrap2, whose
 * corrector iteration limits its step as stability limits theirs, watch
 * for stiffness: when
 * their step has been held by the method's stability, not by the tolerance,
 * for some 800 steps and reaching t1 would take more than 1e5 further steps,
 * they stop with SICM_ESTIFF, saying so and naming cvode-bdf. A short run is
 * never stopped; a loop of short evolve calls is counted to its horizon
 * (sicm_ode_set_horizon).
 *
 * The same message goes to the error hook. */
int sicm_ode_evolve(sicm_ode *o, double *t, double t1, double *y);

/* ---- events ----------------------------------------------------------
 * An event is a real function g(t, y) of the solution; it happens where g
 * changes sign along the solution, in a chosen direction: up (from
 * negative to positive as the integration proceeds, whichever way t runs),
 * down, or both. A g that touches 0 and turns back (a tangency) makes no
 * event; a g that is 0 where an evolve starts makes none there either (it
 * counts from the first point where g is not 0), so an integration resumed
 * from an event's state does not find that event again.
 *
 * With events set, sicm_ode_evolve integrates step by step (its steps are
 * those the method's controller chooses; for CVODE, the Taylor methods and
 * the fixed-step methods, spans of the size a 4th-order method would take
 * first), and after each step [ta, tb] it looks for sign changes of each g on
 * a continuous extension of the step. First a screen: the cubic Hermite
 * interpolant of the step's ends, whose error is estimated from its defect
 * (one evaluation of the system); a step where no g comes near 0 on it, by a
 * margin of that error, or changes sign only in a direction not asked for,
 * costs nothing more. Other steps get the quintic Hermite interpolant of the
 * states and derivatives at the step's start, middle and end (the middle
 * state integrated from the start, which costs about a step more), sampled
 * at SICM_ODE_EVENT_SAMPLES equal sub-intervals, so that two crossings in
 * one step are both found. Each sign change is placed by Brent's method, first
 * on the interpolant, then on the solution itself: each trial time is
 * reached by integrating from the step's start, or from the last trial if
 * nearer (a method with its own continuous output, the Taylor methods,
 * is asked for one step at a time and its polynomial stands for the
 * interpolant and for the solution both), with the same method and
 * tolerances, so a located event is as accurate as the integration (the
 * interpolant only brackets it), to a few ulps of the time since the
 * step's start (the trial integrations run in that time, so the state at
 * a crossing late in a long run is on it to the resolution of the step,
 * not of t). Where the solution does not change sign as the interpolant
 * does, the solution itself is sampled; if it does not change sign there
 * either, there is no event (a graze of the interpolant's making).
 *
 * The located events of a step are handled in time order: the handler, if
 * any, gets the event's index, time and state; it returns 0 to go on, or
 * non-zero to stop there as a terminal event does. When an event stops the
 * integration, sicm_ode_evolve returns SICM_SUCCESS with *t and y at the
 * event (*t != t1 then) and sicm_ode_stopping_event says which.
 *
 * g returns its value; a NaN or infinity fails the evolve with
 * SICM_EBADFUNC naming the event's index. */
typedef double (*sicm_ode_event_function)(double t, const double *y, void *params);

enum { SICM_ODE_EVENT_UP = 1, SICM_ODE_EVENT_DOWN = 2, SICM_ODE_EVENT_BOTH = 3 };
enum { SICM_ODE_EVENT_SAMPLES = 8 };

typedef struct {
  sicm_ode_event_function g;
  void *params;
  int direction; /* SICM_ODE_EVENT_UP, _DOWN or _BOTH */
  int terminal;  /* non-zero: the integration stops at the event */
} sicm_ode_event;

typedef int (*sicm_ode_event_handler)(size_t event, double t, const double *y, void *data);

/* sicm_ode_set_events gives o its events (n of them; n = 0 removes them),
 * copied, and the handler of located events (NULL: none) with its data.
 * Returns SICM_SUCCESS, SICM_EINVAL (a NULL g, a bad direction) or
 * SICM_ENOMEM. */
int sicm_ode_set_events(sicm_ode *o, const sicm_ode_event *events, size_t n,
                        sicm_ode_event_handler handler, void *data);

/* sicm_ode_stopping_event returns the index of the event that stopped the
 * last sicm_ode_evolve, or -1 if it ran to t1 (or failed). */
long sicm_ode_stopping_event(const sicm_ode *o);

/* sicm_ode_event_stats: events located since the object was made, and the
 * trial times their placement on the solution cost (each an integration
 * from a step's start). */
typedef struct {
  unsigned long located;
  unsigned long iterations;
  unsigned long screened; /* steps the cubic screen found free of events */
} sicm_ode_event_stats;
const sicm_ode_event_stats *sicm_ode_get_event_stats(const sicm_ode *o);

/* sicm_ode_set_singularity_probe names the cause when an integration
 * fails at a singularity of its equations (a collision, coordinates that
 * are singular there). probe(y, values, params) computes n quantities the
 * system derivative divides by, at the state y; texts[k] says what
 * values[k] is, e.g. "(sin (ref state 1 0))" (the compiler makes both from
 * the derivative's code). When a step fails (step size too small, a
 * non-finite derivative, a singular matrix), the message names the
 * quantity that has shrunk most, relative to its value where the evolve
 * call began, if it has shrunk by a factor of a thousand or more: at the
 * last state where the derivative failed, or else at the state reported.
 * params and texts must outlive o. Returns SICM_ENOMEM or SICM_SUCCESS. */
typedef void (*sicm_ode_probe)(const double *y, double *values, const double *params);
int sicm_ode_set_singularity_probe(sicm_ode *o, sicm_ode_probe probe, const double *params,
                                   size_t n, const char *const *texts);

/* sicm_ode_set_taylor gives sicm_ode_step_taylor its coefficient function:
 * coefficients(y, order, c, params) stores in c[k * dim + i] the k-th
 * normalized Taylor coefficient y_i^(k) / k! of the solution through the
 * state y, for k = 0..order (c[i] = y[i]); order is at most
 * SICM_ODE_TAYLOR_MAX_ORDER. The system must be autonomous (time, if it
 * matters, one of the components of y): the coefficients do not depend on
 * the integrator's t. params must outlive o. Without a coefficient function
 * the taylor method's evolve fails with SICM_EINVAL; the other methods
 * ignore it. Returns SICM_SUCCESS. */
#define SICM_ODE_TAYLOR_MAX_ORDER 40
typedef void (*sicm_ode_taylor_coefficients)(const double *y, int order, double *c,
                                             const double *params);
int sicm_ode_set_taylor(sicm_ode *o, sicm_ode_taylor_coefficients coefficients,
                        const double *params);

/* The order both Taylor methods expand to under the tolerances abs_tol and
 * rel_tol (the smaller nonzero one, eps: ceil(-ln(eps) / 2) + 1, after Jorba
 * and Zou, within 2..SICM_ODE_TAYLOR_MAX_ORDER): the order their coefficient
 * functions are called with. */
int sicm_ode_taylor_order(double abs_tol, double rel_tol);

/* sicm_ode_set_taylor_extended gives sicm_ode_step_taylor_extended its
 * coefficient function, as sicm_ode_set_taylor but in long double (params
 * stay double: they are the program's run-time values). Returns
 * SICM_SUCCESS. */
typedef void (*sicm_ode_taylor_extended_coefficients)(const long double *y, int order,
                                                      long double *c, const double *params);
int sicm_ode_set_taylor_extended(sicm_ode *o, sicm_ode_taylor_extended_coefficients coefficients,
                                 const double *params);

/* sicm_ode_set_horizon tells the integrator that the caller will go on
 * calling sicm_ode_evolve towards t_end (a loop that stops every dt to
 * monitor the state): the stiffness watch then judges the work left to
 * t_end, not to the end of the current call. */
void sicm_ode_set_horizon(sicm_ode *o, double t_end);

/* ---- the monitor schedule of evolve -----------------------------------
 * evolve calls its monitor at the initial state and then every |dt| towards
 * t_final, the last interval shortened to end exactly there. Both sicm run
 * and built programs walk these times, so both stop at the same bits.
 *
 * sicm_monitor_schedule_start fills s for an integration from t0; it
 * returns NULL, or the reason these arguments make no schedule (a step of
 * 0 towards another time). sicm_monitor_schedule_next stores in *tk the
 * next time after t (the time the integration has reached) and returns 1,
 * or returns 0 once t is t_final. */
typedef struct {
  double t0, step, t_final, near_end;
  long k;
} sicm_monitor_schedule;
const char *sicm_monitor_schedule_start(sicm_monitor_schedule *s, double t0, double dt,
                                        double t_final);
int sicm_monitor_schedule_next(sicm_monitor_schedule *s, double t, double *tk);

/* sicm_ode_reset makes the next sicm_ode_evolve start afresh: the step size is
 * chosen again and multistep history is discarded. Statistics are kept. */
void sicm_ode_reset(sicm_ode *o);

/* sicm_ode_get_stats returns the object's statistics; the pointer stays
 * valid until sicm_ode_free and its contents change with each evolve. */
const sicm_ode_stats *sicm_ode_get_stats(const sicm_ode *o);

/* sicm_ode_last_error returns the message of the last failed
 * sicm_ode_evolve, or "" if none has failed. The string is owned by o and
 * overwritten by the next failure. */
const char *sicm_ode_last_error(const sicm_ode *o);

/* sicm_ode_name returns the name of o's step type. */
const char *sicm_ode_name(const sicm_ode *o);

/* ---- symplectic integrators for separable Hamiltonians -------------------
 * For H(t, q, p) = T(p) + V(t, q) with ndof degrees of freedom, these
 * fixed-step methods are symplectic, time-reversible, and conserve the energy
 * of autonomous systems up to a bounded oscillation (no secular drift) over
 * very long times, which adaptive methods do not.
 *
 * sicm_force stores dV/dq at (t, q) in dVdq[0..ndof-1]; sicm_velocity stores
 * dT/dp at p in dTdp[0..ndof-1] (T must not depend on t or q). Both return 0,
 * or non-zero to stop the integration (SICM_EUSER).
 *
 * The methods are compositions of the Stormer-Verlet ("leapfrog",
 * kick-drift-kick) map S(h):
 *
 *   sicm_symplectic_verlet    S(h), order 2; one force evaluation per step.
 *   sicm_symplectic_yoshida4  S(w1 h) S(w0 h) S(w1 h) with Yoshida's triple-jump
 *                             weights w1 = 1/(2 - 2^(1/3)), w0 = 1 - 2 w1;
 *                             order 4; 3 force evaluations per step.
 *   sicm_symplectic_yoshida6  Yoshida (1990) solution A, 7 stages; order 6.
 *   sicm_symplectic_yoshida8  Yoshida (1990) solution A, 15 stages; order 8.
 *
 * Time dependence of V is handled exactly in the sense of the extended phase
 * space: t advances with the drifts, so the orders above hold for V(t, q)
 * too. */
typedef int (*sicm_force)(double t, const double *q, double *dVdq, void *params);
typedef int (*sicm_velocity)(const double *p, double *dTdp, void *params);

typedef struct sicm_symplectic_type sicm_symplectic_type;

extern const sicm_symplectic_type *const sicm_symplectic_verlet;
extern const sicm_symplectic_type *const sicm_symplectic_yoshida4;
extern const sicm_symplectic_type *const sicm_symplectic_yoshida6;
extern const sicm_symplectic_type *const sicm_symplectic_yoshida8;

/* sicm_symplectic_name returns "verlet", "yoshida4", "yoshida6" or "yoshida8";
 * sicm_symplectic_order returns the method's order of accuracy. */
const char *sicm_symplectic_name(const sicm_symplectic_type *T);
int sicm_symplectic_order(const sicm_symplectic_type *T);

/* sicm_symplectic_evolve advances (q, p) from *t to exactly t1 with n equal
 * steps, n the smallest number of steps of size at most |h| that covers
 * |t1 - *t| (so the step is exactly h when h divides the interval; the sign of
 * h is ignored, the direction is that of t1 - *t). On success *t = t1. On
 * failure (a callback returned non-zero, or q or p became non-finite) it
 * returns non-zero, leaves *t, q and p at the last completed step, and
 * reports a message naming the time and the state through the error hook.
 * h must be finite and non-zero. */
int sicm_symplectic_evolve(const sicm_symplectic_type *T, size_t ndof, sicm_force dVdq,
                           sicm_velocity dTdp, void *params, double *t, double t1, double h,
                           double *q, double *p);

#ifdef __cplusplus
}
#endif

#endif /* SICM_ODE_H */
