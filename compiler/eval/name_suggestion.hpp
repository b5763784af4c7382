// "Did you mean ...?" for an unbound variable: the known name a user most
// likely meant, or none.
#pragma once

#include <string>
#include <vector>

namespace sicm {

// The known name closest to `name` by edit distance, if it is close enough
// to be a slip of the fingers and of the same kind (a word for a word, an
// operator such as * or <= for an operator), else "". Names shorter than
// three characters get no suggestion: every other short name is one edit
// away (y is not a misspelt *, nor x).
std::string suggested_name(const std::string &name, const std::vector<std::string> &known);

} // namespace sicm
