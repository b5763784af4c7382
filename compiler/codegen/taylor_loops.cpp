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
// the member too (one pair's arrays after another's). A group of at least kMinGroup members
// is a loop over its members, each slot's row (or constant's number, or index) affine in the
// member number or read from a static table of ints; a smaller one stays straight-line. The pool
// lives on the heap, one per thread, allocated once: its size (rows x K coefficients) passes the
// stack's at about 60 bodies.
//
// Limits: loops only when a group has at least kMinLoopInstances members, so that small
// systems (Kepler, 10 bodies: 135 products of a pair's inverse cube by its differences) keep
// their straight-line C as it was, which the heyoka benchmark times. Larger ones ran faster
// as loops, as the kernels' loops do (codegen/loops.cpp): 16 bodies over 400 time units
// 0.40 s against 0.49 s straight-line, 32 bodies over 100 0.61 s against 0.85 s; and the C
// compiler took 10 s and 44 s for their straight-line C, under 1 s for the loops.
#include "codegen/taylor_loops.hpp"

#include <algorithm>
#include <map>
#include <string_view>

namespace sicm {

namespace {

constexpr size_t kMinLoopInstances = 256;
constexpr size_t kMinGroup = 4;

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
    // Slot s in member m: base + stride * m, or the table's next column.
    std::vector<std::string> slot_text(nslots);
    std::vector<size_t> tabled;
    for (size_t s = 0; s < nslots; ++s) {
      auto value_of_member = [&](size_t m) { return value_at(shapes[members[m]].slots[s]); };
      const Token &slot = first.slots[s];
      const long base = value_of_member(0), stride = value_of_member(1) - base;
      bool affine = true;
      for (size_t m = 2; m < members.size() && affine; ++m)
        affine = value_of_member(m) == base + stride * long(m);
      if (!affine) {
        slot_text[s] = slot_c(slot, "row[" + std::to_string(tabled.size()) + "]", false);
        tabled.push_back(s);
      } else if (stride == 0) {
        slot_text[s] = slot_c(slot, std::to_string(base), true);
      } else {
        std::string step =
            stride == 1 ? "i" : std::to_string(stride < 0 ? -stride : stride) + " * i";
        std::string index = std::to_string(base) + (stride < 0 ? " - " : " + ") + step;
        slot_text[s] = slot_c(slot, slot.kind == Token::Index ? "(" + index + ")" : index, false);
      }
    }
    plan.body += "    for (int i = 0; i < " + std::to_string(members.size()) + "; ++i) {\n";
    if (!tabled.empty()) {
      plan.body += "      const int *row = " + table + " + " + std::to_string(entries.size());
      plan.body +=
          tabled.size() == 1 ? " + i;\n" : " + " + std::to_string(tabled.size()) + " * i;\n";
      for (size_t i : members)
        for (size_t s : tabled)
          entries.push_back(value_at(shapes[i].slots[s]));
    }
    plan.body += "      " + instantiate(first.text, slot_text) + "\n    }\n";
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
