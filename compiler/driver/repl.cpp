// The read-eval-print loop of `sicm repl`.
//
// The REPL reads text a line at a time and keeps the lines of an unfinished
// entry in a pending buffer. After each line it asks the real reader whether
// the buffer is finished: the buffer is registered as a source ("<repl-N>",
// so that error messages can quote it) and read form by form. Forms that
// read completely are evaluated at once, in order, and their values printed
// the way MIT Scheme prints them (";Value: 7", ";Value: x" for a definition,
// ";Unspecified return value"). If the reader stops because the text ends
// inside a datum (an open parenthesis, string or block comment), the buffer
// is kept, the next line is appended and the buffer is read again from the
// start, skipping the forms already evaluated. Any other reader error is
// reported and the buffer discarded. Using the reader itself as the judge of
// "finished" means the REPL can never disagree with it about strings,
// character literals or comments.
//
// Errors never end the loop: a sicm::Error (the limits of base/limits.hpp
// among them; each entry gets fresh step and expression budgets) is reported
// in compiler style on stderr, anything else as an internal error, and the
// next form is read.
// Program output goes through output() so that the REPL knows the column and
// can start its own lines on a fresh line.
//
// On a terminal, lines come from GNU readline, through its callback
// interface: the loop waits in select() on the terminal and on a self-pipe
// that the SIGINT and SIGWINCH handlers write to (the evaluator runs on a
// thread of its own, so a signal may well be delivered to another thread;
// the pipe wakes this one whichever thread gets it). Ctrl-C at a prompt
// throws away the entry being typed; during evaluation (on a terminal or
// not) it interrupts the evaluation, which ends with an "Interrupted" error,
// and the loop goes on with the next form. Tab completes the names bound in
// the global environment and the special-form keywords. History is loaded
// from the history file at start and each line is appended to it as soon as
// it is entered, so that a session killed by Ctrl-C keeps it; at exit the
// file is trimmed. When stdin is not a terminal the loop reads plain lines
// with no prompts, which makes it easy to drive from tests.
#include "driver/repl.hpp"

#include <fcntl.h>
#include <sys/select.h>
#include <unistd.h>

#include <readline/history.h>
#include <readline/readline.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <new>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "base/error.hpp"
#include "base/limits.hpp"
#include "eval/core.hpp"
#include "eval/interp.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

namespace sicm {

namespace {

const char kPrompt[] = "1 ]=> ";
const char kContinuationPrompt[] = "... ";

// ---- evaluating and printing ---------------------------------------------------

void fresh_line() {
  if (output_column() != 0) output("\n");
}

void say(const std::string &line) {
  fresh_line();
  output(line);
  output("\n");
}

// A definition evaluates to the symbol it defines, which MIT prints too.
void print_result(Value datum, Value v) {
  if (is_printable_toplevel(datum, v) || v.is(Tag::Symbol))
    say(";Value: " + write_string(v));
  else if (v.is(Tag::Unspecified))
    say(";Unspecified return value");
}

void report(const Error &e) {
  fresh_line();
  flush_output();
  report_error(stderr, as_users_error(e));
}

void report_internal(const char *what) {
  fresh_line();
  flush_output();
  std::fprintf(stderr, "sicm: internal error: %s\n", what);
}

// Ctrl-C while a form is being evaluated: the evaluator raises
// "Interrupted" at its next check and the loop carries on.
void on_eval_interrupt(int) {
  request_interrupt();
}

// Our SIGINT handler for as long as the object lives (the previous one
// afterwards). Opening a plot installs the plot library's handler, which
// finishes the plots and exits; it stays until the evaluation that opened
// the plot ends.
class EvalInterruptScope {
public:
  EvalInterruptScope() {
    struct sigaction sa {};
    sa.sa_handler = on_eval_interrupt;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, &old_);
  }
  ~EvalInterruptScope() { sigaction(SIGINT, &old_, nullptr); }
  EvalInterruptScope(const EvalInterruptScope &) = delete;
  EvalInterruptScope &operator=(const EvalInterruptScope &) = delete;

private:
  struct sigaction old_ {};
};

// Evaluate one form and print its value. Nothing escapes: errors, the
// limits of base/limits.hpp and Ctrl-C all end in a message, and the next
// form starts with fresh step and expression budgets.
void eval_and_print(const ReadForm &form) {
  begin_evaluation(form.loc);
  EvalInterruptScope interrupts;
  try {
    print_result(form.datum, eval_toplevel(form.datum, form.loc));
  } catch (const Error &e) {
    report(e);
  } catch (const std::bad_alloc &) {
    fresh_line();
    flush_output();
    std::fputs("sicm: error: out of memory\n", stderr);
  } catch (const std::exception &e) {
    report_internal(e.what());
  } catch (...) {
    report_internal("a non-local exit reached the top level (a continuation called after "
                    "its extent ended?)");
  }
  flush_output();
}

// ---- the pending entry ----------------------------------------------------------

// The text entered since the last finished entry, and how many of its forms
// have been evaluated already.
struct Pending {
  std::string text;
  size_t evaluated = 0;
  int entry = 1; // names the sources <repl-1>, <repl-2>, ...

  bool blank() const { return text.find_first_not_of(" \t\r\n") == std::string::npos; }
  void clear() {
    text.clear();
    evaluated = 0;
    ++entry;
  }
};

// Read the pending text and evaluate the forms not evaluated yet. Returns
// false if the text ends inside a datum and more lines may finish it (at end
// of input that is reported as the error it then is).
bool feed(Pending &p, bool at_eof) {
  uint32_t file = register_source("<repl-" + std::to_string(p.entry) + ">", p.text);
  Reader reader(file);
  size_t index = 0;
  try {
    ReadForm form;
    while (reader.next(form)) {
      if (index++ < p.evaluated) continue;
      ++p.evaluated;
      eval_and_print(form);
    }
  } catch (const Error &e) {
    // The reader complains only because the text stops too early.
    if (e.cause == ErrorCause::IncompleteInput && !at_eof) return false;
    report(e);
  }
  return true;
}

// ---- line sources ------------------------------------------------------------------

enum class Got { Line, Eof, Interrupt };

// Reads one line (without its newline). `continuation`: the pending entry is
// unfinished; `blank`: something was evaluated since the last prompt.
using LineSource = Got (*)(bool continuation, bool blank, std::string &line);

Got read_piped_line(bool, bool, std::string &line) {
  return std::getline(std::cin, line) ? Got::Line : Got::Eof;
}

// ---- history ---------------------------------------------------------------------

constexpr int kHistoryLines = 1000;
std::string g_history_path; // "" = no history file

std::string default_history_path() {
  if (const char *h = std::getenv("SICM_HISTORY"); h && *h) return h;
  if (const char *home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.sicm_history";
  return "";
}

void trim_history_file() {
  history_truncate_file(g_history_path.c_str(), kHistoryLines);
}

void open_history(const std::string &path) {
  using_history();
  stifle_history(kHistoryLines);
  g_history_path = path;
  if (path.empty()) return;
  read_history(path.c_str()); // a missing or unreadable file is no error
  std::atexit(trim_history_file);
}

bool is_last_history_line(const std::string &line) {
  if (history_length == 0) return false;
  HIST_ENTRY *last = history_get(history_base + history_length - 1);
  return last && line == last->line;
}

void remember_line(const std::string &line) {
  if (line.find_first_not_of(" \t\r") == std::string::npos || is_last_history_line(line)) return;
  add_history(line.c_str());
  if (g_history_path.empty()) return;
  // Appending fails if the file does not exist yet; writing creates it.
  if (append_history(1, g_history_path.c_str()) != 0) write_history(g_history_path.c_str());
}

// A pasted block may hold several lines: remember each.
void remember(const std::string &text) {
  size_t start = 0;
  for (size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1)
    remember_line(text.substr(start, nl - start));
  remember_line(text.substr(start));
}

// ---- completion --------------------------------------------------------------------

// Everything but these is part of a symbol, as far as completion cares.
const char kWordBreaks[] = " \t\n()\"'`,;";

const char *const kKeywords[] = {
    "quote",       "quasiquote",   "if",      "define",     "set!",
    "lambda",      "named-lambda", "begin",   "let",        "let*",
    "letrec",      "letrec*",      "cond",    "case",       "and",
    "or",          "when",         "unless",  "do",         "delay",
    "cons-stream", "fluid-let",    "receive", "let-values", "define-integrable",
    "declare"};

std::vector<std::string> g_matches;
size_t g_next_match = 0;

// readline's generator protocol: state 0 starts a new completion.
char *next_match(const char *text, int state) {
  if (state == 0) {
    g_matches = completions(text);
    g_next_match = 0;
  }
  if (g_next_match >= g_matches.size()) return nullptr;
  return strdup(g_matches[g_next_match++].c_str());
}

char **complete(const char *text, int, int) {
  rl_attempted_completion_over = 1; // never fall back to file names
  return rl_completion_matches(text, next_match);
}

// ---- signals -----------------------------------------------------------------------

int g_wake[2] = {-1, -1}; // self-pipe: the handlers write, the input loop selects
volatile std::sig_atomic_t g_interrupted = 0;
volatile std::sig_atomic_t g_resized = 0;

void on_signal(int sig) {
  int saved = errno;
  if (sig == SIGINT)
    g_interrupted = 1;
  else
    g_resized = 1;
  ssize_t n = write(g_wake[1], "!", 1); // a full pipe is fine: a wake-up is pending
  (void)n;
  errno = saved;
}

bool open_wake_pipe() {
  if (pipe(g_wake) != 0) return false;
  for (int fd : g_wake) {
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    fcntl(fd, F_SETFD, FD_CLOEXEC);
  }
  return true;
}

void drain_wake_pipe() {
  char buf[64];
  while (read(g_wake[0], buf, sizeof buf) > 0) {
  }
}

// Our SIGINT and SIGWINCH handlers while a line is being edited; the previous
// ones (normally the defaults) while evaluating.
class SignalScope {
public:
  SignalScope() {
    install(SIGINT, old_int_);
    install(SIGWINCH, old_winch_);
  }
  ~SignalScope() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGWINCH, &old_winch_, nullptr);
  }
  SignalScope(const SignalScope &) = delete;
  SignalScope &operator=(const SignalScope &) = delete;

private:
  static void install(int sig, struct sigaction &old) {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(sig, &sa, &old);
  }
  struct sigaction old_int_ {};
  struct sigaction old_winch_ {};
};

// ---- the console -----------------------------------------------------------------

struct LineResult {
  bool done = false;
  bool eof = false;
  std::string line;
};
LineResult g_result;

// readline's line handler. Removing the handler here stops readline from
// preparing the terminal and showing a prompt before we evaluate the line.
void on_line(char *line) {
  rl_callback_handler_remove();
  g_result.done = true;
  g_result.eof = line == nullptr;
  if (line) g_result.line = line;
  std::free(line);
}

// Ctrl-C while editing: drop the line, as readline's own handler would.
void abandon_line() {
  rl_free_line_state();
  rl_callback_sigcleanup();
  rl_echo_signal_char(SIGINT);
  rl_cleanup_after_signal();
  rl_callback_handler_remove();
  std::fputs("\n;Quit!\n", stdout);
}

Got wait_for_line(std::string &line) {
  int in = fileno(rl_instream ? rl_instream : stdin);
  while (!g_result.done) {
    if (g_interrupted) {
      abandon_line();
      return Got::Interrupt;
    }
    if (g_resized) {
      g_resized = 0;
      rl_resize_terminal();
    }
    fd_set fds;
    FD_ZERO(&fds);
    FD_SET(in, &fds);
    FD_SET(g_wake[0], &fds);
    int r = select(std::max(in, g_wake[0]) + 1, &fds, nullptr, nullptr, nullptr);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      rl_callback_handler_remove();
      return Got::Eof;
    }
    if (FD_ISSET(g_wake[0], &fds)) drain_wake_pipe();
    if (FD_ISSET(in, &fds)) rl_callback_read_char();
  }
  if (g_result.eof) return Got::Eof;
  line = std::move(g_result.line);
  return Got::Line;
}

Got read_console_line(bool continuation, bool blank, std::string &line) {
  if (!continuation) {
    fresh_line();
    if (blank) output("\n"); // MIT leaves a blank line before each prompt
  }
  flush_output();
  SignalScope signals;
  g_interrupted = 0;
  g_resized = 0;
  drain_wake_pipe();
  g_result = LineResult{};
  using_history();
  rl_callback_handler_install(continuation ? kContinuationPrompt : kPrompt, on_line);
  Got got = wait_for_line(line);
  if (got == Got::Line) remember(line);
  return got;
}

void setup_readline(const ReplOptions &options) {
  rl_readline_name = "sicm"; // for $if sicm in ~/.inputrc
  rl_catch_signals = 0;      // we handle SIGINT and SIGWINCH ourselves
  rl_catch_sigwinch = 0;
  rl_attempted_completion_function = complete;
  rl_basic_word_break_characters = kWordBreaks;
  rl_completer_word_break_characters = kWordBreaks;
  rl_variable_bind("blink-matching-paren", "on");
  open_history(options.history_file.empty() ? default_history_path() : options.history_file);
}

// ---- the loop ----------------------------------------------------------------------

int repl_loop(LineSource read_line, bool interactive) {
  Pending p;
  bool blank = interactive; // MIT shows a blank line before the first prompt too
  for (;;) {
    std::string line;
    Got got = read_line(!p.blank(), blank, line);
    if (got == Got::Eof) break;
    blank = true;
    if (got == Got::Interrupt) {
      p.clear();
      continue;
    }
    p.text += line;
    p.text += '\n';
    if (!feed(p, false)) continue;
    blank = !p.blank();
    p.clear();
  }
  if (interactive) output("\n");
  if (!p.blank()) feed(p, true);
  flush_output();
  return 0;
}

} // namespace

// The library's internal helpers are named %...: offered only to a user who
// types the %.
std::vector<std::string> completions(std::string_view prefix) {
  std::set<std::string> names;
  for (const std::string &n : global_names())
    if (n.starts_with(prefix) && (!n.starts_with("%") || prefix.starts_with("%"))) names.insert(n);
  for (const char *k : kKeywords)
    if (std::string_view(k).starts_with(prefix)) names.insert(k);
  return {names.begin(), names.end()};
}

int run_repl(const ReplOptions &options) {
  if (!options.interactive || !open_wake_pipe()) return repl_loop(read_piped_line, false);
  setup_readline(options);
  return repl_loop(read_console_line, true);
}

} // namespace sicm
