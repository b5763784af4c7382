// For a program sicm build cannot compile: what `sicm run` does with it,
// found by running it, so that the build's message says "`sicm run`
// interprets this program" only where it does.
#pragma once

#include <string>

namespace sicm {

// Run `SELF run FILE` (this executable; its output and plots discarded)
// for at most `seconds`, and say what happened, for a note: "`sicm run`
// interprets this program", "`sicm run` fails on it too: FIRST LINE OF ITS
// ERROR", or that it ran that long without failing.
std::string what_sicm_run_does(const std::string &file, double seconds);

} // namespace sicm
