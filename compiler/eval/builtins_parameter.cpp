// (parameter 'name default): a number (a flonum) the user may set from the command line.
//
// `sicm run prog.sicm --param name=value` and `./prog --param name=value`
// (an executable made by sicm build) both give `value`; without the option
// the default. In a built program the value stays a run-time value, so a
// parameter sweep reuses one executable instead of compiling once per value
// (builtins_build.cpp rebinds `parameter`).
#include <cstdlib>
#include <map>
#include <string>

#include "eval/number.hpp"
#include "eval/parameter.hpp"
#include "eval/primitive.hpp"

namespace sicm {

namespace {

std::map<std::string, double> g_given; // from --param, by name

Value P_parameter(Value *a, int) {
  if (!is_symbol(a[0])) wrong_type(a[0], 1, "parameter");
  if (!is_number(a[1])) wrong_type(a[1], 2, "parameter");
  auto it = g_given.find(symbol_name(a[0]));
  // Always a flonum, as a built program's run-time value is.
  return Value::flonum(it == g_given.end() ? to_double(a[1]) : it->second);
}

} // namespace

bool set_parameter_option(const std::string &assignment, std::string *why_not) {
  size_t eq = assignment.find('=');
  if (eq == 0 || eq == std::string::npos) {
    *why_not = "--param wants NAME=VALUE, not '" + assignment + "'";
    return false;
  }
  std::string value = assignment.substr(eq + 1);
  char *end = nullptr;
  double x = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0') {
    *why_not = "--param " + assignment + ": '" + value + "' is not a number";
    return false;
  }
  g_given[assignment.substr(0, eq)] = x;
  return true;
}

void install_parameter_primitives() {
  define_primitive("parameter", 2, 2, P_parameter);
}

} // namespace sicm
