// (parameter 'name default): a number (a flonum) the user may set from the command line.
//
// `sicm run prog.sicm --param name=value` and `./prog --param name=value`
// (an executable made by sicm build) both give `value`; without the option
// the default. In a built program the value stays a run-time value, so a
// parameter sweep reuses one executable instead of compiling once per value
// (pe/build_mode.cpp rebinds `parameter`).
#include <algorithm>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "builtins/parameter.hpp"

namespace sicm {

namespace {

std::map<std::string, double> g_given; // from --param, by name
std::map<std::string, double> g_fixed; // from --fix (sicm build), by name
std::vector<std::string> g_declared;   // the program's parameters, in declaration order

// NAME=VALUE, VALUE a real number in C syntax; the option's name for messages.
bool parse_assignment(const std::string &assignment, const char *option, std::string *name,
                      double *x, std::string *why_not) {
  size_t eq = assignment.find('=');
  if (eq == 0 || eq == std::string::npos) {
    *why_not = std::string(option) + " wants NAME=VALUE, not '" + assignment + "'";
    return false;
  }
  std::string value = assignment.substr(eq + 1);
  char *end = nullptr;
  *x = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0') {
    *why_not = std::string(option) + " " + assignment + ": '" + value + "' is not a number";
    return false;
  }
  *name = assignment.substr(0, eq);
  return true;
}

Value P_parameter(Value *a, int) {
  if (!is_symbol(a[0])) wrong_type(a[0], 1, "parameter");
  if (!is_number(a[1])) wrong_type(a[1], 2, "parameter");
  declare_parameter(symbol_name(a[0]));
  auto it = g_given.find(symbol_name(a[0]));
  // Always a flonum, as a built program's run-time value is.
  return Value::flonum(it == g_given.end() ? to_double(a[1]) : it->second);
}

} // namespace

bool set_parameter_option(const std::string &assignment, std::string *why_not) {
  std::string name;
  double x;
  if (!parse_assignment(assignment, "--param", &name, &x, why_not)) return false;
  g_given[name] = x;
  return true;
}

bool fix_parameter_option(const std::string &assignment, std::string *why_not) {
  std::string name;
  double x;
  if (!parse_assignment(assignment, "--fix", &name, &x, why_not)) return false;
  g_fixed[name] = x;
  return true;
}

bool fixed_parameter(const std::string &name, double *value) {
  auto it = g_fixed.find(name);
  if (it == g_fixed.end()) return false;
  *value = it->second;
  return true;
}

void declare_parameter(const std::string &name) {
  if (std::find(g_declared.begin(), g_declared.end(), name) == g_declared.end())
    g_declared.push_back(name);
}

std::string undeclared_parameter_error() {
  for (const auto *given : {&g_given, &g_fixed}) {
    for (const auto &[name, value] : *given) {
      if (std::find(g_declared.begin(), g_declared.end(), name) != g_declared.end()) continue;
      std::string known;
      for (const std::string &d : g_declared)
        known += (known.empty() ? "" : ", ") + d;
      return std::string(given == &g_given ? "--param " : "--fix ") + name +
             "=...: the program declares no parameter " + name +
             (known.empty() ? " (it declares none)" : " (its parameters: " + known + ")");
    }
  }
  return "";
}

void install_parameter_primitives() {
  define_primitive("parameter", 2, 2, Stage::RunTime, P_parameter);
}

} // namespace sicm
