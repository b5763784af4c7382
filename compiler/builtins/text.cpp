// Character, string and symbol primitives, with MIT Scheme's names, semantics and errors.
//
// Strings are mutable UTF-8 byte buffers and indices count bytes, which is
// exact for the ASCII text SICM programs handle. Characters are code points:
// putting a character into a string encodes it, and reading one decodes the
// sequence that starts at the index, so non-ASCII text round-trips through
// string->list and list->string.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "base/primitive.hpp"
#include "base/utf8.hpp"
#include "builtins/builtins.hpp"
#include "eval/effect_guard.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

// ---- UTF-8 -------------------------------------------------------------------

// The character whose encoding starts at s[pos]; *n receives its length in bytes.
uint32_t get_utf8(std::string_view s, size_t pos, size_t *n) {
  return decode_utf8(s.substr(pos), *n);
}

// ---- arguments ---------------------------------------------------------------

bool supplied(Value *args, int nargs, int i) {
  return i < nargs && !args[i].is(Tag::Default);
}

uint32_t arg_char(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::Char)) wrong_type(args[i], i + 1, who);
  return args[i].ch;
}

String *arg_str(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::String)) wrong_type(args[i], i + 1, who);
  return args[i].string();
}

// A length or count: MIT's guarantee of an index-fixnum reports a wrong type.
size_t arg_count(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::Fixnum) || args[i].i < 0) wrong_type(args[i], i + 1, who);
  if (args[i].i > (int64_t{1} << 31)) bad_range(args[i], i + 1, who);
  return static_cast<size_t>(args[i].i);
}

// Optional [start, end) arguments at positions i and i+1, checked as MIT does:
// end against the length first, then start against end.
std::pair<size_t, size_t> arg_span(Value *args, int nargs, int i, size_t len, const char *who) {
  size_t end = supplied(args, nargs, i + 1) ? arg_bounded(args, i + 1, 0, len, who) : len;
  size_t start = supplied(args, nargs, i) ? arg_bounded(args, i, 0, end, who) : 0;
  return {start, end};
}

Value str(std::string_view s) {
  return make_string(s);
}
Value boolean(bool b) {
  return Value::boolean(b);
}

// ---- characters --------------------------------------------------------------

// Case mapping covers ASCII, Latin-1 and Greek: enough for the letters SICM
// programs name variables with, without a Unicode table.
bool is_upper(uint32_t c) {
  return (c >= 'A' && c <= 'Z') || (c >= 0xC0 && c <= 0xDE && c != 0xD7) ||
         (c >= 0x391 && c <= 0x3A9 && c != 0x3A2);
}
bool is_lower(uint32_t c) {
  return (c >= 'a' && c <= 'z') || (c >= 0xDF && c <= 0xFF && c != 0xF7) ||
         (c >= 0x3B1 && c <= 0x3C9);
}
uint32_t upcase(uint32_t c) {
  if ((c >= 'a' && c <= 'z') || (c >= 0xE0 && c <= 0xFE && c != 0xF7) ||
      (c >= 0x3B1 && c <= 0x3C9 && c != 0x3C2))
    return c - 0x20;
  return c;
}
uint32_t downcase(uint32_t c) {
  if ((c >= 'A' && c <= 'Z') || (c >= 0xC0 && c <= 0xDE && c != 0xD7) ||
      (c >= 0x391 && c <= 0x3A9 && c != 0x3A2))
    return c + 0x20;
  return c;
}
bool is_alphabetic(uint32_t c) {
  return is_upper(c) || is_lower(c) || c == 0x3C2;
}
bool is_numeric(uint32_t c) {
  return c >= '0' && c <= '9';
}
bool is_whitespace(uint32_t c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' || c == 0xA0;
}

// The value of c as a digit in any radix up to 36, or -1.
int digit_of(uint32_t c) {
  if (c >= '0' && c <= '9') return static_cast<int>(c - '0');
  if (c >= 'a' && c <= 'z') return static_cast<int>(c - 'a' + 10);
  if (c >= 'A' && c <= 'Z') return static_cast<int>(c - 'A' + 10);
  return -1;
}

int arg_radix(Value *args, int nargs, int i, const char *who) {
  if (!supplied(args, nargs, i)) return 10;
  return static_cast<int>(arg_bounded(args, i, 2, 36, who));
}

enum class Cmp { Eq, Lt, Gt, Le, Ge };

bool holds(int c, Cmp op) {
  switch (op) {
  case Cmp::Eq: return c == 0;
  case Cmp::Lt: return c < 0;
  case Cmp::Gt: return c > 0;
  case Cmp::Le: return c <= 0;
  case Cmp::Ge: return c >= 0;
  }
  return false;
}

// n-ary comparison: every argument is checked even after the answer is known.
Value compare_chars(Value *args, int nargs, const char *who, Cmp op, bool fold) {
  for (int i = 0; i < nargs; ++i)
    arg_char(args, i, who);
  bool ok = true;
  for (int i = 0; i + 1 < nargs; ++i) {
    uint32_t a = args[i].ch, b = args[i + 1].ch;
    if (fold) a = downcase(a), b = downcase(b);
    ok = ok && holds(a < b ? -1 : a > b ? 1 : 0, op);
  }
  return boolean(ok);
}

// ---- strings -----------------------------------------------------------------

std::string fold_case(std::string_view s, bool up) {
  std::string out;
  for (size_t i = 0; i < s.size();) {
    size_t n;
    uint32_t c = get_utf8(s, i, &n);
    if (n == 1 && c >= 0x80)
      out += s[i]; // a stray byte stays as it is
    else
      append_utf8(out, up ? upcase(c) : downcase(c));
    i += n;
  }
  return out;
}

int compare_bytes(std::string_view a, std::string_view b) {
  int c = a.compare(b); // byte order of UTF-8 is code-point order
  return c < 0 ? -1 : c > 0 ? 1 : 0;
}

Value compare_strings(Value *args, int nargs, const char *who, Cmp op, bool fold) {
  for (int i = 0; i < nargs; ++i)
    arg_str(args, i, who);
  bool ok = true;
  for (int i = 0; i + 1 < nargs && ok; ++i) {
    std::string_view a = string_view(args[i]), b = string_view(args[i + 1]);
    ok = fold ? holds(compare_bytes(fold_case(a, false), fold_case(b, false)), op)
              : holds(compare_bytes(a, b), op);
  }
  return boolean(ok);
}

// The display forms of all arguments, concatenated: MIT's `string` and `symbol`.
std::string display_concat(Value *args, int nargs) {
  std::string out;
  for (int i = 0; i < nargs; ++i)
    print_value(out, args[i], true);
  return out;
}

// Replace bytes [pos, pos+n) of s with text. The String object stays the same
// (string-set! mutates), but its buffer is reallocated when the size changes.
void splice(String *s, size_t pos, size_t n, std::string_view text) {
  if (text.size() == n) {
    std::memcpy(s->data + pos, text.data(), n);
    return;
  }
  std::string joined(s->data, pos);
  joined += text;
  joined.append(s->data + pos + n, s->len - pos - n);
  s->data = gc_strdup(joined);
  s->len = joined.size();
}

Value list_from_string(std::string_view s, size_t start, size_t end) {
  Value head = Value::nil(), tail = Value::nil();
  for (size_t i = start; i < end;) {
    size_t n;
    Value c = Value::character(get_utf8(s.substr(0, end), i, &n));
    Value cell = cons(c, Value::nil());
    if (is_null(head))
      head = cell;
    else
      tail.pair()->cdr = cell;
    tail = cell;
    i += n;
  }
  return head;
}

// string-pad-left / string-pad-right: MIT truncates on the side the padding
// would go, so a number padded left keeps its low-order digits.
Value pad(Value *args, int nargs, bool left, const char *who) {
  std::string_view s = arg_string(args, 0, who);
  size_t n = arg_count(args, 1, who);
  uint32_t fill = supplied(args, nargs, 2) ? arg_char(args, 2, who) : ' ';
  if (n <= s.size()) return str(left ? s.substr(s.size() - n) : s.substr(0, n));
  std::string padding;
  for (size_t i = s.size(); i < n; ++i)
    append_utf8(padding, fill);
  return str(left ? padding + std::string(s) : std::string(s) + padding);
}

int64_t g_symbol_counter = 10;

void install_characters() {
  define_primitive("char?", 1, 1, Stage::Pure,
                   [](Value *a, int) { return boolean(a[0].is(Tag::Char)); });
  define_primitive("char->integer", 1, 1, Stage::Pure,
                   [](Value *a, int) { return Value::fixnum(arg_char(a, 0, "char->integer")); });
  define_primitive("integer->char", 1, 1, Stage::Pure, [](Value *a, int) {
    if (!a[0].is(Tag::Fixnum)) wrong_type(a[0], 1, "integer->char");
    int64_t n = a[0].i;
    if (n < 0 || n > 0x10FFFF || (n >= 0xD800 && n <= 0xDFFF)) bad_range(a[0], 1, "integer->char");
    return Value::character(static_cast<uint32_t>(n));
  });
  define_primitive("char=?", 1, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return compare_chars(a, n, "char=?", Cmp::Eq, false); });
  define_primitive("char<?", 1, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return compare_chars(a, n, "char<?", Cmp::Lt, false); });
  define_primitive("char>?", 1, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return compare_chars(a, n, "char>?", Cmp::Gt, false); });
  define_primitive("char<=?", 1, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return compare_chars(a, n, "char<=?", Cmp::Le, false); });
  define_primitive("char>=?", 1, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return compare_chars(a, n, "char>=?", Cmp::Ge, false); });
  define_primitive("char-ci=?", 1, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return compare_chars(a, n, "char-ci=?", Cmp::Eq, true); });
  define_primitive("char-upcase", 1, 1, Stage::Pure, [](Value *a, int) {
    return Value::character(upcase(arg_char(a, 0, "char-upcase")));
  });
  define_primitive("char-downcase", 1, 1, Stage::Pure, [](Value *a, int) {
    return Value::character(downcase(arg_char(a, 0, "char-downcase")));
  });
  define_primitive("char-alphabetic?", 1, 1, Stage::Pure, [](Value *a, int) {
    return boolean(is_alphabetic(arg_char(a, 0, "char-alphabetic?")));
  });
  define_primitive("char-numeric?", 1, 1, Stage::Pure, [](Value *a, int) {
    return boolean(is_numeric(arg_char(a, 0, "char-numeric?")));
  });
  define_primitive("char-whitespace?", 1, 1, Stage::Pure, [](Value *a, int) {
    return boolean(is_whitespace(arg_char(a, 0, "char-whitespace?")));
  });
  define_primitive("char-upper-case?", 1, 1, Stage::Pure, [](Value *a, int) {
    return boolean(is_upper(arg_char(a, 0, "char-upper-case?")));
  });
  define_primitive("char-lower-case?", 1, 1, Stage::Pure, [](Value *a, int) {
    return boolean(is_lower(arg_char(a, 0, "char-lower-case?")));
  });
  define_primitive("digit-value", 1, 1, Stage::Pure, [](Value *a, int) {
    uint32_t c = arg_char(a, 0, "digit-value");
    return is_numeric(c) ? Value::fixnum(c - '0') : boolean(false);
  });
  define_primitive("char->digit", 1, 2, Stage::Pure, [](Value *a, int n) {
    uint32_t c = arg_char(a, 0, "char->digit");
    int radix = arg_radix(a, n, 1, "char->digit");
    int d = digit_of(c);
    return d >= 0 && d < radix ? Value::fixnum(d) : boolean(false);
  });
  define_primitive("digit->char", 1, 2, Stage::Pure, [](Value *a, int n) {
    if (!a[0].is(Tag::Fixnum)) wrong_type(a[0], 1, "digit->char");
    int radix = arg_radix(a, n, 1, "digit->char");
    int64_t d = a[0].i;
    if (d < 0 || d >= radix) return boolean(false);
    return Value::character(static_cast<uint32_t>("0123456789abcdefghijklmnopqrstuvwxyz"[d]));
  });
  define_primitive("char->string", 1, 1, Stage::Pure, [](Value *a, int) {
    std::string s;
    append_utf8(s, arg_char(a, 0, "char->string"));
    return str(s);
  });
}

void install_strings() {
  define_primitive("string?", 1, 1, Stage::Pure,
                   [](Value *a, int) { return boolean(a[0].is(Tag::String)); });
  define_primitive("make-string", 1, 2, Stage::Pure, [](Value *a, int n) {
    size_t k = arg_count(a, 0, "make-string");
    uint32_t fill = supplied(a, n, 1) ? arg_char(a, 1, "make-string") : ' ';
    std::string s;
    for (size_t i = 0; i < k; ++i)
      append_utf8(s, fill);
    return str(s);
  });
  define_primitive("string", 0, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return str(display_concat(a, n)); });
  define_primitive("string-length", 1, 1, Stage::Pure, [](Value *a, int) {
    return Value::fixnum(static_cast<int64_t>(arg_str(a, 0, "string-length")->len));
  });
  define_primitive("string-ref", 2, 2, Stage::Pure, [](Value *a, int) {
    String *s = arg_str(a, 0, "string-ref");
    if (!a[1].is(Tag::Fixnum)) wrong_type(a[1], 2, "string-ref");
    if (a[1].i < 0 || static_cast<size_t>(a[1].i) >= s->len) bad_range(a[1], 2, "string-ref");
    size_t n;
    return Value::character(get_utf8(string_view(a[0]), static_cast<size_t>(a[1].i), &n));
  });
  define_primitive("string-set!", 3, 3, Stage::Effect, [](Value *a, int) {
    String *s = arg_str(a, 0, "string-set!");
    refuse_change_of(a[0], "string-set!");
    if (!a[1].is(Tag::Fixnum)) wrong_type(a[1], 2, "string-set!");
    if (a[1].i < 0 || static_cast<size_t>(a[1].i) >= s->len) bad_range(a[1], 2, "string-set!");
    uint32_t c = arg_char(a, 2, "string-set!");
    size_t pos = static_cast<size_t>(a[1].i), n;
    get_utf8(string_view(a[0]), pos, &n);
    std::string text;
    append_utf8(text, c);
    splice(s, pos, n, text);
    return Value::unspecified();
  });
  define_primitive("substring", 2, 3, Stage::Pure, [](Value *a, int n) {
    arg_str(a, 0, "substring");
    std::string_view s = string_view(a[0]);
    auto [start, end] = arg_span(a, n, 1, s.size(), "substring");
    return str(s.substr(start, end - start));
  });
  define_primitive("string-head", 2, 2, Stage::Pure, [](Value *a, int) {
    arg_str(a, 0, "string-head");
    std::string_view s = string_view(a[0]);
    return str(s.substr(0, arg_bounded(a, 1, 0, s.size(), "string-head")));
  });
  define_primitive("string-tail", 2, 2, Stage::Pure, [](Value *a, int) {
    arg_str(a, 0, "string-tail");
    std::string_view s = string_view(a[0]);
    return str(s.substr(arg_bounded(a, 1, 0, s.size(), "string-tail")));
  });
  define_primitive("string-append", 0, kVariadic, Stage::Pure, [](Value *a, int n) {
    std::string out;
    for (int i = 0; i < n; ++i) {
      arg_str(a, i, "string-append");
      out += string_view(a[i]);
    }
    return str(out);
  });
  define_primitive("string-copy", 1, 3, Stage::Pure, [](Value *a, int n) {
    arg_str(a, 0, "string-copy");
    std::string_view s = string_view(a[0]);
    auto [start, end] = arg_span(a, n, 1, s.size(), "string-copy");
    return str(s.substr(start, end - start));
  });
  define_primitive("string->list", 1, 3, Stage::Pure, [](Value *a, int n) {
    arg_str(a, 0, "string->list");
    std::string_view s = string_view(a[0]);
    auto [start, end] = arg_span(a, n, 1, s.size(), "string->list");
    return list_from_string(s, start, end);
  });
  define_primitive("list->string", 1, 1, Stage::Pure, [](Value *a, int) {
    if (list_length(a[0]) < 0) wrong_type(a[0], 1, "list->string");
    std::string out;
    for (Value p = a[0]; is_pair(p); p = cdr(p)) {
      if (!car(p).is(Tag::Char)) wrong_type(car(p), 1, "list->string");
      append_utf8(out, car(p).ch);
    }
    return str(out);
  });
  define_primitive("string-null?", 1, 1, Stage::Pure,
                   [](Value *a, int) { return boolean(arg_str(a, 0, "string-null?")->len == 0); });
  define_primitive("string-upcase", 1, 1, Stage::Pure, [](Value *a, int) {
    arg_str(a, 0, "string-upcase");
    return str(fold_case(string_view(a[0]), true));
  });
  define_primitive("string-downcase", 1, 1, Stage::Pure, [](Value *a, int) {
    arg_str(a, 0, "string-downcase");
    return str(fold_case(string_view(a[0]), false));
  });
  define_primitive("string-reverse", 1, 1, Stage::Pure, [](Value *a, int) {
    arg_str(a, 0, "string-reverse");
    // Reverse characters, not bytes, so multi-byte characters stay intact.
    std::string_view s = string_view(a[0]);
    std::string out(s.size(), '\0');
    for (size_t i = 0; i < s.size();) {
      size_t n;
      get_utf8(s, i, &n);
      out.replace(s.size() - i - n, n, s.substr(i, n));
      i += n;
    }
    return str(out);
  });

  define_primitive("string=?", 1, kVariadic, Stage::Pure, [](Value *a, int n) {
    return compare_strings(a, n, "string=?", Cmp::Eq, false);
  });
  define_primitive("string<?", 1, kVariadic, Stage::Pure, [](Value *a, int n) {
    return compare_strings(a, n, "string<?", Cmp::Lt, false);
  });
  define_primitive("string>?", 1, kVariadic, Stage::Pure, [](Value *a, int n) {
    return compare_strings(a, n, "string>?", Cmp::Gt, false);
  });
  define_primitive("string<=?", 1, kVariadic, Stage::Pure, [](Value *a, int n) {
    return compare_strings(a, n, "string<=?", Cmp::Le, false);
  });
  define_primitive("string>=?", 1, kVariadic, Stage::Pure, [](Value *a, int n) {
    return compare_strings(a, n, "string>=?", Cmp::Ge, false);
  });
  define_primitive("string-ci=?", 1, kVariadic, Stage::Pure, [](Value *a, int n) {
    return compare_strings(a, n, "string-ci=?", Cmp::Eq, true);
  });

  // (string-index string char-or-predicate [start end]) -> index or #f
  define_primitive("string-index", 2, 4, Stage::Pure, [](Value *a, int n) {
    arg_str(a, 0, "string-index");
    if (!a[1].is(Tag::Char) && !is_procedure(a[1])) wrong_type(a[1], 2, "string-index");
    auto [start, end] = arg_span(a, n, 2, string_view(a[0]).size(), "string-index");
    for (size_t i = start; i < end;) {
      size_t len;
      // Re-read the buffer each time: the predicate may mutate the string.
      std::string_view s = string_view(a[0]);
      if (i >= s.size()) break;
      Value c = Value::character(get_utf8(s, i, &len));
      bool hit = a[1].is(Tag::Char) ? c.ch == a[1].ch : apply_procedure(a[1], &c, 1).truthy();
      if (hit) return Value::fixnum(static_cast<int64_t>(i));
      i += len;
    }
    return boolean(false);
  });
  define_primitive("string-search-forward", 2, 3, Stage::Pure, [](Value *a, int n) {
    std::string_view pattern = arg_string(a, 0, "string-search-forward");
    std::string_view s = arg_string(a, 1, "string-search-forward");
    size_t start = supplied(a, n, 2) ? arg_bounded(a, 2, 0, s.size(), "string-search-forward") : 0;
    size_t at = s.find(pattern, start);
    return at == std::string_view::npos ? boolean(false) : Value::fixnum(static_cast<int64_t>(at));
  });
  // MIT returns the index just after the match, the place a backward scan stops.
  define_primitive("string-search-backward", 2, 3, Stage::Pure, [](Value *a, int n) {
    std::string_view pattern = arg_string(a, 0, "string-search-backward");
    std::string_view s = arg_string(a, 1, "string-search-backward");
    size_t end =
        supplied(a, n, 2) ? arg_bounded(a, 2, 0, s.size(), "string-search-backward") : s.size();
    if (pattern.size() > end) return boolean(false);
    size_t at = s.substr(0, end).rfind(pattern);
    return at == std::string_view::npos ? boolean(false)
                                        : Value::fixnum(static_cast<int64_t>(at + pattern.size()));
  });
  // Every index where pattern occurs, overlapping matches included.
  define_primitive("string-search-all", 2, 4, Stage::Pure, [](Value *a, int n) {
    std::string_view pattern = arg_string(a, 0, "string-search-all");
    std::string_view s = arg_string(a, 1, "string-search-all");
    auto [start, end] = arg_span(a, n, 2, s.size(), "string-search-all");
    gcvec<Value> hits;
    for (size_t at = s.find(pattern, start);
         at != std::string_view::npos && at + pattern.size() <= end; at = s.find(pattern, at + 1))
      hits.push_back(Value::fixnum(static_cast<int64_t>(at)));
    return list_from(hits.data(), hits.size());
  });
  define_primitive("string-prefix?", 2, 2, Stage::Pure, [](Value *a, int) {
    std::string_view p = arg_string(a, 0, "string-prefix?");
    std::string_view s = arg_string(a, 1, "string-prefix?");
    return boolean(s.substr(0, p.size()) == p);
  });
  define_primitive("string-suffix?", 2, 2, Stage::Pure, [](Value *a, int) {
    std::string_view p = arg_string(a, 0, "string-suffix?");
    std::string_view s = arg_string(a, 1, "string-suffix?");
    return boolean(s.size() >= p.size() && s.substr(s.size() - p.size()) == p);
  });
  define_primitive("string-pad-left", 2, 3, Stage::Pure,
                   [](Value *a, int n) { return pad(a, n, true, "string-pad-left"); });
  define_primitive("string-pad-right", 2, 3, Stage::Pure,
                   [](Value *a, int n) { return pad(a, n, false, "string-pad-right"); });
  // (string-join strings [delimiter]): the delimiter defaults to a space.
  define_primitive("string-join", 1, 2, Stage::Pure, [](Value *a, int n) {
    if (list_length(a[0]) < 0) wrong_type(a[0], 1, "string-join");
    std::string_view delim = " ";
    if (supplied(a, n, 1)) delim = arg_string(a, 1, "string-join");
    std::string out;
    for (Value p = a[0]; is_pair(p); p = cdr(p)) {
      if (!is_string(car(p))) wrong_type(car(p), 1, "string-join");
      if (!eq(p, a[0])) out += delim;
      out += string_view(car(p));
    }
    return str(out);
  });
}

void install_symbols() {
  define_primitive("symbol?", 1, 1, Stage::Pure,
                   [](Value *a, int) { return boolean(is_symbol(a[0])); });
  define_primitive("symbol->string", 1, 1, Stage::Pure,
                   [](Value *a, int) { return str(arg_symbol(a, 0, "symbol->string")->name); });
  define_primitive("string->symbol", 1, 1, Stage::Pure,
                   [](Value *a, int) { return intern(arg_string(a, 0, "string->symbol")); });
  define_primitive("intern", 1, 1, Stage::Pure,
                   [](Value *a, int) { return intern(arg_string(a, 0, "intern")); });
  define_primitive("string->uninterned-symbol", 1, 1, Stage::Pure, [](Value *a, int) {
    return make_uninterned_symbol(arg_string(a, 0, "string->uninterned-symbol"));
  });
  define_primitive("symbol-append", 0, kVariadic, Stage::Pure, [](Value *a, int n) {
    std::string name;
    for (int i = 0; i < n; ++i)
      name += arg_symbol(a, i, "symbol-append")->name;
    return intern(name);
  });
  // (symbol obj ...): MIT interns the concatenated display forms.
  define_primitive("symbol", 0, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return intern(display_concat(a, n)); });
  // (generate-uninterned-symbol [prefix]): a fresh symbol named like g12; a
  // symbol or string argument replaces the "g".
  define_primitive("generate-uninterned-symbol", 0, 1, Stage::Pure, [](Value *a, int n) {
    std::string name = "g";
    if (supplied(a, n, 0)) {
      if (is_symbol(a[0]))
        name = symbol_name(a[0]);
      else if (is_string(a[0]))
        name = string_view(a[0]);
    }
    name += std::to_string(++g_symbol_counter);
    return make_uninterned_symbol(name);
  });
  define_primitive("symbol<?", 1, kVariadic, Stage::Pure, [](Value *a, int n) {
    for (int i = 0; i < n; ++i)
      arg_symbol(a, i, "symbol<?");
    bool ok = true;
    for (int i = 0; i + 1 < n; ++i)
      ok = ok && symbol_name(a[i]) < symbol_name(a[i + 1]);
    return boolean(ok);
  });
}

} // namespace

void install_text_primitives() {
  install_characters();
  install_strings();
  install_symbols();
}

} // namespace sicm
