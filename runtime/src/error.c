/* The runtime's one error hook and the descriptions of its status codes. */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "sicm/runtime.h"

/* The only global state of the numerical runtime (see sicm/error.h). NULL
 * means the default handler. */
static sicm_error_handler_t *current_handler;

static void default_handler(const char *reason, int status) {
  (void)status;
  fprintf(stderr, "sicm: %s\n", reason);
}

sicm_error_handler_t *sicm_set_error_handler(sicm_error_handler_t *handler) {
  sicm_error_handler_t *previous = current_handler;
  current_handler = handler;
  return previous;
}

int sicm_error(int status, const char *fmt, ...) {
  char reason[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(reason, sizeof reason, fmt, ap);
  va_end(ap);
  (current_handler ? current_handler : default_handler)(reason, status);
  return status;
}

const char *sicm_strerror(int status) {
  switch (status) {
  case SICM_SUCCESS: return "success";
  case SICM_EINVAL: return "invalid argument";
  case SICM_ENOMEM: return "out of memory";
  case SICM_EBADFUNC: return "function value is not finite";
  case SICM_EUSER: return "stopped by a user function";
  case SICM_ESTEP: return "step size too small";
  case SICM_EMAXITER: return "too many steps or iterations";
  case SICM_ETOL: return "tolerance cannot be reached";
  case SICM_EBRACKET: return "root not bracketed";
  case SICM_ECONV: return "convergence failure";
  case SICM_EFAILED: return "failure in a numerical library";
  case SICM_ESINGULAR: return "singular matrix in a linear solve";
  case SICM_ESTIFF: return "stiff system: use an implicit method";
  }
  return "unknown status";
}

int sicm_is_singular_nan(double x) {
  uint64_t bits;
  memcpy(&bits, &x, sizeof bits);
  return bits == SICM_SINGULAR_NAN_BITS;
}
