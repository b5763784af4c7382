// The book's display conventions for names, as Unicode text and as TeX.
#include "print/display_names.hpp"

#include <cstdint>
#include <vector>

#include "base/utf8.hpp"

namespace sicm {

namespace {

struct Greek {
  const char *name;
  const char *text; // UTF-8
  const char *tex;
};

// Capitals whose letter looks Latin (Alpha, Beta, ...) are left out on
// purpose: the book never uses them, and "A" or "B" would read as Latin.
const Greek kGreek[] = {
    {"alpha", "α", "\\alpha"},   {"beta", "β", "\\beta"},       {"gamma", "γ", "\\gamma"},
    {"delta", "δ", "\\delta"},   {"epsilon", "ε", "\\epsilon"}, {"zeta", "ζ", "\\zeta"},
    {"eta", "η", "\\eta"},       {"theta", "θ", "\\theta"},     {"iota", "ι", "\\iota"},
    {"kappa", "κ", "\\kappa"},   {"lambda", "λ", "\\lambda"},   {"mu", "μ", "\\mu"},
    {"nu", "ν", "\\nu"},         {"xi", "ξ", "\\xi"},           {"omicron", "ο", "o"},
    {"pi", "π", "\\pi"},         {"rho", "ρ", "\\rho"},         {"sigma", "σ", "\\sigma"},
    {"tau", "τ", "\\tau"},       {"upsilon", "υ", "\\upsilon"}, {"phi", "φ", "\\phi"},
    {"chi", "χ", "\\chi"},       {"psi", "ψ", "\\psi"},         {"omega", "ω", "\\omega"},
    {"Gamma", "Γ", "\\Gamma"},   {"Delta", "Δ", "\\Delta"},     {"Theta", "Θ", "\\Theta"},
    {"Lambda", "Λ", "\\Lambda"}, {"Xi", "Ξ", "\\Xi"},           {"Pi", "Π", "\\Pi"},
    {"Sigma", "Σ", "\\Sigma"},   {"Phi", "Φ", "\\Phi"},         {"Psi", "Ψ", "\\Psi"},
    {"Omega", "Ω", "\\Omega"},
};

// (character, its subscript or superscript form) as code points.
struct Script {
  uint32_t from, to;
};

const Script kSubscripts[] = {
    {'0', 0x2080},   {'1', 0x2081},   {'2', 0x2082},   {'3', 0x2083},   {'4', 0x2084},
    {'5', 0x2085},   {'6', 0x2086},   {'7', 0x2087},   {'8', 0x2088},   {'9', 0x2089},
    {'+', 0x208A},   {'-', 0x208B},   {'=', 0x208C},   {'(', 0x208D},   {')', 0x208E},
    {'a', 0x2090},   {'e', 0x2091},   {'o', 0x2092},   {'x', 0x2093},   {'h', 0x2095},
    {'k', 0x2096},   {'l', 0x2097},   {'m', 0x2098},   {'n', 0x2099},   {'p', 0x209A},
    {'s', 0x209B},   {'t', 0x209C},   {'i', 0x1D62},   {'r', 0x1D63},   {'u', 0x1D64},
    {'v', 0x1D65},   {'j', 0x2C7C},   {0x3B2, 0x1D66}, {0x3B3, 0x1D67}, {0x3C1, 0x1D68},
    {0x3C6, 0x1D69}, {0x3C7, 0x1D6A},
};

const Script kSuperscripts[] = {
    {'0', 0x2070},   {'1', 0x00B9},   {'2', 0x00B2},   {'3', 0x00B3},   {'4', 0x2074},
    {'5', 0x2075},   {'6', 0x2076},   {'7', 0x2077},   {'8', 0x2078},   {'9', 0x2079},
    {'+', 0x207A},   {'-', 0x207B},   {'=', 0x207C},   {'(', 0x207D},   {')', 0x207E},
    {'a', 0x1D43},   {'b', 0x1D47},   {'c', 0x1D9C},   {'d', 0x1D48},   {'e', 0x1D49},
    {'f', 0x1DA0},   {'g', 0x1D4D},   {'h', 0x02B0},   {'i', 0x2071},   {'j', 0x02B2},
    {'k', 0x1D4F},   {'l', 0x02E1},   {'m', 0x1D50},   {'n', 0x207F},   {'o', 0x1D52},
    {'p', 0x1D56},   {'r', 0x02B3},   {'s', 0x02E2},   {'t', 0x1D57},   {'u', 0x1D58},
    {'v', 0x1D5B},   {'w', 0x02B7},   {'x', 0x02E3},   {'y', 0x02B8},   {'z', 0x1DBB},
    {0x3B2, 0x1D5D}, {0x3B3, 0x1D5E}, {0x3B4, 0x1D5F}, {0x3B8, 0x1DBF}, {0x3C6, 0x1D60},
    {0x3C7, 0x1D61},
};

template <size_t N>
std::optional<std::string> map_script(std::string_view text, const Script (&table)[N]) {
  if (text.empty()) return std::nullopt;
  std::string out;
  while (!text.empty()) {
    size_t len;
    uint32_t cp = decode_utf8(text, len);
    text.remove_prefix(len);
    const Script *hit = nullptr;
    for (const Script &s : table)
      if (s.from == cp) hit = &s;
    if (!hit) return std::nullopt;
    append_utf8(out, hit->to);
  }
  return out;
}

// A name cut into its parts: base, trailing dots, then "_x" / "^y" marks.
struct NameParts {
  std::string_view base;
  int dots = 0;
  std::vector<std::pair<char, std::string_view>> marks;
};

std::optional<NameParts> split_name(std::string_view name) {
  NameParts p;
  size_t pos = name.find_first_of("_^");
  p.base = name.substr(0, pos);
  if (p.base.empty()) return std::nullopt;
  while (pos != std::string_view::npos) {
    size_t next = name.find_first_of("_^", pos + 1);
    std::string_view part =
        name.substr(pos + 1, next == std::string_view::npos ? next : next - pos - 1);
    if (part.empty()) return std::nullopt;
    p.marks.emplace_back(name[pos], part);
    pos = next;
  }
  // A base that is all dots ("dot", "dotdot") names nothing being
  // differentiated, so it keeps its letters.
  std::string_view base = p.base;
  int dots = 0;
  while (dots < 3 && base.size() > 3 && base.ends_with("dot")) {
    base.remove_suffix(3);
    ++dots;
  }
  if (base != "dot") {
    p.base = base;
    p.dots = dots;
  }
  return p;
}

// The Greek letter a base names, alone or followed by digits ("theta1"):
// the letter's entry and the digits, or nullptr.
const Greek *greek_prefix(std::string_view base, std::string_view &digits) {
  for (const Greek &g : kGreek) {
    std::string_view n = g.name;
    if (!base.starts_with(n)) continue;
    std::string_view rest = base.substr(n.size());
    bool all_digits = true;
    for (char c : rest)
      all_digits = all_digits && c >= '0' && c <= '9';
    if (all_digits) {
      digits = rest;
      return &g;
    }
  }
  return nullptr;
}

// One symbol or \mathit{several}: in TeX math, "ys" would be y times s.
std::string tex_word(std::string_view s) {
  size_t len = 0;
  if (!s.empty()) decode_utf8(s, len);
  if (len == s.size()) return tex_escape(s);
  return "\\mathit{" + tex_escape(s) + "}";
}

} // namespace

std::string tex_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
    case '#':
    case '$':
    case '%':
    case '&':
    case '{':
    case '}':
    case '_':
      out += '\\';
      out += c;
      break;
    case '~': out += "\\sim{}"; break;
    case '^': out += "\\wedge{}"; break;
    case '\\': out += "\\backslash{}"; break;
    default: out += c;
    }
  }
  return out;
}

std::optional<std::string> to_subscript(std::string_view text) {
  return map_script(text, kSubscripts);
}

std::optional<std::string> to_superscript(std::string_view text) {
  return map_script(text, kSuperscripts);
}

std::string display_name(std::string_view name) {
  std::optional<NameParts> p = split_name(name);
  if (!p) return std::string(name);
  std::string_view digits;
  const Greek *g = greek_prefix(p->base, digits);
  std::string out = g ? std::string(g->text) + std::string(digits) : std::string(p->base);
  // Combining dot, diaeresis, three dots above: placed on the last letter.
  static const uint32_t kDots[] = {0, 0x0307, 0x0308, 0x20DB};
  if (p->dots) append_utf8(out, kDots[p->dots]);
  for (auto [mark, part] : p->marks) {
    std::string shown = display_name(part);
    std::optional<std::string> script = mark == '_' ? to_subscript(shown) : to_superscript(shown);
    if (script) {
      out += *script;
    } else {
      out += mark;
      out += shown;
    }
  }
  return out;
}

std::string tex_name(std::string_view name) {
  std::optional<NameParts> p = split_name(name);
  if (!p) return tex_word(name);
  std::string_view digits;
  const Greek *g = greek_prefix(p->base, digits);
  std::string out = g ? std::string(g->tex) + std::string(digits) : tex_word(p->base);
  static const char *const kDots[] = {"", "\\dot", "\\ddot", "\\dddot"};
  if (p->dots) out = std::string(kDots[p->dots]) + "{" + out + "}";
  for (auto [mark, part] : p->marks) {
    out += mark;
    out += "{" + tex_name(part) + "}";
  }
  return out;
}

} // namespace sicm
