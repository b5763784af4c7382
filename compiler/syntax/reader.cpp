// The reader: a hand-written recursive-descent parser over the source text.
#include "syntax/reader.hpp"

#include <cctype>

#include "base/number.hpp"
#include "base/utf8.hpp"

namespace sicm {

namespace {

bool is_delimiter(int c) {
  return c == EOF || std::isspace(c) || c == '(' || c == ')' || c == '"' || c == ';' || c == '\'' ||
         c == '`' || c == ',';
}

// Named characters MIT Scheme understands after #\ .
struct NamedChar {
  const char *name;
  uint32_t code;
};
constexpr NamedChar kNamedChars[] = {
    {"space", ' '},   {"newline", '\n'},  {"tab", '\t'},   {"nul", 0},     {"null", 0},
    {"return", '\r'}, {"linefeed", '\n'}, {"altmode", 27}, {"escape", 27}, {"backspace", 8},
    {"delete", 127},  {"rubout", 127},    {"alarm", 7},    {"page", 12},
};

// The text stops inside a datum: an error for a file, but the REPL reads
// another line and tries again (driver/repl.cpp).
[[noreturn]] void incomplete_input(SrcLoc loc, const std::string &msg) {
  throw Error(ErrorKind::Syntax, ErrorCause::IncompleteInput, loc, msg);
}

} // namespace

Reader::Reader(uint32_t file) : file_(file), text_(source_text(file)) {}

int Reader::peek() const {
  return pos_ < text_.size() ? static_cast<unsigned char>(text_[pos_]) : EOF;
}

int Reader::get() {
  if (pos_ >= text_.size()) return EOF;
  int c = static_cast<unsigned char>(text_[pos_++]);
  if (c == '\n') {
    ++line_;
    col_ = 1;
  } else {
    ++col_;
  }
  return c;
}

SrcLoc Reader::here() const {
  return SrcLoc{file_, line_, col_};
}

void Reader::skip_block_comment(SrcLoc start) {
  // "#|" has been consumed; block comments nest.
  int nesting = 1;
  while (nesting > 0) {
    int c = get();
    if (c == EOF) incomplete_input(start, "unterminated block comment: this '#|' is never closed");
    if (c == '|' && peek() == '#') {
      get();
      --nesting;
    } else if (c == '#' && peek() == '|') {
      get();
      ++nesting;
    }
  }
}

void Reader::skip_atmosphere() {
  for (;;) {
    int c = peek();
    if (c == EOF) return;
    if (std::isspace(c)) {
      get();
    } else if (c == ';') {
      while (peek() != EOF && peek() != '\n')
        get();
    } else if (c == '#' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '|') {
      SrcLoc start = here();
      get();
      get();
      skip_block_comment(start);
    } else if (c == '#' && pos_ + 1 < text_.size() && text_[pos_ + 1] == ';') {
      // #; comments out the next datum.
      SrcLoc start = here();
      get();
      get();
      skip_atmosphere();
      if (peek() == EOF || peek() == ')')
        syntax_error(start, "'#;' must be followed by a datum to comment out");
      SrcLoc loc;
      read_datum(loc);
    } else {
      return;
    }
  }
}

bool Reader::next(ReadForm &out) {
  skip_atmosphere();
  if (peek() == EOF) return false;
  if (peek() == ')') syntax_error(here(), "unbalanced parentheses: unexpected ')'");
  out.datum = read_datum(out.loc);
  return true;
}

Value Reader::read_datum(SrcLoc &loc) {
  skip_atmosphere();
  loc = here();
  int c = peek();
  switch (c) {
  case EOF: incomplete_input(loc, "unexpected end of input: a datum was expected");
  case '(':
  case '[': {
    get();
    return read_list(c == '(' ? ')' : ']', loc);
  }
  case ')':
  case ']':
    syntax_error(loc,
                 std::string("unbalanced parentheses: unexpected '") + static_cast<char>(c) + "'");
  case '"': return read_string(loc);
  case '#': return read_hash(loc);
  case '\'':
  case '`':
  case ',': {
    get();
    const char *name = c == '\'' ? "quote" : c == '`' ? "quasiquote" : "unquote";
    if (c == ',' && peek() == '@') {
      get();
      name = "unquote-splicing";
    }
    if (++depth_ > kMaxReadDepth) syntax_error(loc, "datum nested too deeply");
    SrcLoc inner;
    Value d = read_datum(inner);
    --depth_;
    return cons(intern(name), cons(d, Value::nil(), inner), loc);
  }
  default: return read_atom(loc);
  }
}

Value Reader::read_list(char close, SrcLoc open) {
  if (++depth_ > kMaxReadDepth) syntax_error(open, "datum nested too deeply");
  gcvec<Value> items;
  gcvec<SrcLoc> locs;
  Value tail = Value::nil();
  for (;;) {
    skip_atmosphere();
    int c = peek();
    if (c == EOF)
      incomplete_input(open, std::string("unbalanced parentheses: this '") +
                                 (close == ')' ? '(' : '[') + "' is never closed");
    if (c == ')' || c == ']') {
      if (c != close)
        syntax_error(here(), std::string("mismatched brackets: expected '") + close + "'");
      get();
      break;
    }
    // A lone "." introduces the tail of a dotted list.
    if (c == '.' && pos_ + 1 <= text_.size() &&
        is_delimiter(pos_ + 1 < text_.size() ? static_cast<unsigned char>(text_[pos_ + 1]) : EOF)) {
      SrcLoc dot = here();
      get();
      if (items.empty()) syntax_error(dot, "ill-formed dotted list: nothing before '.'");
      SrcLoc tl;
      skip_atmosphere();
      if (peek() == ')' || peek() == ']' || peek() == EOF)
        syntax_error(dot, "ill-formed dotted list: nothing after '.'");
      tail = read_datum(tl);
      skip_atmosphere();
      if (peek() != close) {
        if (peek() == EOF)
          incomplete_input(open, "unbalanced parentheses: this '(' is never closed");
        syntax_error(here(), "ill-formed dotted list: more than one datum after '.'");
      }
      get();
      break;
    }
    SrcLoc loc;
    items.push_back(read_datum(loc));
    locs.push_back(loc);
  }
  --depth_;
  Value result = tail;
  for (size_t i = items.size(); i-- > 0;)
    result = cons(items[i], result, locs[i]);
  return result;
}

Value Reader::read_string(SrcLoc start) {
  get(); // opening quote
  std::string s;
  for (;;) {
    int c = get();
    if (c == EOF) incomplete_input(start, "unterminated string: this '\"' is never closed");
    if (c == '"') break;
    if (c != '\\') {
      s += static_cast<char>(c);
      continue;
    }
    SrcLoc esc = here();
    int e = get();
    switch (e) {
    case 'n': s += '\n'; break;
    case 't': s += '\t'; break;
    case 'r': s += '\r'; break;
    case 'a': s += '\a'; break;
    case '0': s += '\0'; break;
    case '\\': s += '\\'; break;
    case '"': s += '"'; break;
    case 'x': {
      // \xHH; (R7RS): hex digits terminated by a semicolon.
      uint32_t cp = 0;
      int digits = 0;
      while (std::isxdigit(peek())) {
        int h = get();
        cp =
            cp * 16 + static_cast<uint32_t>(std::isdigit(h) ? h - '0' : std::tolower(h) - 'a' + 10);
        if (++digits > 6) syntax_error(esc, "bad \\x escape in string");
      }
      if (digits == 0 || get() != ';') syntax_error(esc, "bad \\x escape in string: use \\xHH;");
      if (cp < 0x80) {
        s += static_cast<char>(cp);
      } else if (cp < 0x800) {
        s += static_cast<char>(0xC0 | (cp >> 6));
        s += static_cast<char>(0x80 | (cp & 0x3F));
      } else if (cp < 0x10000) {
        s += static_cast<char>(0xE0 | (cp >> 12));
        s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        s += static_cast<char>(0x80 | (cp & 0x3F));
      } else if (cp < 0x110000) {
        s += static_cast<char>(0xF0 | (cp >> 18));
        s += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
        s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        s += static_cast<char>(0x80 | (cp & 0x3F));
      } else {
        syntax_error(esc, "bad \\x escape in string: not a Unicode code point");
      }
      break;
    }
    case '\n': {
      // A backslash-newline continues the line, skipping leading white space.
      while (peek() == ' ' || peek() == '\t')
        get();
      break;
    }
    case EOF: incomplete_input(start, "unterminated string: this '\"' is never closed");
    default:
      if (e == ' ' || e == '\t') {
        // "\   <newline>  " is also a continuation.
        while (peek() == ' ' || peek() == '\t')
          get();
        if (peek() == '\n') {
          get();
          while (peek() == ' ' || peek() == '\t')
            get();
          break;
        }
      }
      syntax_error(esc, std::string("unknown escape '\\") + static_cast<char>(e) + "' in string");
    }
  }
  return make_string(s);
}

Value Reader::read_hash(SrcLoc start) {
  get(); // '#'
  int c = peek();
  if (c == '(') {
    get();
    Value items = read_list(')', start);
    if (list_length(items) < 0)
      syntax_error(start, "ill-formed vector: '.' is not allowed in #( ... )");
    gcvec<Value> v = list_to_vector(items);
    Value vec = make_vector(v.size(), Value::nil());
    for (size_t i = 0; i < v.size(); ++i)
      vec.vector()->items[i] = v[i];
    return vec;
  }
  if (c == '\\') {
    get();
    if (peek() == EOF) incomplete_input(start, "unexpected end of input after '#\\'");
    // The first character is taken even if it is a delimiter: #\( #\space
    size_t begin = pos_;
    size_t len = 0;
    decode_utf8(text_.substr(pos_), len);
    for (size_t i = 0; i < len; ++i)
      get();
    while (!is_delimiter(peek()))
      get();
    std::string_view name = text_.substr(begin, pos_ - begin);
    size_t first_len = 0;
    uint32_t first = decode_utf8(name, first_len);
    if (first_len == name.size()) return Value::character(first);
    for (const NamedChar &nc : kNamedChars)
      if (name == nc.name) return Value::character(nc.code);
    if ((name[0] == 'x' || name[0] == 'U' || name[0] == 'u') && name.size() > 1) {
      size_t skip = (name[0] != 'x' && name.size() > 2 && name[1] == '+') ? 2 : 1;
      std::string hex(name.substr(skip));
      char *end = nullptr;
      unsigned long cp = std::strtoul(hex.c_str(), &end, 16);
      if (!hex.empty() && *end == '\0' && cp < 0x110000) return Value::character(uint32_t(cp));
    }
    syntax_error(start, "unknown character name '#\\" + std::string(name) + "'");
  }
  if (c == '!') {
    get();
    size_t begin = pos_;
    while (!is_delimiter(peek()))
      get();
    std::string_view name = text_.substr(begin, pos_ - begin);
    if (name == "optional") return intern("#!optional");
    if (name == "rest") return intern("#!rest");
    if (name == "default") return Value::default_object();
    if (name == "eof") return Value::eof();
    if (name == "unspecific") return Value::unspecified();
    if (name == "eval" || name == "fold-case" || name == "no-fold-case") return read_datum(start);
    syntax_error(start, "unknown syntax '#!" + std::string(name) + "'");
  }
  // #t #f #true #false, and numbers with radix/exactness prefixes.
  size_t begin = pos_ - 1;
  while (!is_delimiter(peek()))
    get();
  std::string_view token = text_.substr(begin, pos_ - begin);
  if (token == "#t" || token == "#true") return Value::boolean(true);
  if (token == "#f" || token == "#false") return Value::boolean(false);
  if (token.size() > 1 && std::strchr("xXbBoOdDeEiI", token[1])) {
    if (auto n = parse_number(token)) return *n;
    syntax_error(start, "bad number '" + std::string(token) + "'");
  }
  if (token == "#") syntax_error(start, "bad syntax '#': expected #t, #f, #\\char, #( or #|");
  syntax_error(start, "unknown syntax '" + std::string(token) + "'");
}

Value Reader::read_atom(SrcLoc start) {
  if (peek() == '|') {
    // |symbol with spaces|
    get();
    std::string name;
    for (;;) {
      int c = get();
      if (c == EOF) incomplete_input(start, "unterminated |symbol|");
      if (c == '|') break;
      if (c == '\\') c = get();
      if (c == EOF) incomplete_input(start, "unterminated |symbol|");
      name += static_cast<char>(c);
    }
    return intern(name);
  }
  size_t begin = pos_;
  while (!is_delimiter(peek())) {
    if (peek() == '|' || peek() == '[' || peek() == ']') break;
    get();
  }
  std::string_view token = text_.substr(begin, pos_ - begin);
  if (token.empty()) {
    int c = peek();
    get();
    syntax_error(start, std::string("unexpected character '") + static_cast<char>(c) + "'");
  }
  if (auto n = parse_number(token)) return *n;
  if (token == ".") syntax_error(start, "unexpected '.' outside a list");
  // n/0 is a rational with a zero denominator, not a symbol.
  size_t slash = token.find('/');
  if (slash != std::string_view::npos && slash + 2 == token.size() && token.back() == '0' &&
      parse_number(token.substr(0, slash)))
    syntax_error(start, "bad number '" + std::string(token) + "': division by zero");
  return intern(token);
}

bool symbol_needs_bars(std::string_view name) {
  // read_hash makes these two symbols of #!optional and #!rest.
  if (name == "#!optional" || name == "#!rest") return false;
  if (name.empty() || name == "." || name[0] == '#') return true;
  for (char ch : name) {
    int c = static_cast<unsigned char>(ch);
    if (is_delimiter(c) || c == '|' || c == '[' || c == ']') return true;
  }
  // What read_atom would take for a number (or refuse as n/0).
  if (parse_number(name)) return true;
  size_t slash = name.find('/');
  return slash != std::string_view::npos && slash + 2 == name.size() && name.back() == '0' &&
         parse_number(name.substr(0, slash));
}

gcvec<ReadForm> read_all(uint32_t file) {
  Reader reader(file);
  gcvec<ReadForm> forms;
  ReadForm f;
  while (reader.next(f))
    forms.push_back(f);
  return forms;
}

} // namespace sicm
