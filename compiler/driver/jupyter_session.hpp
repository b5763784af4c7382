// `sicm repl --kernel`: one sicm session driven by a Jupyter kernel, over the
// protocol of driver/jupyter_protocol.hpp (see jupyter_session.cpp for how it works).
#pragma once

#include <string>

namespace sicm {

struct JupyterOptions {
  // Where the session's plots are written before they are sent; "" = a
  // fresh directory under $TMPDIR, removed at the end of the session.
  std::string plot_dir;
};

// Answer requests on stdin until end of input. Call after
// init_interpreter(), on the evaluator thread. Returns the exit status.
int run_jupyter_session(const JupyterOptions &options);

} // namespace sicm
