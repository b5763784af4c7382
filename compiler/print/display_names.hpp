// The book's conventions for showing names: Greek letters, dots, subscripts.
//
// A symbol in an expression is shown the way SICM typesets it:
//   theta -> θ, Omega -> Ω          a Greek letter's name is the letter
//   thetadot -> θ̇, xdotdot -> ẍ     each trailing "dot" (up to three) is a time
//                                   derivative, a dot above the letter
//   p_x -> pₓ, v^0 -> v⁰            "_" starts a subscript and "^" a
//                                   superscript; each part is shown by these
//                                   same rules (p_theta -> p_θ), and is kept
//                                   with its "_" or "^" when some character
//                                   of it has no Unicode sub/superscript form
// Names that do not fit the pattern (a leading or doubled "_", a bare "dot")
// are shown as they are.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace sicm {

// The Unicode text for a name (UTF-8).
std::string display_name(std::string_view name);

// The TeX for a name: \theta, \dot{\theta}, p_{x}, v^{0}; other names of more
// than one letter in \mathit{...} so they read as one symbol, not a product.
std::string tex_name(std::string_view name);

// text for TeX math mode, taken literally: TeX's special characters escaped.
std::string tex_escape(std::string_view text);

// text with every character replaced by its Unicode subscript (superscript)
// form, or nullopt when some character has none. Knows digits, + - = ( ),
// the Latin letters Unicode has forms for, and a few Greek ones.
std::optional<std::string> to_subscript(std::string_view text);
std::optional<std::string> to_superscript(std::string_view text);

} // namespace sicm
