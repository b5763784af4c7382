// User-facing errors: one exception type, one reporter.
//
// Errors a user can cause are thrown as sicm::Error with a location and a
// message, and printed by report_error() as
//     file:line:col: error: message
//         the source line
//             ^
// Broken internal invariants are not Errors: they abort (see SICM_ASSERT).
// Code that catches an Error to retry, fall back or read on decides by its
// cause (ErrorCause), never by its message, which is for people.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "base/srcloc.hpp"

namespace sicm {

enum class ErrorKind {
  Syntax,  // reader and special-form errors, unknown identifiers: exit 65
  Runtime, // errors while evaluating: exit 70
};

// What an error means to the code that catches it. Set where the error is
// raised; the message may be reworded freely.
enum class ErrorCause : uint8_t {
  Other,           // an ordinary error of the program
  CannotCompile,   // sicm build cannot leave this for run time ("cannot compile: ...";
                   // pe/build_mode.cpp): a caller may try another way
  Limit,           // a named limit of base/limits.hpp (steps, memory, expression nodes,
                   // recursion depth, residual size) was hit
  Interrupted,     // Ctrl-C (base/limits.hpp): nothing may swallow it
  IncompleteInput, // the reader ran out of text inside a datum: the REPL reads another line
};

// Exit statuses, following sysexits.h as compilers do.
constexpr int kExitCompileError = 65; // EX_DATAERR
constexpr int kExitRuntimeError = 70; // EX_SOFTWARE

// Is the program being compiled at its top level, outside every procedure
// traced for run time and every alternative of a run-time test? sicm build
// answers (pe/build_mode.cpp) while it lives; null otherwise. An error
// raised there is certain to happen when the program runs, at that point
// of it: the build makes it the program's failure (driver/pipeline.cpp).
using TopLevelProbe = bool (*)();
void set_top_level_probe(TopLevelProbe probe);
bool raised_at_top_level();

// The note of every "cannot compile" error. The driver adds what `sicm run`
// does with the program (driver/run_check.hpp): it says "`sicm run`
// interprets this program" only where it does.
inline constexpr const char *kCannotCompileNote =
    "sicm build leaves only numerical work for run time";

struct Error : std::runtime_error {
  ErrorKind kind;
  ErrorCause cause = ErrorCause::Other;
  SrcLoc loc;
  std::string note;                          // optional extra line (e.g. "did you mean ...")
  bool at_top_level = raised_at_top_level(); // of a program sicm build compiles
  Error(ErrorKind k, SrcLoc l, std::string msg, std::string n = {})
      : std::runtime_error(std::move(msg)), kind(k), loc(l), note(std::move(n)) {}
  Error(ErrorKind k, ErrorCause c, SrcLoc l, std::string msg, std::string n = {})
      : std::runtime_error(std::move(msg)), kind(k), cause(c), loc(l), note(std::move(n)) {}
  int exit_code() const {
    return kind == ErrorKind::Syntax ? kExitCompileError : kExitRuntimeError;
  }
};

[[noreturn]] void syntax_error(SrcLoc loc, const std::string &msg);
[[noreturn]] void runtime_error(SrcLoc loc, const std::string &msg);

// Where evaluation is, for errors raised outside the evaluator's loop:
// the call being evaluated (for errors raised by primitives), and where the
// top-level form being run starts. The evaluator keeps both (eval/eval.cpp,
// eval/interp.cpp).
SrcLoc current_call_loc();
SrcLoc current_toplevel_loc();

// Print an error in compiler style on stream f (the source line and a caret
// when the location is known).
void report_error(std::FILE *f, const Error &e);
std::string format_error(const Error &e);

[[noreturn]] void internal_failure(const char *file, int line, const char *what);
#define SICM_ASSERT(cond)                                                                          \
  do {                                                                                             \
    if (!(cond)) ::sicm::internal_failure(__FILE__, __LINE__, #cond);                              \
  } while (0)

} // namespace sicm
