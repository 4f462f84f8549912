#pragma once
// Control characters are not allowed in TOML (besides tab and line breaks), and non-ASCII text
// belongs in strings and comments. Refusing the rest here keeps it away from toml++ 3.3 parser
// paths that are undefined behaviour on such input (found by fuzzing: fuzz/, and the regression
// inputs in tests/fuzz_regressions/). A quote opens a string only where TOML lets one begin: at the
// start of a line, after '=', '[', ',' or '{', or after the '.' of a dotted key; a quote right after a
// number or other bare value (0.03e'...) is refused, since toml++ then reads the string's text
// (non-ASCII included) as part of the bad value.
// Throws a UserError naming source, the line and the fix for the first character refused.
#include <string>

namespace sphdisk {

void check_toml_characters(const std::string& text, const std::string& source);

}  // namespace sphdisk
