// The residual program as text (see residual_dump.hpp).
#include "codegen/residual_dump.hpp"

#include <map>
#include <regex>
#include <unordered_map>

#include "codegen/singular_factors.hpp"

namespace sicm {

namespace {

// A residual variable's symbol spelled as the C names it, rN.
std::string spelled(const std::string &text, const std::map<std::string, std::string> &names) {
  std::string out;
  static const std::regex symbol(R"(__sicm_rt\d+__)");
  auto last = text.cbegin();
  for (std::sregex_iterator m(text.begin(), text.end(), symbol), end; m != end; ++m) {
    out.append(last, text.cbegin() + m->position());
    auto it = names.find(m->str());
    out += it == names.end() ? m->str() : it->second;
    last = text.cbegin() + m->position() + m->length();
  }
  out.append(last, text.cend());
  return out;
}

const char *compute_name(RCompute c) {
  switch (c) {
  case RCompute::Expr: return "";
  case RCompute::Less: return "<";
  case RCompute::LessEq: return "<=";
  case RCompute::Equal: return "=";
  case RCompute::Select: return "select";
  case RCompute::Not: return "not";
  case RCompute::Floor: return "floor";
  case RCompute::Round: return "round";
  case RCompute::Truncate: return "truncate";
  case RCompute::Max: return "max";
  case RCompute::Min: return "min";
  case RCompute::RealTime: return "real-time";
  case RCompute::RunTime: return "runtime";
  case RCompute::Param: return "param";
  case RCompute::ReadCell: return "read-cell";
  case RCompute::ListLength: return "list-length";
  case RCompute::ListRef: return "list-ref";
  case RCompute::ListFold: return "list-fold";
  }
  return "?";
}

class Dumper {
public:
  explicit Dumper(const ResidualProgram &p) : p_(p) {
    for (const RVar &v : p.vars) {
      std::string marker = "__sicm_rt" + std::to_string(v.id) + "__";
      names_[marker] = "r" + std::to_string(v.id);
      // Variables named otherwise (a kernel's inputs x0 ... and parameters
      // k0 ..., named as sicm run names them: pe/numerics.cpp) are spelled
      // through a marker too.
      if (v.sym->name != marker)
        renamed_[expr_symbol(v.sym)] = expr_symbol(make_uninterned_symbol(marker).symbol());
    }
  }

  std::string run() {
    for (const RFunction &f : p_.functions) {
      out_ += "f" + std::to_string(f.id) + (f.id == 0 ? " main" : " " + f.name);
      if (f.parent >= 0) out_ += " (in f" + std::to_string(f.parent) + ")";
      out_ += " (" + vars(f.inputs) + ")";
      if (!f.outputs.empty()) out_ += " -> " + exprs(f.outputs);
      out_ += "\n";
      block(f.body, 1);
    }
    return out_;
  }

private:
  std::string vars(const std::vector<int> &ids) {
    std::string s;
    for (int v : ids)
      s += (s.empty() ? "r" : " r") + std::to_string(v);
    return s;
  }

  std::string exprs(const std::vector<ExprId> &ids) {
    std::string s;
    for (ExprId e : ids)
      s += (s.empty() ? "" : " ") +
           spelled(expr_debug_string(renamed_.empty() ? e : with_leaves({e}, renamed_)[0]), names_);
    return s;
  }

  std::string callees(const RStmt &s) {
    std::string c;
    auto add = [&](const char *role, int f) {
      if (f >= 0) c += std::string(" ") + role + " f" + std::to_string(f);
    };
    add("calls", s.callee);
    add("monitor", s.monitor);
    add("first-monitor", s.first_monitor);
    add("jacobian", s.jacobian);
    add("probe", s.probe);
    for (int m : s.members)
      c += " member f" + std::to_string(m);
    static const char *const directions[] = {"", "up", "down", "both"};
    for (const REvent &e : s.events)
      c += " event f" + std::to_string(e.event) + " " +
           directions[e.direction >= 1 && e.direction <= 3 ? e.direction : 0] +
           (e.action >= 0 ? " calls f" + std::to_string(e.action) : std::string(" stops"));
    return c;
  }

  void line(int depth, const std::string &text) {
    out_ += std::string(2 * depth, ' ') + text + "\n";
  }

  void block(const std::vector<RStmt> &body, int depth) {
    for (const RStmt &s : body) {
      std::string text;
      switch (s.kind) {
      case RKind::Text: text = "text \"" + escaped(s.text) + "\""; break;
      case RKind::Let:
        text =
            "r" + std::to_string(s.var) + " = " +
            (s.compute == RCompute::Expr ? exprs(s.args)
                                         : std::string("(") + compute_name(s.compute) +
                                               (s.text.empty() ? "" : " " + s.text) +
                                               (s.args.empty() ? "" : " " + exprs(s.args)) + ")");
        break;
      case RKind::Print: text = "print r" + std::to_string(s.var); break;
      default:
        text = statement_kind_name(s.kind);
        if (s.plot >= 0) text += " plot" + std::to_string(s.plot);
        if (s.cell >= 0) text += " cell" + std::to_string(s.cell);
        if (s.list >= 0) text += " list" + std::to_string(s.list);
        if (s.count > 0) text += " x" + std::to_string(s.count);
        text += callees(s);
        if (!s.method.empty()) text += " " + s.method;
        if (!s.args.empty()) text += " (" + exprs(s.args) + ")";
        if (!s.outs.empty()) text += " -> " + vars(s.outs);
        if (!s.results.empty()) text += " => " + vars(s.results);
        break;
      }
      line(depth, text);
      if (s.kind == RKind::If || s.kind == RKind::Loop) block(s.then_body, depth + 1);
      if (s.kind == RKind::If && !s.else_body.empty()) {
        line(depth, "else");
        block(s.else_body, depth + 1);
      }
    }
  }

  static std::string escaped(const std::string &s) {
    std::string out;
    for (char c : s)
      out += c == '\n' ? std::string("\\n") : c == '"' ? std::string("\\\"") : std::string(1, c);
    return out;
  }

  std::unordered_map<ExprId, ExprId> renamed_;
  const ResidualProgram &p_;
  std::map<std::string, std::string> names_;
  std::string out_;
};

} // namespace

const char *statement_kind_name(RKind k) {
  switch (k) {
  case RKind::Text: return "text";
  case RKind::Let: return "let";
  case RKind::Print: return "print";
  case RKind::Frame: return "frame";
  case RKind::PlotPoint: return "plot-point";
  case RKind::PlotLine: return "plot-line";
  case RKind::PlotStyle: return "plot-series";
  case RKind::Close: return "graphics-close";
  case RKind::Clear: return "graphics-clear";
  case RKind::SetCell: return "set-cell";
  case RKind::If: return "if";
  case RKind::Loop: return "loop";
  case RKind::Continue: return "continue";
  case RKind::Break: return "break";
  case RKind::Integral: return "definite-integral";
  case RKind::Minimize: return "minimize";
  case RKind::Multimin: return "multidimensional-minimize";
  case RKind::FindRoot: return "find-root";
  case RKind::Bisect: return "bisect";
  case RKind::Advance: return "state-advancer";
  case RKind::Evolve: return "evolve";
  case RKind::Crossings: return "crossings";
  case RKind::ListNew: return "list-new";
  case RKind::ListPush: return "list-push";
  case RKind::ListConst: return "list-const";
  case RKind::ParallelMap: return "parallel-map";
  case RKind::Fail: return "fail";
  case RKind::FailCapture: return "fail-capture";
  }
  return "?";
}

std::string dump_residual(const ResidualProgram &program) {
  return Dumper(program).run();
}

} // namespace sicm
