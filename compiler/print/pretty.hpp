// The pretty-printer of pp: a value's written form
// broken into lines of at most `width` characters as MIT Scheme's pp breaks
// data and expressions:
//   - a list that fits on the rest of its line is written there;
//   - else, when its head is an atom and every argument fits flat after
//     "(head ", the arguments are stacked in that column (standard style):
//       (* -2
//          g
//          (expt l1 3))
//   - else the head stands alone and every element goes on its own line one
//     column in, laid out again by these rules (columnar style):
//       (/
//        (+ ...)
//        (+ ...))
//   - define, lambda, named-lambda and the let forms keep their header
//     (name and parameters, bindings) on the first line and indent their
//     body by two.
// A closing parenthesis counts against the line of the last element it
// closes. The layout works on the written text (strings, characters and
// #[...] objects are atoms), so it applies to any value.
#pragma once

#include <string>

#include "base/value.hpp"

namespace sicm {

constexpr int kPrettyWidth = 78; // MIT's pp: no line longer than this

std::string pretty_string(Value v, int width = kPrettyWidth);

// The same layout of text that is already a written form.
std::string pretty_text(const std::string &written, int width = kPrettyWidth);

} // namespace sicm
