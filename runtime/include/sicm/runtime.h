/* sicm runtime library (libsicmrt): the one public header.
 *
 * C11, every symbol prefixed sicm_. Generated programs and the compiler link
 * against it. Functions are grouped by module; each group says what it
 * provides. */
#ifndef SICM_RUNTIME_H
#define SICM_RUNTIME_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- number printing --------------------------------------------------
 * The one implementation of flonum printing, shared by the compiler (for
 * values known at compile time) and by generated programs (for values
 * computed at run time), so both print identically.
 *
 * sicm_format_double writes x in MIT Scheme's form: the shortest digit
 * string that reads back as x, laid out as MIT does ("435.", ".75",
 * "-1.5987211554602254e-14", "1e21", "+inf.0", "-inf.0", "+nan.0", "0.",
 * "-0."). buf must hold at least SICM_DOUBLE_BUFSIZE bytes. Returns the
 * length written (not counting the terminating NUL). */
#define SICM_DOUBLE_BUFSIZE 40
size_t sicm_format_double(char *buf, double x);

/* sicm_shortest_digits stores in digits (>= 18 bytes) the shortest decimal
 * digit string d1 d2 ... dn (no sign, no point, no trailing zeros) such that
 * 0.d1d2...dn * 10^(*exponent10 + 1) read back gives |x|, i.e. |x| is
 * d1.d2...dn * 10^(*exponent10). x must be finite and non-zero. Returns n. */
size_t sicm_shortest_digits(char *digits, int *exponent10, double x);

#ifdef __cplusplus
}
#endif

#endif /* SICM_RUNTIME_H */
