/* sicm runtime: status codes and the one error hook shared by every numerical module. */
#ifndef SICM_ERROR_H
#define SICM_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes returned by the numerical functions of the runtime (ODE
 * integrators, minimizers, root finders, quadrature). Zero is success;
 * every failure is a distinct positive code, so callers can test
 * `status != SICM_SUCCESS` and still tell the causes apart. */
enum {
  SICM_SUCCESS = 0,
  SICM_EINVAL = 1,     /* an argument is invalid (bad interval, dimension, tolerance) */
  SICM_ENOMEM = 2,     /* memory could not be allocated */
  SICM_EBADFUNC = 3,   /* a user function produced a non-finite value (NaN or infinity) */
  SICM_EUSER = 4,      /* a user function returned non-zero to stop the computation */
  SICM_ESTEP = 5,      /* the step size became too small to make progress */
  SICM_EMAXITER = 6,   /* the allowed number of steps or iterations was exhausted */
  SICM_ETOL = 7,       /* the requested tolerance cannot be reached */
  SICM_EBRACKET = 8,   /* the interval does not bracket a root */
  SICM_ECONV = 9,      /* an inner iteration (Newton, linear solve) failed to converge */
  SICM_EFAILED = 10,   /* any other failure of an underlying library */
  SICM_ESINGULAR = 11, /* a linear solve in a user function met a singular matrix */
  SICM_ESTIFF = 12     /* stiff: stability, not accuracy, holds an explicit method's step */
};

/* The NaN that a compiled kernel writes into every output when a linear
 * solve in it met a singular matrix (or, for a symmetric one such as a mass
 * matrix, one that is not positive definite): its bits. An integrator that
 * receives it from the system derivative stops with SICM_ESINGULAR and says
 * so with the time and the state, where any other NaN would make it retry
 * with a shorter step. */
#define SICM_SINGULAR_NAN_BITS 0x7ff800005349474eULL

/* sicm_is_singular_nan says whether x is that NaN. */
int sicm_is_singular_nan(double x);

/* sicm_strerror returns a short constant English description of a status
 * code ("step size too small", ...), or "unknown status" for a code it does
 * not know. */
const char *sicm_strerror(int status);

/* The error hook. Every failure inside the runtime's numerical modules is
 * reported exactly once through the current handler, with a complete
 * message ("reason") naming the function and the cause, and the status the
 * function then returns. The handler is a notification: whatever it does,
 * the function still returns its status to the caller (the runtime never
 * aborts the process, and GSL's own abort-on-error handler is disabled while
 * runtime code runs).
 *
 * The default handler writes "sicm: REASON" and a newline to stderr. A
 * handler that wants silence simply does nothing. This handler is the only
 * global state of the numerical runtime; changing it while another thread
 * is inside the runtime is not supported.
 *
 * GSL's error handler is process-global too: runtime functions switch it off
 * on entry and restore the caller's on exit. A program that calls the
 * runtime from several threads at once should call gsl_set_error_handler_off
 * once at start-up, so that no thread can see GSL's aborting default. */
typedef void sicm_error_handler_t(const char *reason, int status);

/* sicm_set_error_handler installs handler (NULL reinstates the default) and
 * returns the previous handler (NULL if it was the default). */
sicm_error_handler_t *sicm_set_error_handler(sicm_error_handler_t *handler);

/* sicm_error formats a reason from fmt and its arguments (printf
 * conventions), passes it with status to the current handler, and returns
 * status, so runtime code can write `return sicm_error(SICM_EINVAL, ...)`.
 * Reasons longer than 1023 bytes are truncated. */
int sicm_error(int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#ifdef __cplusplus
}
#endif

#endif /* SICM_ERROR_H */
