#include "core/toml_characters.hpp"

#include "core/error.hpp"

namespace sphdisk {

void check_toml_characters(const std::string& text, const std::string& source) {
  enum class In { Code, Comment, Basic, Literal, MultiBasic, MultiLiteral } in = In::Code;
  std::size_t line = 1;
  char prev = '\n';         // the last non-blank character in code on this line ('\n': none yet)
  char token_first = '\n';  // the first character of the bare token (or '"': string) prev ends
  bool blank = false;       // blanks since prev
  const auto starts_token = [](char c) { return c == '\n' || c == '=' || c == '[' || c == ',' || c == '{'; };
  const auto number_like = [](char c) { return (c >= '0' && c <= '9') || c == '+' || c == '-'; };
  auto fail = [&](const std::string& what, const std::string& fix) {
    throw UserError(source + ":" + std::to_string(line) + ": " + what + "; " + fix);
  };
  for (std::size_t k = 0; k < text.size(); ++k) {
    const auto u = static_cast<unsigned char>(text[k]);
    const bool starts3 = k + 2 < text.size() && text[k + 1] == text[k] && text[k + 2] == text[k];
    if (u == '\n') {
      ++line;
      if (in == In::Comment || in == In::Basic || in == In::Literal) in = In::Code;  // single-line forms end
      prev = token_first = '\n';
      blank = false;
      continue;
    }
    if ((u < 0x20 && u != '\t' && u != '\r') || u == 0x7f) fail("control character (code " + std::to_string(u) + ")", "remove it: TOML allows only tab and line breaks");
    switch (in) {
      case In::Code:
        if (u >= 0x80) fail("non-ASCII character outside a string or comment", "keys and bare values must be plain ASCII");
        if (u == ' ' || u == '\t' || u == '\r') {
          blank = true;
          break;
        }
        if (u == '"' || u == '\'') {
          if (!starts_token(prev) && !(prev == '.' && !number_like(token_first)))
            fail(std::string("quote ") + text[k] + " inside a bare value", "quote the whole value or remove the quote");
          in = u == '"' ? (starts3 ? (k += 2, In::MultiBasic) : In::Basic) : (starts3 ? (k += 2, In::MultiLiteral) : In::Literal);
          break;
        }
        if (u == '#') {
          in = In::Comment;
          break;
        }
        if (blank || starts_token(prev)) token_first = text[k];
        prev = text[k];
        blank = false;
        break;
      case In::Basic:
        if (u == '\\') ++k;
        else if (u == '"') in = In::Code, prev = token_first = '"', blank = false;
        break;
      case In::MultiBasic:
        if (u == '\\') ++k;
        else if (u == '"' && starts3) k += 2, in = In::Code, prev = token_first = '"', blank = false;
        break;
      case In::Literal:
        if (u == '\'') in = In::Code, prev = token_first = '"', blank = false;
        break;
      case In::MultiLiteral:
        if (u == '\'' && starts3) k += 2, in = In::Code, prev = token_first = '"', blank = false;
        break;
      case In::Comment:
        break;
    }
  }
}

}  // namespace sphdisk
