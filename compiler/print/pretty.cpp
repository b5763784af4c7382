// The pretty-printer of pp (see pretty.hpp for the rules).
#include "print/pretty.hpp"

#include <cstring>
#include <vector>

#include "print/printer.hpp"

namespace sicm {

namespace {

// A written form read back as a tree: an atom, or a list with the prefix
// written before its parenthesis (' ` , ,@ or the # of a vector).
struct TextNode {
  std::string prefix;
  std::string atom; // the text of an atom
  bool is_list = false;
  std::vector<TextNode> items;
  std::string flat; // the whole node on one line
};

bool is_delimiter(char c) {
  return c == ' ' || c == '\n' || c == '\t' || c == '(' || c == ')';
}

class Reader {
public:
  explicit Reader(const std::string &text) : s_(text) {}

  // Every node of the text (a written form is usually one).
  std::vector<TextNode> nodes() {
    std::vector<TextNode> out;
    while (skip_space(), i_ < s_.size()) {
      if (s_[i_] == ')') { // unbalanced: keep it as an atom
        out.push_back(atom_node(")"));
        ++i_;
        continue;
      }
      out.push_back(node());
    }
    return out;
  }

private:
  void skip_space() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\n' || s_[i_] == '\t'))
      ++i_;
  }

  static TextNode atom_node(std::string text) {
    TextNode n;
    n.atom = text;
    n.flat = std::move(text);
    return n;
  }

  TextNode node() {
    std::string prefix;
    for (;;) {
      if (s_.compare(i_, 2, ",@") == 0) {
        prefix += ",@";
        i_ += 2;
      } else if (i_ < s_.size() && (s_[i_] == '\'' || s_[i_] == '`' || s_[i_] == ',')) {
        prefix += s_[i_++];
      } else if (s_.compare(i_, 2, "#(") == 0) {
        prefix += '#';
        ++i_;
        break;
      } else {
        break;
      }
    }
    if (i_ < s_.size() && s_[i_] == '(') return list(prefix);
    TextNode n = atom_node(prefix + atom_text());
    return n;
  }

  TextNode list(const std::string &prefix) {
    TextNode n;
    n.prefix = prefix;
    n.is_list = true;
    ++i_; // (
    for (;;) {
      skip_space();
      if (i_ >= s_.size()) break;
      if (s_[i_] == ')') {
        ++i_;
        break;
      }
      n.items.push_back(node());
    }
    // (quote x) is written 'x, as MIT's pp writes it.
    if (n.items.size() == 2 && !n.items[0].is_list && n.items[0].atom == "quote") {
      TextNode quoted = n.items[1];
      quoted.prefix = prefix + "'" + quoted.prefix;
      quoted.flat = prefix + "'" + quoted.flat;
      if (!quoted.is_list) quoted.atom = quoted.flat;
      return quoted;
    }
    n.flat = prefix + "(";
    for (size_t k = 0; k < n.items.size(); ++k)
      n.flat += (k ? " " : "") + n.items[k].flat;
    n.flat += ")";
    return n;
  }

  // An atom: a string with its escapes, a #[...] object, a character, or
  // anything up to a delimiter.
  std::string atom_text() {
    size_t start = i_;
    if (i_ < s_.size() && s_[i_] == '"') {
      for (++i_; i_ < s_.size() && s_[i_] != '"'; ++i_)
        if (s_[i_] == '\\') ++i_;
      if (i_ < s_.size()) ++i_;
      return s_.substr(start, i_ - start);
    }
    if (s_.compare(i_, 2, "#[") == 0) {
      int depth = 0;
      for (; i_ < s_.size(); ++i_) {
        if (s_[i_] == '[') ++depth;
        if (s_[i_] == ']' && --depth == 0) {
          ++i_;
          break;
        }
      }
      return s_.substr(start, i_ - start);
    }
    if (s_.compare(i_, 2, "#\\") == 0) i_ = std::min(s_.size(), i_ + 3); // #\( is a character
    while (i_ < s_.size() && !is_delimiter(s_[i_]))
      ++i_;
    return s_.substr(start, i_ - start);
  }

  const std::string &s_;
  size_t i_ = 0;
};

// How many elements after the head stay on the first line of a special form
// whose body is indented by two (0: not such a form).
size_t header_items(const TextNode &n) {
  if (n.items.empty() || n.items[0].is_list) return 0;
  const std::string &head = n.items[0].atom;
  static const char *const kOne[] = {"define",  "lambda",    "named-lambda", "let*",  "letrec",
                                     "letrec*", "fluid-let", "when",         "unless"};
  for (const char *k : kOne)
    if (head == k) return 1;
  if (head == "let") return n.items.size() > 1 && !n.items[1].is_list ? 2 : 1;
  return 0;
}

class Layout {
public:
  explicit Layout(int width) : width_(static_cast<size_t>(width)) {}

  // n written from column col, followed on its last line by `trailing`
  // closing parentheses.
  std::string layout(const TextNode &n, size_t col, size_t trailing) {
    if (!n.is_list || n.items.empty() || col + n.flat.size() + trailing <= width_) return n.flat;
    size_t c = col + n.prefix.size(); // the column of the parenthesis
    const std::vector<TextNode> &items = n.items;
    size_t last = items.size() - 1;
    if (size_t h = header_items(n); h > 0 && last > h) {
      std::string out = n.prefix + "(" + items[0].atom;
      for (size_t k = 1; k <= h; ++k)
        out += " " + items[k].flat;
      for (size_t k = h + 1; k <= last; ++k)
        out += "\n" + pad(c + 2) + layout(items[k], c + 2, k == last ? trailing + 1 : 0);
      return out + ")";
    }
    if (!items[0].is_list && items[0].atom == "if" && last > 0) {
      // Code: the test and the alternatives stacked after "(if ", each laid out there.
      size_t standard = c + 4;
      std::string out =
          n.prefix + "(if " + layout(items[1], standard, last == 1 ? trailing + 1 : 0);
      for (size_t k = 2; k <= last; ++k)
        out += "\n" + pad(standard) + layout(items[k], standard, k == last ? trailing + 1 : 0);
      return out + ")";
    }
    if (!items[0].is_list && last > 0) {
      size_t standard = c + 1 + items[0].flat.size() + 1;
      bool fits = true;
      for (size_t k = 1; k <= last && fits; ++k)
        fits = standard + items[k].flat.size() + (k == last ? trailing + 1 : 0) <= width_;
      if (fits) {
        std::string out = n.prefix + "(" + items[0].flat + " " + items[1].flat;
        for (size_t k = 2; k <= last; ++k)
          out += "\n" + pad(standard) + items[k].flat;
        return out + ")";
      }
    }
    std::string out = n.prefix + "(" + layout(items[0], c + 1, last == 0 ? trailing + 1 : 0);
    for (size_t k = 1; k <= last; ++k)
      out += "\n" + pad(c + 1) + layout(items[k], c + 1, k == last ? trailing + 1 : 0);
    return out + ")";
  }

private:
  static std::string pad(size_t n) { return std::string(n, ' '); }

  size_t width_;
};

} // namespace

std::string pretty_text(const std::string &written, int width) {
  if (static_cast<int>(written.size()) <= width || written.find('(') == std::string::npos)
    return written;
  std::string out;
  Layout layout(width);
  for (const TextNode &n : Reader(written).nodes())
    out += (out.empty() ? "" : " ") + layout.layout(n, 0, 0);
  return out;
}

std::string pretty_string(Value v, int width) {
  return pretty_text(write_string(v), width);
}

} // namespace sicm
