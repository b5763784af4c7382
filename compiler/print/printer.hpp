// Printing values the way MIT Scheme prints them: `write` form (strings
// quoted, characters as #\a) and `display` form.
#pragma once

#include <string>

#include "eval/value.hpp"

namespace sicm {

void print_value(std::string &out, Value v, bool display);
std::string write_string(Value v);
std::string display_string(Value v);

} // namespace sicm
