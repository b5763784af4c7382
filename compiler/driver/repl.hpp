// The read-eval-print loop of `sicm repl` (see repl.cpp for how it works).
#pragma once

#include <string>

namespace sicm {

struct ReplOptions {
  bool interactive = false; // stdin is a terminal: readline, prompts, history
  std::string history_file; // "" = $SICM_HISTORY, else ~/.sicm_history
};

// Read forms from stdin, evaluate them in the global environment and print
// their values MIT style, until end of input. Call after init_interpreter(),
// on the evaluator thread. Returns the exit status (0).
int run_repl(const ReplOptions &options);

} // namespace sicm
