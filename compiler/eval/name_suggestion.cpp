// The name an unbound variable most likely meant (see name_suggestion.hpp).
#include "eval/name_suggestion.hpp"

#include <algorithm>
#include <cctype>

namespace sicm {

namespace {

size_t edit_distance(const std::string &a, const std::string &b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j)
    prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

// A word has a letter or a digit in it (square, L-pendulum, m:transpose);
// an operator has none (*, <=, ->).
bool is_word(const std::string &name) {
  return std::any_of(name.begin(), name.end(),
                     [](unsigned char c) { return std::isalnum(c) != 0; });
}

} // namespace

std::string suggested_name(const std::string &name, const std::vector<std::string> &known) {
  if (name.size() < 3) return "";
  // A third of the name's length, at least one edit.
  size_t best_d = std::max<size_t>(1, name.size() / 3) + 1;
  std::string best;
  for (const std::string &k : known) {
    if (is_word(k) != is_word(name)) continue;
    size_t d = edit_distance(name, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

} // namespace sicm
