// Parameters set from the command line: (parameter 'name default).
#pragma once

#include <string>

namespace sicm {

// Record `--param NAME=VALUE` (VALUE a real number in C syntax). False and
// a reason for anything else.
bool set_parameter_option(const std::string &assignment, std::string *why_not);

// Record `--fix NAME=VALUE` for sicm build: the parameter becomes the
// compile-time constant VALUE (terms it zeroes fold away) instead of a
// run-time input. False and a reason for a malformed assignment.
bool fix_parameter_option(const std::string &assignment, std::string *why_not);

// The value --fix gave the parameter `name`, if it did.
bool fixed_parameter(const std::string &name, double *value);

// Note that the program declares the parameter `name` ((parameter 'name
// default) was evaluated, in sicm run or in sicm build).
void declare_parameter(const std::string &name);

// After the program: "" if every --param and --fix names a parameter it
// declared, else the error, naming the first such option and the
// parameters the program has (as the executables of sicm build refuse an
// unknown --param).
std::string undeclared_parameter_error();

// (parameter name default). Called by init_interpreter.

} // namespace sicm
