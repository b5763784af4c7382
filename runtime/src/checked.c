/* The program's own arithmetic where the interpreter would not give a real
 * number: division by zero and results in the complex plane fail at the
 * call, as `sicm run` raises an error (or computes a complex number, which
 * compiled code cannot hold) instead of going on with an infinity or a NaN.
 * Kernels (state derivatives, objective functions) do not call these: there
 * a NaN is what the integrators and minimizers already watch for. */
#include <math.h>
#include <stdio.h>

#include "sicm/runtime.h"

static _Noreturn void division_by_zero(const sicm_site *site, const char *who) {
  char reason[64];
  snprintf(reason, sizeof reason, "Division by zero signalled by %s.", who);
  sicm_program_fail(site, NULL, reason);
}

static _Noreturn void complex_result(const sicm_site *site, const char *who, double x) {
  char number[SICM_DOUBLE_BUFSIZE], reason[160 + SICM_DOUBLE_BUFSIZE];
  number[sicm_format_double(number, x)] = '\0';
  snprintf(reason, sizeof reason,
           "the result for %s is a complex number, and compiled code computes with real "
           "numbers (sicm run computes it)",
           number);
  sicm_program_fail(site, who, reason);
}

double sicm_checked_quotient(const sicm_site *site, const char *who, double a, double b) {
  if (b == 0) division_by_zero(site, who);
  return a / b;
}

double sicm_checked_sqrt(const sicm_site *site, double x) {
  if (x < 0) complex_result(site, "sqrt", x);
  return sqrt(x);
}

double sicm_checked_log(const sicm_site *site, double x) {
  if (x < 0) complex_result(site, "log", x);
  if (x == 0) division_by_zero(site, "log");
  return log(x);
}

double sicm_checked_asin(const sicm_site *site, double x) {
  if (x < -1 || x > 1) complex_result(site, "asin", x);
  return asin(x);
}

double sicm_checked_acos(const sicm_site *site, double x) {
  if (x < -1 || x > 1) complex_result(site, "acos", x);
  return acos(x);
}

double sicm_checked_pow(const sicm_site *site, double x, double y) {
  if (x < 0 && isfinite(y) && y != floor(y)) complex_result(site, "expt", x);
  if (x == 0 && y < 0) division_by_zero(site, "expt");
  return pow(x, y);
}
