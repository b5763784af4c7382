// The errors of an integration about its system derivative (see
// integration_errors.hpp).
#include "builtins/integration_errors.hpp"

#include "print/printer.hpp"

namespace sicm {

void derivative_shape_error(SrcLoc loc, const char *who, Value derivative, Value state) {
  runtime_error(loc, std::string(who) + ": the system derivative returned " +
                         write_string(derivative) + " for the state " + write_string(state) +
                         "; it must be a structure of real numbers of the state's shape");
}

void taylor_refused(SrcLoc loc, const char *who, const char *method, TaylorRefusal why,
                    const std::string &operation) {
  std::string what;
  switch (why) {
  case TaylorRefusal::NotOneExpression:
    what = " needs a system derivative that is one expression of the state; this one tests the "
           "state or keeps values between calls";
    break;
  case TaylorRefusal::NoRecurrence:
    what = " needs a system derivative whose operations all have Taylor recurrences; this one "
           "has " +
           operation;
    break;
  case TaylorRefusal::KernelLimit:
    what = " needs a compiled system derivative; this one was not compiled "
           "(--max-compiled-kernels was reached)";
    break;
  }
  runtime_error(loc, std::string(who) + ": " + method + what + "; choose another integrator");
}

} // namespace sicm
