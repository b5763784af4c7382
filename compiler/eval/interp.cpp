// The interpreter's top level: whole-program checks, running a source file
// form by form. (Start-up, which installs every layer's primitives, is
// driver/init.cpp.)
#include "eval/interp.hpp"

#include <algorithm>
#include <unordered_set>

#include "eval/analyze.hpp"
#include "eval/core.hpp"
#include "eval/name_suggestion.hpp"
#include "eval/procedure.hpp"
#include "syntax/reader.hpp"

namespace sicm {

namespace {

struct GlobalUse {
  Symbol *name;
  SrcLoc loc;
};
std::vector<GlobalUse> *g_uses = nullptr; // collecting during check_program

void record_use(Symbol *name, SrcLoc loc) {
  if (g_uses) g_uses->push_back(GlobalUse{name, loc});
}

} // namespace

namespace {
SrcLoc g_toplevel_loc; // the top-level form being run (a program's, or a REPL entry's)
} // namespace

Value eval_toplevel(Value datum, SrcLoc loc) {
  g_toplevel_loc = loc;
  Node *n = analyze_form(datum, loc, nullptr);
  return eval(n, nullptr);
}

bool is_printable_toplevel(Value datum, Value result) {
  if (is_definition(datum)) return false;
  return !result.is(Tag::Unspecified) && !result.is(Tag::Default);
}

Error as_users_error(const Error &e) {
  Error shown = e;
  SrcLoc user = current_toplevel_loc();
  if (is_library_loc(e.loc) && user.known()) {
    shown.loc = user;
    shown.note = "raised inside the library, at " + loc_text(e.loc) +
                 (e.note.empty() ? "" : "\nnote: " + e.note);
  }
  return shown;
}

std::vector<std::string> global_names() {
  // Every bound, interned symbol: intern() of a name gives the same symbol,
  // so walk the names the table knows through a probe list built at need.
  return bound_global_names();
}

gcvec<Node *> check_program(const gcvec<ReadForm> &forms) {
  std::vector<Symbol *> defined;
  for (const ReadForm &f : forms)
    toplevel_defined_names(f.datum, defined);
  std::unordered_set<Symbol *> defined_set(defined.begin(), defined.end());
  std::vector<GlobalUse> uses;
  gcvec<Node *> nodes;
  g_uses = &uses;
  try {
    for (const ReadForm &f : forms)
      nodes.push_back(analyze_form(f.datum, f.loc, record_use));
  } catch (...) {
    g_uses = nullptr;
    throw;
  }
  g_uses = nullptr;
  for (const GlobalUse &u : uses) {
    if (u.name->bound || defined_set.count(u.name)) continue;
    std::vector<std::string> known = global_names();
    for (Symbol *d : defined)
      known.push_back(d->name);
    std::string near = suggested_name(u.name->name, known);
    throw Error(ErrorKind::Syntax, u.loc, "Unbound variable: " + u.name->name,
                near.empty() ? "" : "did you mean '" + near + "'?");
  }
  return nodes;
}

SrcLoc current_toplevel_loc() {
  return g_toplevel_loc;
}

void run_source(uint32_t file) {
  gcvec<ReadForm> forms = read_all(file);
  // Analyzed once, for the check and for running: analysis depends only on
  // the forms themselves, not on what earlier forms did when they ran.
  gcvec<Node *> nodes = check_program(forms);
  for (size_t i = 0; i < forms.size(); ++i) {
    const ReadForm &f = forms[i];
    g_toplevel_loc = f.loc;
    Value v = eval(nodes[i], nullptr);
    if (is_printable_toplevel(f.datum, v)) {
      if (print_preparer()) v = print_preparer()(v);
      output(written(v));
      output("\n");
    }
  }
  flush_output();
}

} // namespace sicm
