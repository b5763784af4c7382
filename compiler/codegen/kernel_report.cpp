// What each kernel of a built program computes (see kernel_report.hpp).
#include "codegen/kernel_report.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <regex>
#include <set>
#include <unordered_map>

#include "cas/expr.hpp"

namespace sicm {

const char *const kReportedOps[12] = {"add", "mul", "div", "sqrt",  "sin",   "cos",
                                      "exp", "log", "pow", "atan2", "solve", "call"};

namespace {

// C words that look like calls but are not: keywords, and the helpers whose
// work is counted under another name (a factorization is part of a solve).
const std::set<std::string> kNotCalls = {"if",
                                         "for",
                                         "while",
                                         "switch",
                                         "return",
                                         "sizeof",
                                         "_Pragma",
                                         "sicm_ldlt_factor",
                                         "sicm_lu_factor",
                                         "sicm_singular_nan"};

// Blank out comments and string and character literals, so that what is
// left is code.
std::string code_only(std::string_view s) {
  std::string out(s);
  for (size_t i = 0; i < out.size(); ++i) {
    if (out.compare(i, 2, "/*") == 0) {
      size_t end = out.find("*/", i + 2);
      end = end == std::string::npos ? out.size() : end + 2;
      for (size_t k = i; k < end; ++k)
        out[k] = ' ';
      i = end - 1;
    } else if (out[i] == '"' || out[i] == '\'') {
      char quote = out[i];
      size_t k = i + 1;
      while (k < out.size() && out[k] != quote)
        k += out[k] == '\\' ? 2 : 1;
      for (size_t j = i; j <= k && j < out.size(); ++j)
        out[j] = ' ';
      i = k;
    }
  }
  return out;
}

// Where the statement that begins at code[i] (after blanks) ends: a block
// at its closing brace, a for loop after its body, anything else after its
// semicolon.
size_t statement_end(const std::string &code, size_t i) {
  const size_t n = code.size();
  while (i < n && std::isspace(static_cast<unsigned char>(code[i])))
    ++i;
  if (i < n && code[i] == '{') {
    int depth = 0;
    for (; i < n; ++i) {
      depth += code[i] == '{' ? 1 : code[i] == '}' ? -1 : 0;
      if (depth == 0) return i + 1;
    }
    return n;
  }
  if (code.compare(i, 3, "for") == 0) {
    size_t open = code.find('(', i);
    int depth = 0;
    for (size_t k = open; k < n; ++k) {
      depth += code[k] == '(' ? 1 : code[k] == ')' ? -1 : 0;
      if (depth == 0) return statement_end(code, k + 1);
    }
    return n;
  }
  int depth = 0;
  for (; i < n; ++i) {
    depth += code[i] == '(' || code[i] == '[' ? 1 : code[i] == ')' || code[i] == ']' ? -1 : 0;
    if (code[i] == ';' && depth == 0) return i + 1;
  }
  return n;
}

// The loop variables of the loops around a body: their ranges [lo, hi).
using LoopRanges = std::map<std::string, std::pair<double, double>>;

// How many times a loop with this header (the text between its parentheses)
// runs, on average over the enclosing loops: the emitter's forms `int v = A;
// v < B; ++v` with numbers A and B, and `int v = w + c; v < B; ++v` over an
// enclosing loop's variable w (the pairs i < j); any other loop counts once.
double trip_count(const std::string &header, LoopRanges &ranges, std::string *var) {
  static const std::regex form(
      R"(\s*int (\w+) = (\w+)(?: \+ (\d+))?; (\w+) < (\d+); \+\+(\w+)\s*)");
  std::smatch m;
  if (!std::regex_match(header, m, form) || m[1] != m[4] || m[1] != m[6]) return 1;
  *var = m[1];
  double hi = std::stod(m[5]), offset = m[3].matched ? std::stod(m[3]) : 0, lo;
  if (std::isdigit(static_cast<unsigned char>(m[2].str()[0]))) {
    lo = std::stod(m[2]) + offset;
    ranges[*var] = {lo, hi};
    return std::max(0.0, hi - lo);
  }
  auto outer = ranges.find(m[2]);
  if (outer == ranges.end()) return 1;
  // v runs from w + c: on average from the mean of w's range plus c.
  double mean = (outer->second.first + outer->second.second - 1) / 2;
  lo = mean + offset;
  ranges[*var] = {lo, hi};
  return std::max(0.0, hi - lo);
}

void count_ops(const std::string &code, double times, LoopRanges ranges,
               std::map<std::string, double> &ops) {
  const size_t n = code.size();
  int brackets = 0; // inside an index: its arithmetic is addressing, not the kernel's
  for (size_t i = 0; i < n;) {
    char c = code[i];
    if (std::isdigit(static_cast<unsigned char>(c)) ||
        (c == '.' && i + 1 < n && std::isdigit(static_cast<unsigned char>(code[i + 1])))) {
      // A number, exponent and all: the - of 1e-05 is not a subtraction.
      while (i < n &&
             (std::isalnum(static_cast<unsigned char>(code[i])) || code[i] == '.' ||
              ((code[i] == '-' || code[i] == '+') && (code[i - 1] == 'e' || code[i - 1] == 'E'))))
        ++i;
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      size_t start = i;
      while (i < n && (std::isalnum(static_cast<unsigned char>(code[i])) || code[i] == '_'))
        ++i;
      std::string word = code.substr(start, i - start);
      size_t k = i;
      while (k < n && code[k] == ' ')
        ++k;
      if (word == "for" && k < n && code[k] == '(') {
        // A loop: its body's operations as many times as it runs.
        size_t close = k;
        for (int depth = 0; close < n; ++close) {
          depth += code[close] == '(' ? 1 : code[close] == ')' ? -1 : 0;
          if (depth == 0) break;
        }
        std::string var;
        LoopRanges inner = ranges;
        double trips = trip_count(code.substr(k + 1, close - k - 1), inner, &var);
        size_t end = statement_end(code, close + 1);
        count_ops(code.substr(close + 1, end - close - 1), times * trips, inner, ops);
        i = end;
        continue;
      }
      if (k >= n || code[k] != '(' || kNotCalls.count(word)) continue;
      // The checked forms of the program's own arithmetic (sicm/program.h)
      // are the operation they check.
      if (word == "sicm_checked_sqrt") word = "sqrt";
      if (word == "sicm_checked_log") word = "log";
      if (word == "sicm_checked_pow") word = "pow";
      if (word == "sincos") {
        ops["sin"] += times, ops["cos"] += times;
      } else if (word == "sicm_checked_quotient") {
        ops["div"] += times;
      } else if (word == "sqrt" || word == "sin" || word == "cos" || word == "exp" ||
                 word == "log" || word == "pow" || word == "atan2") {
        ops[word] += times;
      } else if (word == "sicm_ldlt_solve" || word == "sicm_lu_solve") {
        ops["solve"] += times;
      } else {
        ops["call"] += times;
      }
      continue;
    }
    const char next = i + 1 < n ? code[i + 1] : '\0';
    if ((c == '+' || c == '-') && (next == c || next == '=' || (c == '-' && next == '>'))) {
      i += 2; // ++, --, +=, -=, ->: loop bookkeeping in the solve helpers, not arithmetic
      continue;
    }
    brackets += c == '[' ? 1 : c == ']' ? -1 : 0;
    if (brackets == 0) {
      if (c == '+' || c == '-') ops["add"] += times;
      if (c == '*' && next != '=') ops["mul"] += times;
      if (c == '/' && next != '=') ops["div"] += times;
    }
    ++i;
  }
}

} // namespace

std::map<std::string, size_t> count_c_ops(std::string_view body) {
  std::map<std::string, double> counted;
  count_ops(code_only(body), 1, {}, counted);
  std::map<std::string, size_t> ops;
  for (const char *op : kReportedOps)
    ops[op] = static_cast<size_t>(std::llround(counted[op]));
  return ops;
}

namespace {

// Which function each statement calls, and for what.
struct Use {
  std::string role;
  SrcLoc loc;
};

void find_uses(const std::vector<RStmt> &body, std::map<int, Use> &uses) {
  for (const RStmt &s : body) {
    auto note = [&](int f, const char *role) {
      if (f >= 0 && !uses.count(f)) uses[f] = Use{role, s.loc};
    };
    switch (s.kind) {
    case RKind::Evolve:
    case RKind::Crossings:
    case RKind::Advance: note(s.callee, "state-derivative"); break;
    case RKind::Integral: note(s.callee, "integrand"); break;
    case RKind::Minimize:
    case RKind::Multimin: note(s.callee, "objective"); break;
    case RKind::FindRoot:
    case RKind::Bisect: note(s.callee, "other"); break;
    default: break;
    }
    for (int member : s.members)
      note(member, "other"); // a member of parallel-map
    note(s.monitor, "monitor");
    for (const REvent &e : s.events) {
      note(e.event, "other"); // the event function of on-crossing or stop-on-crossing
      note(e.action, "monitor");
    }
    note(s.jacobian, "jacobian");
    note(s.probe, "other"); // what the derivative divides by, evaluated only on failure
    find_uses(s.then_body, uses);
    find_uses(s.else_body, uses);
  }
}

class Dependencies {
public:
  explicit Dependencies(const ResidualProgram &p) : p_(p) {
    for (const RVar &v : p.vars)
      var_of_[v.sym] = v.id;
    for (const RFunction &f : p.functions)
      walk(f.body);
  }

  // The parameters the variables that expressions refer to depend on,
  // leaving out the variables of function f itself (its inputs, its lets).
  std::set<std::string> of(const std::vector<ExprId> &exprs, int f) const {
    std::set<std::string> out;
    expr_visit(exprs, [&](ExprId id) {
      if (expr_kind(id) != ExprKind::Symbol) return true;
      auto v = var_of_.find(expr_node(id).sym);
      if (v == var_of_.end() || p_.vars[v->second].function == f) return true;
      auto d = params_.find(v->second);
      if (d != params_.end()) out.insert(d->second.begin(), d->second.end());
      return true;
    });
    return out;
  }

  // Every expression of function f: its outputs and its statements' arguments.
  static void expressions(const std::vector<RStmt> &body, std::vector<ExprId> &out) {
    for (const RStmt &s : body) {
      out.insert(out.end(), s.args.begin(), s.args.end());
      expressions(s.then_body, out);
      expressions(s.else_body, out);
    }
  }

private:
  void walk(const std::vector<RStmt> &body) {
    for (const RStmt &s : body) {
      std::set<std::string> from = of(s.args, -1);
      if (s.kind == RKind::Let && s.compute == RCompute::Param) from.insert(s.text);
      if (s.var >= 0) params_[s.var].insert(from.begin(), from.end());
      for (int v : s.outs)
        params_[v].insert(from.begin(), from.end());
      walk(s.then_body);
      walk(s.else_body);
    }
  }

  const ResidualProgram &p_;
  std::unordered_map<Symbol *, int> var_of_;
  std::map<int, std::set<std::string>> params_;
};

// The body of `static void fN(...) {` in the unit: up to the closing brace
// at the start of a line.
std::string_view function_body(const std::string &unit, int f) {
  const std::string head =
      "static void f" + std::to_string(f) + "(const double *in, double *out, const double *p) {\n";
  size_t start = unit.find(head);
  if (start == std::string::npos) return {};
  start += head.size();
  size_t end = unit.find("\n}\n", start);
  return std::string_view(unit).substr(start, end == std::string::npos ? 0 : end - start);
}

std::string json_string(const std::string &s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\')
      out += std::string("\\") + static_cast<char>(c);
    else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else
      out += static_cast<char>(c);
  }
  return out + "\"";
}

} // namespace

std::vector<KernelReport> report_kernels(const ResidualProgram &program,
                                         const std::string &c_unit) {
  std::map<int, Use> uses;
  for (const RFunction &f : program.functions)
    find_uses(f.body, uses);
  Dependencies deps(program);
  std::vector<KernelReport> out;
  for (size_t f = 1; f < program.functions.size(); ++f) {
    const RFunction &fn = program.functions[f];
    KernelReport r;
    auto use = uses.find(static_cast<int>(f));
    r.role = use == uses.end() ? "other" : use->second.role;
    SrcLoc loc = use == uses.end() ? fn.loc : use->second.loc;
    r.site = loc.known() ? loc_text(loc) : "?";
    r.inputs = fn.inputs.size();
    r.outputs = fn.outputs.size();
    std::vector<ExprId> exprs = fn.outputs;
    Dependencies::expressions(fn.body, exprs);
    std::set<std::string> params = deps.of(exprs, static_cast<int>(f));
    r.parameters.assign(params.begin(), params.end());
    r.ops = count_c_ops(function_body(c_unit, static_cast<int>(f)));
    for (const auto &[name, count] : r.ops)
      r.total += count;
    out.push_back(std::move(r));
  }
  return out;
}

std::string report_json(const std::vector<KernelReport> &kernels,
                        const std::vector<std::string> &effects) {
  std::string s = "{\"kernels\": [";
  for (size_t k = 0; k < kernels.size(); ++k) {
    const KernelReport &r = kernels[k];
    s += k ? ", " : "";
    s += "{\"site\": " + json_string(r.site) + ", \"role\": " + json_string(r.role) +
         ", \"inputs\": " + std::to_string(r.inputs) +
         ", \"outputs\": " + std::to_string(r.outputs) + ", \"parameters\": [";
    for (size_t i = 0; i < r.parameters.size(); ++i)
      s += (i ? ", " : "") + json_string(r.parameters[i]);
    s += "], \"ops\": {";
    for (size_t i = 0; i < sizeof kReportedOps / sizeof *kReportedOps; ++i)
      s += std::string(i ? ", " : "") + "\"" + kReportedOps[i] +
           "\": " + std::to_string(r.ops.at(kReportedOps[i]));
    s += "}, \"total\": " + std::to_string(r.total) + "}";
  }
  s += "], \"effects\": [";
  for (size_t i = 0; i < effects.size(); ++i)
    s += (i ? ", " : "") + json_string(effects[i]);
  return s + "]}\n";
}

std::string report_table(const std::vector<KernelReport> &kernels,
                         const std::vector<std::string> &effects) {
  std::string s;
  char line[512];
  std::snprintf(line, sizeof line,
                "%-28s %-16s %4s %4s %5s %5s %5s %5s %5s %5s %5s %5s %5s %5s %5s %5s %6s\n", "site",
                "role", "in", "out", "add", "mul", "div", "sqrt", "sin", "cos", "exp", "log", "pow",
                "atan2", "solve", "call", "total");
  s += line;
  for (const KernelReport &r : kernels) {
    std::string site = r.site.size() > 28 ? "..." + r.site.substr(r.site.size() - 25) : r.site;
    std::snprintf(line, sizeof line,
                  "%-28s %-16s %4zu %4zu %5zu %5zu %5zu %5zu %5zu %5zu %5zu %5zu %5zu %5zu %5zu "
                  "%5zu %6zu\n",
                  site.c_str(), r.role.c_str(), r.inputs, r.outputs, r.ops.at("add"),
                  r.ops.at("mul"), r.ops.at("div"), r.ops.at("sqrt"), r.ops.at("sin"),
                  r.ops.at("cos"), r.ops.at("exp"), r.ops.at("log"), r.ops.at("pow"),
                  r.ops.at("atan2"), r.ops.at("solve"), r.ops.at("call"), r.total);
    s += line;
    if (!r.parameters.empty()) {
      s += "    parameters:";
      for (const std::string &p : r.parameters)
        s += " " + p;
      s += "\n";
    }
  }
  if (!effects.empty()) {
    s += "effects:";
    for (const std::string &e : effects)
      s += " " + e;
    s += "\n";
  }
  return s;
}

} // namespace sicm
