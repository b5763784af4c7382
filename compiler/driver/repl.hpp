// The read-eval-print loop of `sicm repl` (see repl.cpp for how it works).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace sicm {

struct ReplOptions {
  bool interactive = false; // stdin is a terminal: readline, prompts, history
  std::string history_file; // "" = $SICM_HISTORY, else ~/.sicm_history
};

// Read forms from stdin, evaluate them in the global environment and print
// their values MIT style, until end of input. Call after init_interpreter(),
// on the evaluator thread. Returns the exit status (0).
int run_repl(const ReplOptions &options);

// The names a completion of `prefix` offers, sorted: those bound in the
// global environment and the special-form keywords (the library's %-helpers
// only when the prefix starts with %). Tab in the REPL, complete requests
// of `sicm repl --kernel`.
std::vector<std::string> completions(std::string_view prefix);

} // namespace sicm
