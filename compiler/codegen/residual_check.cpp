// The residual program's verifier (see residual_check.hpp).
//
// One walk over the functions in id order (a function's enclosing functions
// come before it: a procedure is traced while its caller is), each body in
// statement order. Variables are scoped to their function, not to blocks:
// the emitter declares what a branch or a loop defines where the function
// starts (the code after an if selects between the alternatives' values),
// so a use must follow its definition in the walk, in any enclosing or
// earlier block of the same function, or name a variable of an enclosing
// function (a capture, passed in p[]).
#include "codegen/residual_check.hpp"

#include <cstdlib>
#include <unordered_map>
#include <vector>

#include "base/error.hpp"
#include "codegen/residual_dump.hpp"

namespace sicm {

namespace {

// The operands a Let's computation takes (codegen/residual.hpp).
size_t compute_arity(RCompute c) {
  switch (c) {
  case RCompute::Expr:
  case RCompute::Not:
  case RCompute::Floor:
  case RCompute::Round:
  case RCompute::Truncate:
  case RCompute::Param: return 1;
  case RCompute::Less:
  case RCompute::LessEq:
  case RCompute::Equal:
  case RCompute::Max:
  case RCompute::Min:
  case RCompute::ListFold: return 2;
  case RCompute::Select:
  case RCompute::ListRef: return 3;
  case RCompute::RealTime:
  case RCompute::RunTime:
  case RCompute::ReadCell:
  case RCompute::ListLength: return 0;
  }
  return 0;
}

struct Violation {
  std::string what;
};

class Checker {
public:
  explicit Checker(const ResidualProgram &p) : p_(p), defs_(p.vars.size(), 0) {}

  void run() {
    if (p_.functions.empty()) fail("the program has no main function");
    for (size_t v = 0; v < p_.vars.size(); ++v) {
      const RVar &var = p_.vars[v];
      where_ = "r" + std::to_string(v);
      if (var.id != static_cast<int>(v)) fail("its id is " + std::to_string(var.id));
      if (!var.sym) fail("it has no symbol");
      if (!function_ok(var.function)) fail("its function f" + std::to_string(var.function));
      if (!ids_.emplace(var.sym, static_cast<int>(v)).second)
        fail("its symbol is also r" + std::to_string(ids_[var.sym]) + "'s");
    }
    for (size_t c = 0; c < p_.cells.size(); ++c)
      if (!p_.cells[c].place) fail("cell" + std::to_string(c) + " has no place");
    for (size_t l = 0; l < p_.lists.size(); ++l)
      if (p_.lists[l].width < 0) fail("list" + std::to_string(l) + " has a negative width");
    for (size_t t = 0; t < p_.tables.size(); ++t) {
      const RTable &table = p_.tables[t];
      if (table.width < 0 || (table.width > 0 && table.data.size() % size_t(table.width) != 0))
        fail("table" + std::to_string(t) + " is not a whole number of rows");
    }
    for (size_t f = 0; f < p_.functions.size(); ++f)
      function(static_cast<int>(f));
  }

private:
  [[noreturn]] void fail(const std::string &what) { throw Violation{where_ + ": " + what}; }
  void require(bool ok, const std::string &what) {
    if (!ok) fail(what);
  }

  bool function_ok(int f) const { return f >= 0 && static_cast<size_t>(f) < p_.functions.size(); }
  bool var_ok(int v) const { return v >= 0 && static_cast<size_t>(v) < p_.vars.size(); }

  bool is_ancestor(int a, int f) const {
    for (int g = p_.functions[static_cast<size_t>(f)].parent; g >= 0;
         g = p_.functions[static_cast<size_t>(g)].parent)
      if (g == a) return true;
    return false;
  }

  void function(int f) {
    const RFunction &fn = p_.functions[static_cast<size_t>(f)];
    f_ = f;
    where_ = "f" + std::to_string(f);
    require(fn.id == f, "its id is " + std::to_string(fn.id));
    if (f == 0)
      require(fn.parent == -1, "main has an enclosing function");
    else
      require(fn.parent >= 0 && fn.parent < f,
              "its enclosing function f" + std::to_string(fn.parent) + " does not come before it");
    defined_.assign(p_.vars.size(), false);
    for (int v : fn.inputs) {
      define(v, "input");
      require(p_.vars[static_cast<size_t>(v)].type == RType::Real,
              "input r" + std::to_string(v) + " is not a real");
    }
    loops_.clear();
    block(fn.body, "f" + std::to_string(f));
    where_ = "f" + std::to_string(f) + " outputs";
    for (ExprId o : fn.outputs)
      uses(o);
  }

  void block(const std::vector<RStmt> &body, const std::string &path) {
    for (size_t i = 0; i < body.size(); ++i) {
      const RStmt &s = body[i];
      std::string at =
          path + ": statement " + std::to_string(i) + " (" + statement_kind_name(s.kind) + ")";
      where_ = at;
      statement(s, at);
    }
  }

  void define(int v, const char *as) {
    require(var_ok(v), std::string(as) + " r" + std::to_string(v) + " is not a variable");
    const RVar &var = p_.vars[static_cast<size_t>(v)];
    require(var.function == f_, std::string(as) + " r" + std::to_string(v) + " belongs to f" +
                                    std::to_string(var.function));
    require(defs_[static_cast<size_t>(v)]++ == 0, "r" + std::to_string(v) + " is defined twice");
    defined_[static_cast<size_t>(v)] = true;
  }

  // A variable read by name (Print's).
  void use(int v) {
    require(var_ok(v), "r" + std::to_string(v) + " is not a variable");
    use_var(v);
  }

  void use_var(int v) {
    const RVar &var = p_.vars[static_cast<size_t>(v)];
    if (var.function == f_) {
      require(defined_[static_cast<size_t>(v)],
              "r" + std::to_string(v) + " is used before it is defined");
    } else if (is_ancestor(var.function, f_)) {
      require(defs_[static_cast<size_t>(v)] > 0, "r" + std::to_string(v) + " of f" +
                                                     std::to_string(var.function) +
                                                     " is captured but never defined");
    }
    // A variable of a function that does not enclose this one is the
    // emitter's compile error (a value that escapes its procedure).
  }

  // The variables an expression reads. A symbol that is no variable, or an
  // unknown function applied, is the emitter's compile error.
  void uses(ExprId e) {
    require(e < expr_count(), "expression " + std::to_string(e) + " is not in the arena");
    expr_visit({e}, [&](ExprId id) {
      const ExprNode &n = expr_node(id);
      if (n.kind != ExprKind::Symbol) return true;
      auto it = ids_.find(n.sym);
      if (it != ids_.end()) use_var(it->second);
      return true;
    });
  }

  void args(const RStmt &s, size_t n) {
    require(s.args.size() == n,
            "has " + std::to_string(s.args.size()) + " operands, not " + std::to_string(n));
  }
  void outs(const RStmt &s, size_t n) {
    require(s.outs.size() == n,
            "defines " + std::to_string(s.outs.size()) + " results, not " + std::to_string(n));
  }
  void callee(int g, const char *what, bool optional) {
    if (optional && g == -1) return;
    require(function_ok(g), std::string(what) + " f" + std::to_string(g) + " is not a function");
  }
  void plot(const RStmt &s) { // plots are numbered from 1 (pe/plots.cpp)
    require(s.plot >= 1 && s.plot <= p_.plots, "plot " + std::to_string(s.plot) + " out of range");
  }
  void cell(const RStmt &s) {
    require(s.cell >= 0 && static_cast<size_t>(s.cell) < p_.cells.size(),
            "cell " + std::to_string(s.cell) + " out of range");
  }
  void list(const RStmt &s) {
    require(s.list >= 0 && static_cast<size_t>(s.list) < p_.lists.size(),
            "list " + std::to_string(s.list) + " out of range");
  }
  void define_outs(const RStmt &s, RType type) {
    for (size_t i = 0; i < s.outs.size(); ++i) {
      int v = s.outs[i];
      define(v, "result");
      // Minimize's third result is its count of iterations.
      RType want = s.kind == RKind::Minimize && i == 2 ? RType::Integer : type;
      require(p_.vars[static_cast<size_t>(v)].type == want,
              "result r" + std::to_string(v) + " has the wrong type");
    }
  }

  // The fields the statement's kind needs (codegen/residual.hpp), its
  // operands' variables, then what it defines.
  void statement(const RStmt &s, const std::string &at) {
    if (s.kind != RKind::If && s.kind != RKind::Loop) require(s.then_body.empty(), "has a body");
    if (s.kind != RKind::If) require(s.else_body.empty(), "has an else body");
    for (ExprId a : s.args)
      uses(a);
    switch (s.kind) {
    case RKind::Text: break;
    case RKind::Fail: require(!s.text.empty() || capturing_, "fails without a message"); break;
    case RKind::FailCapture: capturing_ = true; break;
    case RKind::Let: let(s); break;
    case RKind::Print: use(s.var); break;
    case RKind::Frame:
      args(s, 4);
      plot(s);
      require(s.axis_labels.size() <= 2, "has more than two axis labels");
      break;
    case RKind::PlotPoint:
      args(s, 2);
      plot(s);
      break;
    case RKind::PlotLine:
      args(s, 4);
      plot(s);
      break;
    case RKind::PlotStyle:
      args(s, 0);
      plot(s);
      break;
    case RKind::Clear:
    case RKind::Close: plot(s); break;
    case RKind::SetCell:
      args(s, 1);
      cell(s);
      break;
    case RKind::If:
      args(s, 1);
      block(s.then_body, at + " then");
      block(s.else_body, at + " else");
      break;
    case RKind::Loop:
      require(s.args.size() == s.outs.size(), "has not one initial value per loop variable");
      for (int v : s.outs)
        define(v, "loop variable");
      for (int v : s.results)
        define(v, "loop result");
      loops_.push_back(&s);
      block(s.then_body, at + " body");
      loops_.pop_back();
      break;
    case RKind::Continue:
      require(!loops_.empty(), "is outside a loop");
      require(s.outs == loops_.back()->outs, "does not assign its loop's variables");
      require(s.args.size() == s.outs.size(), "has not one value per loop variable");
      break;
    case RKind::Break:
      require(!loops_.empty(), "is outside a loop");
      require(s.results == loops_.back()->results, "does not assign its loop's results");
      require(s.args.size() == s.results.size(), "has not one value per loop result");
      break;
    case RKind::Integral:
    case RKind::FindRoot:
      args(s, 2);
      outs(s, 1);
      callee(s.callee, "callee", false);
      define_outs(s, RType::Real);
      break;
    case RKind::Bisect:
      args(s, 3);
      outs(s, 1);
      callee(s.callee, "callee", false);
      define_outs(s, RType::Real);
      break;
    case RKind::Minimize:
      args(s, 2);
      outs(s, 3);
      callee(s.callee, "callee", false);
      define_outs(s, RType::Real);
      break;
    case RKind::Multimin:
      require(s.outs.size() <= s.args.size(), "defines more results than it has operands");
      callee(s.callee, "callee", false);
      define_outs(s, RType::Real);
      break;
    case RKind::Advance:
    case RKind::Evolve: ode(s); break;
    case RKind::Crossings: crossings(s); break;
    case RKind::ListNew: list(s); break;
    case RKind::ListPush:
      list(s);
      require(s.args.size() == static_cast<size_t>(p_.lists[static_cast<size_t>(s.list)].width),
              "pushes an element of another width than its list's");
      break;
    case RKind::ListConst:
      list(s);
      require(s.leaf >= 0 && static_cast<size_t>(s.leaf) < p_.tables.size(),
              "table " + std::to_string(s.leaf) + " out of range");
      break;
    case RKind::ParallelMap: parallel_map(s); break;
    }
  }

  void let(const RStmt &s) {
    size_t n = compute_arity(s.compute);
    require(s.args.size() == n, "its computation takes " + std::to_string(n) + " operands, not " +
                                    std::to_string(s.args.size()));
    if (s.compute == RCompute::ReadCell) cell(s);
    if (s.compute == RCompute::ListLength || s.compute == RCompute::ListRef ||
        s.compute == RCompute::ListFold)
      list(s);
    if (s.compute == RCompute::ListFold) require(s.leaf >= 0 && s.leaf < 4, "unknown fold");
    define(s.var, "variable");
    bool truth = s.compute == RCompute::Less || s.compute == RCompute::LessEq ||
                 s.compute == RCompute::Equal || s.compute == RCompute::Not;
    if (truth)
      require(p_.vars[static_cast<size_t>(s.var)].type == RType::Boolean,
              "a comparison's variable r" + std::to_string(s.var) + " is not a truth value");
  }

  // Crossings: the state's leaves, then the final time, as Advance's; the
  // event a function of the state with one output, the list one of states.
  void crossings(const RStmt &s) {
    require(s.outs.empty(), "defines variables (its result is its list)");
    ode(s);
    callee(s.monitor, "event", false);
    const RFunction &event = p_.functions[static_cast<size_t>(s.monitor)];
    require(event.inputs.size() + 1 == s.args.size() && event.outputs.size() == 1,
            "its event f" + std::to_string(s.monitor) + " is not a number of the state");
    list(s);
    require(static_cast<size_t>(p_.lists[static_cast<size_t>(s.list)].width) + 1 == s.args.size(),
            "its list's elements are not states");
    require(s.direction >= 1 && s.direction <= 3, "has no direction");
    require(s.count >= 0, "has a negative count");
  }

  // Advance: the state's leaves, then dt; Evolve: the state's leaves, dt
  // and the final time. The system derivative maps the state to its rate.
  void ode(const RStmt &s) {
    size_t extra = s.kind == RKind::Evolve ? 2 : 1;
    require(s.args.size() >= extra, "has no state");
    size_t dim = s.args.size() - extra;
    require(s.outs.size() <= dim, "defines more results than the state has leaves");
    require(!s.method.empty(), "has no method");
    callee(s.callee, "system derivative", false);
    const RFunction &sys = p_.functions[static_cast<size_t>(s.callee)];
    require(sys.inputs.size() == dim && sys.outputs.size() == dim,
            "its system derivative f" + std::to_string(s.callee) + " is not of the state's size");
    if (s.kind != RKind::Crossings) {
      callee(s.monitor, "monitor", true);
      require(s.kind == RKind::Evolve || s.monitor == -1, "advance has a monitor");
    }
    callee(s.first_monitor, "first monitor", true);
    require(s.first_monitor == -1 || s.monitor >= 0, "has a first monitor but no monitor");
    require(s.kind != RKind::Crossings || s.events.empty(), "crossings has events");
    for (const REvent &e : s.events) {
      callee(e.event, "event", false);
      const RFunction &event = p_.functions[static_cast<size_t>(e.event)];
      require(event.inputs.size() == dim && event.outputs.size() == 1,
              "its event f" + std::to_string(e.event) + " is not a number of the state");
      callee(e.action, "event's procedure", true);
      require(e.action == -1 || p_.functions[static_cast<size_t>(e.action)].inputs.size() == dim,
              "its event's procedure f" + std::to_string(e.action) + " does not take the state");
      require(e.direction >= 1 && e.direction <= 3, "has an event without a direction");
    }
    // A kernel (emitted as plain C, as sicm run's JIT kernels) is one DAG.
    for (int k : {s.callee, s.jacobian, s.probe})
      if (k >= 0)
        require(!p_.functions[static_cast<size_t>(k)].kernel ||
                    p_.functions[static_cast<size_t>(k)].body.empty(),
                "its kernel f" + std::to_string(k) + " has statements");
    callee(s.jacobian, "jacobian", true);
    callee(s.probe, "singular factors", true);
    if (s.probe >= 0)
      require(p_.functions[static_cast<size_t>(s.probe)].outputs.size() == s.probe_texts.size(),
              "its singular factors do not match their texts");
    else
      require(s.probe_texts.empty(), "has texts of singular factors but no function");
    define_outs(s, RType::Real);
  }

  void parallel_map(const RStmt &s) {
    require(s.count >= 0, "has a negative count");
    require(!s.members.empty(), "has no member function");
    require(s.members.size() == 1 || s.members.size() == static_cast<size_t>(s.count),
            "has neither one function for all members nor one each");
    for (int m : s.members)
      callee(m, "member", false);
    if (s.count > 0)
      require(s.args.size() % static_cast<size_t>(s.count) == 0,
              "its operands do not divide among its members");
    size_t results = 0;
    for (int i = 0; i < s.count; ++i)
      results += p_.functions[static_cast<size_t>(s.members[s.members.size() == 1 ? 0 : i])]
                     .outputs.size();
    outs(s, results);
    for (int v : s.outs)
      define(v, "result");
  }

  const ResidualProgram &p_;
  std::vector<int> defs_;     // per variable: its definitions so far
  std::vector<bool> defined_; // per variable: defined so far in the function walked
  std::unordered_map<Symbol *, int> ids_;
  std::vector<const RStmt *> loops_; // the loops around the statement walked
  bool capturing_ = false;           // a FailCapture was met: a Fail may print its message
  int f_ = 0;
  std::string where_;
};

} // namespace

std::string residual_violation(const ResidualProgram &program) {
  try {
    Checker(program).run();
  } catch (const Violation &v) {
    return v.what;
  }
  return "";
}

bool residual_checks_enabled() {
  static const bool enabled = [] {
    const char *e = std::getenv("SICM_CHECK_RESIDUAL");
    return e && std::string(e) == "1";
  }();
  return enabled;
}

void check_residual(const ResidualProgram &program, const char *pass) {
  if (!residual_checks_enabled()) return;
  std::string what = residual_violation(program);
  if (!what.empty())
    internal_failure(__FILE__, __LINE__,
                     ("residual program after " + std::string(pass) + ": " + what).c_str());
}

} // namespace sicm
