// `sicm repl --kernel`: the REPL a Jupyter kernel drives (jupyter_session.hpp).
//
// The session is the REPL's: one global environment for the whole session,
// so definitions live from cell to cell, and each form gets fresh step and
// expression budgets. What differs is the framing. A cell arrives whole, so
// all of its forms are read before any is evaluated (a syntax error anywhere
// runs nothing, as in Python's kernel), and the forms then run in order
// until one fails. Every output is a message of jupyter_protocol.hpp:
// program output is collected by the output hook and sent as stream text;
// values are sent as text/plain and, when symbolic, as TeX in the book's
// dot notation; plots are written into a directory of the session's own and
// every SVG that appears there (a frame closed by graphics-close) is sent
// and removed after each form.
//
// Interrupts. The kernel sends SIGINT to interrupt a cell. Our handler only
// asks the evaluator to stop (base/limits.hpp), so the cell ends with an
// "Interrupted" error and the session lives on. The plot library installs a
// SIGINT handler of its own the first time a plot is opened, which finishes
// the plots and exits (right for `sicm run`, fatal for a session): so at
// start a plot is opened and finished once, which installs that handler
// before ours, and ours then stays for the whole session.
#include "driver/jupyter_session.hpp"

#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <new>
#include <sstream>
#include <vector>

#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/error.hpp"
#include "base/limits.hpp"
#include "base/temporary_files.hpp"
#include "builtins/plot.hpp"
#include "driver/jupyter_protocol.hpp"
#include "driver/repl.hpp"
#include "eval/core.hpp"
#include "eval/interp.hpp"
#include "print/infix.hpp"
#include "print/printer.hpp"
#include "sicm/runtime.h"
#include "syntax/reader.hpp"

namespace sicm {

namespace {

std::FILE *g_out = nullptr; // the protocol's stream: the process's first stdout

// ---- program output as stream messages ---------------------------------------

// Output is sent in pieces: at the end of each form, and meanwhile when a
// line ends and kStreamInterval has passed, so a long run shows progress
// without a message per `display`.
constexpr auto kStreamInterval = std::chrono::milliseconds(100);
constexpr size_t kStreamMaxBytes = 64 * 1024;

std::string g_pending_output;
std::chrono::steady_clock::time_point g_last_sent;

void send_output() {
  if (g_pending_output.empty()) return;
  write_jupyter_message(g_out, json_object({{"type", json_string("stream")},
                                            {"name", json_string("stdout")},
                                            {"text", json_string(g_pending_output)}}));
  g_pending_output.clear();
  g_last_sent = std::chrono::steady_clock::now();
}

void collect_output(std::string_view s) {
  g_pending_output += s;
  bool line_ended = s.find('\n') != std::string_view::npos;
  if (g_pending_output.size() >= kStreamMaxBytes ||
      (line_ended && std::chrono::steady_clock::now() - g_last_sent >= kStreamInterval))
    send_output();
}

// ---- values, errors and plots as messages ------------------------------------

bool shown_in_tex(Value v) {
  return is_expression(v) || is_structure(v) || is_matrix(v);
}

void send_result(Value v, bool last) {
  std::vector<std::pair<std::string, std::string>> data = {
      {"text/plain", json_string(write_string(v))}};
  if (shown_in_tex(v)) {
    try {
      data.push_back({"text/latex", json_string("$$" + value_to_tex(v) + "$$")});
    } catch (const Error &) { // no TeX for it: the text alone
    }
  }
  write_jupyter_message(g_out, json_object({{"type", json_string("result")},
                                            {"last", last ? "true" : "false"},
                                            {"data", json_object(data)}}));
}

std::vector<std::string> lines_of(const std::string &text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

const char *error_name(const Error &e) {
  if (e.cause == ErrorCause::Interrupted) return "Interrupted";
  if (e.cause == ErrorCause::Limit) return "LimitError";
  return e.kind == ErrorKind::Syntax ? "SyntaxError" : "Error";
}

// e, located in the cell `file` when it is there (line and col 0 otherwise).
void send_error(const Error &raw, uint32_t file) {
  Error e = as_users_error(raw);
  bool here = e.loc.known() && e.loc.file == file;
  write_jupyter_message(g_out,
                        json_object({{"type", json_string("error")},
                                     {"ename", json_string(error_name(e))},
                                     {"evalue", json_string(e.what())},
                                     {"line", std::to_string(here ? e.loc.line : 0)},
                                     {"col", std::to_string(here ? e.loc.col : 0)},
                                     {"traceback", json_strings(lines_of(format_error(e)))}}));
}

void send_internal_error(const std::string &what) {
  write_jupyter_message(
      g_out, json_object({{"type", json_string("error")},
                          {"ename", json_string("InternalError")},
                          {"evalue", json_string(what)},
                          {"line", "0"},
                          {"col", "0"},
                          {"traceback", json_strings({"sicm: internal error: " + what})}}));
}

std::string g_plot_dir;

// Every finished plot in the plot directory (NAME.svg; NAME.svg.tmp is one
// being written), sent in name order, then removed with its NAME.tsv.
void send_plots() {
  DIR *d = opendir(g_plot_dir.c_str());
  if (!d) return;
  std::vector<std::string> svgs;
  while (dirent *ent = readdir(d)) {
    std::string name = ent->d_name;
    if (name.size() > 4 && name.ends_with(".svg")) svgs.push_back(name);
  }
  closedir(d);
  std::sort(svgs.begin(), svgs.end());
  for (const std::string &name : svgs) {
    std::string path = g_plot_dir + "/" + name;
    std::ifstream in(path, std::ios::binary);
    std::stringstream svg;
    svg << in.rdbuf();
    write_jupyter_message(
        g_out, json_object({{"type", json_string("display")},
                            {"data", json_object({{"image/svg+xml", json_string(svg.str())}})}}));
    std::remove(path.c_str());
    std::remove((path.substr(0, path.size() - 4) + ".tsv").c_str());
  }
}

void send_done() {
  write_jupyter_message(g_out, json_object({{"type", json_string("done")}}));
}

// ---- requests ------------------------------------------------------------------

// Evaluate one form; false if it failed (the cell stops there).
bool run_form(const ReadForm &form, uint32_t file, bool last) {
  begin_evaluation(form.loc);
  bool ok = false;
  try {
    Value v = eval_toplevel(form.datum, form.loc);
    send_output();
    if (is_printable_toplevel(form.datum, v)) send_result(v, last);
    ok = true;
  } catch (const Error &e) {
    send_output();
    send_error(e, file);
  } catch (const std::bad_alloc &) {
    send_output();
    send_internal_error("out of memory");
  } catch (const std::exception &e) {
    send_output();
    send_internal_error(e.what());
  } catch (...) {
    send_output();
    send_internal_error("a non-local exit reached the top level");
  }
  send_plots();
  return ok;
}

void execute(const std::string &code, const std::string &name) {
  uint32_t file = register_source(name, code);
  gcvec<ReadForm> forms; // GC memory: the data must live until their turn
  try {
    Reader reader(file);
    for (ReadForm form; reader.next(form);)
      forms.push_back(form);
  } catch (const Error &e) {
    send_error(e, file);
    return;
  }
  for (size_t i = 0; i < forms.size(); ++i)
    if (!run_form(forms[i], file, i + 1 == forms.size())) return;
}

// ---- the session -----------------------------------------------------------------

void on_interrupt(int) {
  request_interrupt();
}

// Install the plot library's signal handlers (by opening and finishing a
// plot nobody sees), then ours for SIGINT, for the whole session.
void take_sigint() {
  const char *name = ".sicm-kernel-start";
  if (sicm_plot *p = sicm_plot_open(g_plot_dir.c_str(), name, nullptr, 0, 1, 0, 1)) {
    sicm_plot_free(p);
    std::remove((g_plot_dir + "/" + name + ".svg").c_str());
    std::remove((g_plot_dir + "/" + name + ".tsv").c_str());
  }
  struct sigaction sa {};
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
}

// The protocol keeps the process's stdout; fd 1 becomes stderr, so that
// anything else written to stdout reaches the kernel as stderr text.
bool take_stdout() {
  int fd = dup(1);
  if (fd < 0 || !(g_out = fdopen(fd, "w"))) return false;
  std::fflush(stdout);
  return dup2(2, 1) >= 0;
}

// A fresh directory for the plots, or "" if none can be made.
std::string make_plot_dir() {
  std::string templ = temporary_directory() + "/sicm-kernel-XXXXXX";
  return mkdtemp(templ.data()) ? templ : "";
}

void remove_plot_dir(const std::string &dir) {
  if (DIR *d = opendir(dir.c_str())) {
    while (dirent *ent = readdir(d)) {
      std::string name = ent->d_name;
      if (name != "." && name != "..") std::remove((dir + "/" + name).c_str());
    }
    closedir(d);
  }
  rmdir(dir.c_str());
}

bool g_own_plot_dir = false;

// At exit, however it comes (end of input, or (exit) in a cell): the output
// not sent yet, and the plot directory if we made it. Registered after the
// plot library's own exit handler, so it runs first: the plots still open
// are finished here, into the directory, before it goes.
void end_session() {
  send_output();
  set_output_hook(nullptr);
  sicm_plot_close_all();
  if (g_own_plot_dir) remove_plot_dir(g_plot_dir);
}

} // namespace

int run_jupyter_session(const JupyterOptions &options) {
  if (!take_stdout()) {
    std::perror("sicm repl --kernel: stdout");
    return 1;
  }
  g_plot_dir = options.plot_dir.empty() ? make_plot_dir() : options.plot_dir;
  if (g_plot_dir.empty()) {
    std::perror("sicm repl --kernel: cannot make a directory for plots");
    return 1;
  }
  set_plot_directory(g_plot_dir);
  take_sigint();
  g_own_plot_dir = options.plot_dir.empty();
  std::atexit(end_session); // also when a cell calls (exit)
  set_output_hook(collect_output);
  set_dot_notation(true);
  write_jupyter_message(g_out, json_object({{"type", json_string("ready")}}));
  int cell = 0;
  for (JupyterRequest r; !(r = read_jupyter_request(stdin)).verb.empty();) {
    if (r.verb == "execute") {
      ++cell;
      execute(r.text, r.name.empty() ? "<cell-" + std::to_string(cell) + ">" : r.name);
    } else if (r.verb == "complete") {
      write_jupyter_message(g_out, json_object({{"type", json_string("matches")},
                                                {"matches", json_strings(completions(r.text))}}));
    }
    send_done();
  }
  return 0;
}

} // namespace sicm
