// A bound on how deeply a TOML text nests, checked before the text reaches toml++: toml++ parses
// and destroys nested tables and arrays recursively, so a key dotted 100,000 levels deep
// overflows the stack instead of being an error.
#pragma once
#include <string_view>

namespace tpsim {

/// The deepest nesting tpsim's TOML files may use: table headers, dotted keys, arrays and inline
/// tables all count one level per step ([a.b] x.y = [[1]] is 6 deep). Scenes and chip configs
/// need 4 at most.
inline constexpr int kMaxTomlNesting = 64;

/// Throws tpsim::Error "SOURCE:LINE: ..." at the first point where `text` nests deeper than
/// kMaxTomlNesting. A cheap lexical scan that skips strings and comments; it accepts every valid
/// TOML text within the limit and leaves syntax errors for toml++ to report.
void check_toml_nesting(std::string_view text, std::string_view source);

}  // namespace tpsim
