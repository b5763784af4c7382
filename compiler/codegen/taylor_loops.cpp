// Repeated recurrences of a Taylor function found as loops (see taylor_loops.hpp).
//
// Approach, after heyoka's compact mode. The Taylor emitter writes order k as one statement
// per recurrence (a product, a power, a sum, ...), over its nodes in id order, and an N-body
// derivative gives the same few recurrences once per pair of bodies and sums of them once per
// body. Ids interleave those instances (a pair's terms, then partial sums of the forces of
// earlier pairs; a node shared by pairs computed in the first that needs it), so runs of
// instances are not found in that order as codegen/loops.cpp finds them in a kernel's
// schedule. Instead each statement gets a depth, one more than that of the deepest statement
// whose array it reads (0 when it reads none), and statements of one depth with the same text
// once their arrays, constants and indices are abstracted to slots (arrays and constants
// numbered by first appearance, so which of them coincide is part of the text) form a group:
// the pairs of bodies of different masses, whose products by m_i m_j are by different
// constants, group as those of equal masses do. The statements of one depth read only arrays
// of smaller depths, so running the depths in order, the groups of a depth in any order,
// computes every coefficient from the same values as the unrolled order did: each statement
// is the same C (the same recurrence, the same scalars, the same order of its operations),
// so the coefficients are bit for bit the unrolled ones.
//
// Every array becomes a row of one pool; rows are numbered in the order the statements
// write them, so a group writes consecutive rows and many of the rows it reads are affine in
// the member too (one pair's arrays after another's). A group's members run in any order,
// so those that load the state's components are sorted by component, and the rows of the
// bodies' coordinates are in the bodies' order. A group of at least kMinGroup members is a
// loop, each slot's row (or constant's number, or index) an affine function of the loop's
// counters, else read from a static table of ints; a smaller group stays straight-line. The
// loop is over the members, or, when that leaves fewer slots in tables, over steps of up to
// kMaxLanes members (a pair's three components: its force is its inverse cube's row, the
// step, times its differences', the member), the steps being the pairs first < second of n
// bodies in order when they are (a difference reads rows 3 first + lane and 3 second + lane,
// as codegen/loops.cpp's pair loops read in[]). What stays in tables is mostly the sums of
// the forces, each of whose terms comes from a pair of its own. The pool lives on the heap,
// one per thread, allocated at its first call: 100 bodies' is 34 MB, more than a stack.
//
// Limits: loops only when a group has at least kMinLoopInstances members, so that small
// systems (Kepler, 10 bodies: 135 products of a pair's inverse cube by its differences) keep
// their straight-line C as it was, which the heyoka benchmark times. Larger ones ran faster
// as loops, as the kernels' loops do (codegen/loops.cpp): 16 bodies over 400 time units in
// 0.39 s against 0.45-0.48 s straight-line, 32 bodies over 100 in 0.46-0.49 s against
// 0.69-0.74 s; and the C compiler took 10 s and 44 s for their straight-line C, under 1 s
// for the loops.
#include "codegen/taylor_loops.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <string_view>

namespace sicm {

namespace {

constexpr size_t kMinLoopInstances = 256;
constexpr size_t kMinGroup = 4;
// A loop may run over up to kMaxLanes members per step (the components of a pair's vectors).
constexpr size_t kMaxLanes = 8;

bool is_identifier_start(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_';
}

bool is_identifier_char(char ch) {
  return is_identifier_start(ch) || (ch >= '0' && ch <= '9');
}

// A token of a statement that may differ between instances: text [begin, end) names array
// `value` or scalar `value` (a constant, as "k3"), or is the integer `value` as an index (97
// in c[k * 193 + 97], the state's component a statement loads).
struct Token {
  enum Kind { Array, Scalar, Index } kind;
  size_t begin, end;
  long value;
};

// The names of arrays and scalars: name -> (kind, number). The names are views of strings
// that outlive the map, so that looking a token up allocates nothing.
using Names = std::unordered_map<std::string_view, std::pair<Token::Kind, size_t>>;

// The arrays and scalars a text names (and, with indices, the integers it indexes with), in
// order; numbers are read whole, so the e5 of 1e5 is no name.
std::vector<Token> tokens_of(const std::string &text, const Names &names, bool indices) {
  std::vector<Token> tokens;
  for (size_t i = 0; i < text.size();) {
    size_t j = i + 1;
    if (is_identifier_start(text[i])) {
      while (j < text.size() && is_identifier_char(text[j]))
        ++j;
      auto it = names.find(std::string_view(text).substr(i, j - i));
      if (it != names.end()) tokens.push_back({it->second.first, i, j, long(it->second.second)});
    } else if (text[i] >= '0' && text[i] <= '9') {
      bool integer = true;
      while (j < text.size() && (is_identifier_char(text[j]) || text[j] == '.')) {
        integer = integer && text[j] >= '0' && text[j] <= '9';
        ++j;
      }
      if (indices && integer && j < text.size() && text[j] == ']' && j - i < 10)
        tokens.push_back({Token::Index, i, j, std::stol(text.substr(i, j - i))});
    }
    i = j;
  }
  return tokens;
}

// A statement with what may differ abstracted: the text with "$s$" for slot s, an array or a
// scalar (numbered by first appearance, so which of them coincide is part of the text), and
// "#s#" for slot s, an index.
struct Shape {
  std::string text;
  std::vector<Token> slots; // their kinds and values; begin and end unused
};

Shape shape_of(const std::string &statement, const Names &names) {
  Shape shape;
  size_t at = 0;
  for (const Token &token : tokens_of(statement, names, true)) {
    size_t slot = 0;
    if (token.kind != Token::Index)
      while (slot < shape.slots.size() &&
             !(shape.slots[slot].kind == token.kind && shape.slots[slot].value == token.value))
        ++slot;
    else
      slot = shape.slots.size();
    if (slot == shape.slots.size()) shape.slots.push_back(token);
    const char *mark = token.kind == Token::Index ? "#" : "$";
    shape.text += statement.substr(at, token.begin - at) + mark + std::to_string(slot) + mark;
    at = token.end;
  }
  shape.text += statement.substr(at);
  return shape;
}

// shape's text with slot s written as slot_text[s].
std::string instantiate(const std::string &text, const std::vector<std::string> &slot_text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '$' && text[i] != '#') {
      out += text[i];
      continue;
    }
    size_t close = text.find(text[i], i + 1);
    out += slot_text[std::stoul(text.substr(i + 1, close - i - 1))];
    i = close;
  }
  return out;
}

// Statements of one depth and shape, in the emitter's order.
struct Group {
  size_t depth;
  std::vector<size_t> members;
};

// How a loop numbers its members: member i alone, or `lanes` members per step (a pair's three
// components), the steps numbered by `step`, or, when pairs is nonzero, being the pairs
// first < second of `pairs` bodies in the order (0, 1), (0, 2), ..., (1, 2), ...
struct LoopForm {
  size_t lanes = 1, pairs = 0;
};

// The forms a loop of `count` members may take: flat first, then with lanes, then over pairs.
std::vector<LoopForm> forms_for(size_t count) {
  std::vector<LoopForm> forms{{1, 0}};
  for (size_t lanes = 2; lanes <= kMaxLanes; ++lanes)
    if (count % lanes == 0 && count / lanes >= 2) forms.push_back({lanes, 0});
  for (size_t lanes = 1; lanes <= kMaxLanes; ++lanes) {
    if (count % lanes) continue;
    size_t n = 3;
    while (n * (n - 1) / 2 < count / lanes)
      ++n;
    if (n * (n - 1) / 2 == count / lanes) forms.push_back({lanes, n});
  }
  return forms;
}

// A column as C: base + the sum of coefficient * counter.
struct Affine {
  long base = 0;
  std::vector<std::pair<long, std::string>> terms;

  std::string text() const {
    std::string s = std::to_string(base);
    for (const auto &[coefficient, counter] : terms) {
      if (coefficient == 0) continue;
      long magnitude = coefficient < 0 ? -coefficient : coefficient;
      s += (coefficient < 0 ? " - " : " + ") +
           (magnitude == 1 ? counter : std::to_string(magnitude) + " * " + counter);
    }
    return s;
  }
  bool uniform() const {
    for (const auto &term : terms)
      if (term.first != 0) return false;
    return true;
  }
};

// v as base + stride * i, if it is one.
std::optional<Affine> fit_members(const std::vector<long> &v) {
  const long base = v[0], stride = v.size() > 1 ? v[1] - base : 0;
  for (size_t m = 0; m < v.size(); ++m)
    if (v[m] != base + stride * long(m)) return std::nullopt;
  return Affine{base, {{stride, "i"}}};
}

// v as an affine function of the counters of form (not flat), if it is one.
std::optional<Affine> fit_form(const std::vector<long> &v, const LoopForm &form) {
  const size_t lanes = form.lanes;
  const long lane_stride = lanes > 1 ? v[1] - v[0] : 0;
  Affine fit;
  std::vector<long> predicted(v.size());
  if (form.pairs == 0) {
    const long step_stride = v[lanes] - v[0];
    fit = {v[0], {{step_stride, "step"}, {lane_stride, "lane"}}};
    for (size_t m = 0; m < v.size(); ++m)
      predicted[m] = v[0] + step_stride * long(m / lanes) + lane_stride * long(m % lanes);
  } else {
    // v = v(0, 1) + sf * first + ss * (second - 1) + sl * lane; (0, 2) is step 1 and (1, 2)
    // step pairs - 1.
    const long ss = v[lanes] - v[0];
    const long sf = v[lanes * (form.pairs - 1)] - v[0] - ss;
    fit = {v[0] - ss, {{sf, "first"}, {ss, "second"}, {lane_stride, "lane"}}};
    size_t m = 0;
    for (size_t a = 0; a < form.pairs; ++a)
      for (size_t b = a + 1; b < form.pairs; ++b)
        for (size_t l = 0; l < lanes; ++l, ++m)
          predicted[m] = fit.base + sf * long(a) + ss * long(b) + lane_stride * long(l);
  }
  if (predicted != v) return std::nullopt;
  return fit;
}

} // namespace

std::string TaylorLoops::in_pool(const std::string &text) const {
  Names names;
  std::vector<size_t> rows;
  for (const auto &[name, row] : row_of) {
    names.emplace(name, std::pair(Token::Array, rows.size()));
    rows.push_back(row);
  }
  std::string out;
  size_t at = 0;
  for (const Token &token : tokens_of(text, names, false)) {
    out += text.substr(at, token.begin - at) + pool + "[" +
           std::to_string(rows[size_t(token.value)]) + "]";
    at = token.end;
  }
  return out + text.substr(at);
}

TaylorLoops plan_taylor_loops(const std::vector<std::string> &statements,
                              const std::vector<std::string> &arrays,
                              const std::vector<std::string> &before_loop,
                              const std::vector<std::string> &scalars, const std::string &pool,
                              const std::string &scalar_array) {
  Names names;
  for (size_t a = 0; a < arrays.size(); ++a)
    names.emplace(arrays[a], std::pair(Token::Array, a));
  for (size_t k = 0; k < scalars.size(); ++k)
    names.emplace(scalars[k], std::pair(Token::Scalar, k));
  const size_t kNone = size_t(-1);
  // writer[a]: the statement that writes array a, the first that names it.
  std::vector<size_t> writer(arrays.size(), kNone);
  std::vector<bool> filled_before(arrays.size(), false);
  for (const std::string &name : before_loop)
    filled_before[names.at(name).second] = true;
  std::vector<Shape> shapes;
  std::vector<size_t> depth(statements.size(), 0);
  std::vector<Group> groups;
  std::map<std::pair<size_t, std::string>, size_t> group_of;
  size_t largest = 0;
  for (size_t i = 0; i < statements.size(); ++i) {
    shapes.push_back(shape_of(statements[i], names));
    for (const Token &slot : shapes[i].slots) {
      const size_t a = size_t(slot.value);
      if (slot.kind != Token::Array || filled_before[a]) continue;
      if (writer[a] == kNone)
        writer[a] = i;
      else
        depth[i] = std::max(depth[i], depth[writer[a]] + 1);
    }
    auto [it, fresh] = group_of.emplace(std::pair(depth[i], shapes[i].text), groups.size());
    if (fresh) groups.push_back({depth[i], {}});
    groups[it->second].members.push_back(i);
    largest = std::max(largest, groups[it->second].members.size());
  }
  TaylorLoops plan;
  if (largest < kMinLoopInstances) return plan;
  plan.pool = pool;

  // The depths in order, a depth's groups in the order of their first statements.
  std::vector<size_t> order(groups.size());
  for (size_t g = 0; g < groups.size(); ++g)
    order[g] = g;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return groups[a].depth < groups[b].depth; });

  // A group's members are independent (they read only arrays of smaller depths), so they may
  // run in any order: those that index (the loads of the state's components) in the order
  // of their indices, so that the rows they write are in that order too.
  for (Group &group : groups) {
    auto indices = [&](size_t i) {
      std::vector<long> v;
      for (const Token &slot : shapes[i].slots)
        if (slot.kind == Token::Index) v.push_back(slot.value);
      return v;
    };
    if (!indices(group.members[0]).empty())
      std::stable_sort(group.members.begin(), group.members.end(),
                       [&](size_t a, size_t b) { return indices(a) < indices(b); });
  }

  // Rows: the arrays filled before the loop, then the others as the statements write them.
  std::vector<size_t> row(arrays.size(), kNone);
  size_t rows = 0;
  for (size_t a = 0; a < arrays.size(); ++a)
    if (filled_before[a]) row[a] = rows++;
  for (size_t g : order)
    for (size_t i : groups[g].members)
      for (const Token &slot : shapes[i].slots)
        if (slot.kind == Token::Array && writer[size_t(slot.value)] == i)
          row[size_t(slot.value)] = rows++;
  for (size_t a = 0; a < arrays.size(); ++a)
    if (row[a] == kNone) row[a] = rows++; // named by no statement
  plan.rows = rows;
  for (size_t a = 0; a < arrays.size(); ++a)
    plan.row_of[arrays[a]] = row[a];

  const std::string table = pool + "_rows";
  std::vector<long> entries;
  // A slot as C, given its value (a row, a scalar's number, an index) as C: an array's row
  // of the pool, a scalar by its name when it is one for all members, else an element of
  // scalar_array, an index as it is.
  auto slot_c = [&](const Token &slot, const std::string &value, bool uniform) {
    switch (slot.kind) {
    case Token::Array: return pool + "[" + value + "]";
    case Token::Scalar:
      if (uniform) return scalars[size_t(slot.value)];
      plan.scalar_array = true;
      return scalar_array + "[" + value + "]";
    case Token::Index: break;
    }
    return value;
  };
  auto value_at = [&](const Token &slot) {
    return slot.kind == Token::Array ? long(row[size_t(slot.value)]) : slot.value;
  };
  for (size_t g : order) {
    const std::vector<size_t> &members = groups[g].members;
    const Shape &first = shapes[members[0]];
    const size_t nslots = first.slots.size();
    if (members.size() < kMinGroup) {
      for (size_t i : members) {
        std::vector<std::string> slot_text;
        for (const Token &slot : shapes[i].slots)
          slot_text.push_back(slot_c(slot, std::to_string(value_at(slot)), true));
        plan.body += "    " + instantiate(first.text, slot_text) + "\n";
      }
      continue;
    }
    // Slot s's values over the members; the form that leaves the fewest in a table.
    std::vector<std::vector<long>> columns(nslots);
    for (size_t s = 0; s < nslots; ++s)
      for (size_t i : members)
        columns[s].push_back(value_at(shapes[i].slots[s]));
    std::vector<std::optional<Affine>> fits;
    LoopForm form;
    size_t fewest = nslots + 1;
    for (const LoopForm &candidate : forms_for(members.size())) {
      std::vector<std::optional<Affine>> candidate_fits;
      size_t tabled = 0;
      for (size_t s = 0; s < nslots; ++s) {
        std::optional<Affine> fit = fit_members(columns[s]);
        if (!fit && candidate.lanes * std::max<size_t>(candidate.pairs, 1) > 1)
          fit = fit_form(columns[s], candidate);
        tabled += !fit;
        candidate_fits.push_back(std::move(fit));
      }
      if (tabled < fewest) {
        fewest = tabled;
        form = candidate;
        fits = std::move(candidate_fits);
      }
    }
    // Slot s as C: its fit, or the table's next column.
    std::vector<std::string> slot_text(nslots);
    std::vector<size_t> tabled;
    bool counts_members = false;
    for (size_t s = 0; s < nslots; ++s) {
      const Token &slot = first.slots[s];
      if (!fits[s]) {
        slot_text[s] = slot_c(slot, "row[" + std::to_string(tabled.size()) + "]", false);
        tabled.push_back(s);
        counts_members = true;
        continue;
      }
      const Affine &fit = *fits[s];
      std::string index = fit.text();
      counts_members = counts_members || (!fit.uniform() && fit.terms[0].second == "i");
      if (fit.uniform())
        slot_text[s] = slot_c(slot, index, true);
      else
        slot_text[s] = slot_c(slot, slot.kind == Token::Index ? "(" + index + ")" : index, false);
    }
    // The loops: over the members, or their steps (or pairs) and lanes, counting the members
    // in i when a slot needs it.
    const std::string count = std::to_string(members.size()), lanes = std::to_string(form.lanes);
    const std::string i = counts_members ? ", ++i" : "";
    std::string indent = "    ";
    auto open = [&](const std::string &header) {
      plan.body += indent + header + " {\n";
      indent += "  ";
    };
    if (form.lanes == 1 && form.pairs == 0) {
      open("for (int i = 0; i < " + count + "; ++i)");
    } else if (form.pairs == 0) {
      open("for (int step = 0" + std::string(counts_members ? ", i = 0" : "") + "; step < " +
           std::to_string(members.size() / form.lanes) + "; ++step)");
      open("for (int lane = 0; lane < " + lanes + "; ++lane" + i + ")");
    } else {
      const std::string n = std::to_string(form.pairs);
      open("for (int first = 0" + std::string(counts_members ? ", i = 0" : "") + "; first < " + n +
           "; ++first)");
      if (form.lanes == 1) {
        open("for (int second = first + 1; second < " + n + "; ++second" + i + ")");
      } else {
        open("for (int second = first + 1; second < " + n + "; ++second)");
        open("for (int lane = 0; lane < " + lanes + "; ++lane" + i + ")");
      }
    }
    if (!tabled.empty()) {
      plan.body += indent + "const int *row = " + table + " + " + std::to_string(entries.size());
      plan.body +=
          tabled.size() == 1 ? " + i;\n" : " + " + std::to_string(tabled.size()) + " * i;\n";
      for (size_t m = 0; m < members.size(); ++m)
        for (size_t s : tabled)
          entries.push_back(columns[s][m]);
    }
    plan.body += indent + instantiate(first.text, slot_text) + "\n";
    while (indent.size() > 4) {
      indent.resize(indent.size() - 2);
      plan.body += indent + "}\n";
    }
  }
  if (!entries.empty()) {
    plan.tables = "  static const int " + table + "[" + std::to_string(entries.size()) + "] = {";
    for (size_t e = 0; e < entries.size(); ++e)
      plan.tables += (e % 16 == 0 ? "\n     " : "") + std::string(" ") +
                     std::to_string(entries[e]) + (e + 1 < entries.size() ? "," : "");
    plan.tables += "\n  };\n";
  }
  return plan;
}

} // namespace sicm
