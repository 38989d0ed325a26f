#include "io/json.hpp"

#include <fmt/format.h>

namespace clothlab {

std::string json_string(std::string_view text) {
  std::string out = "\"";
  for (size_t k = 0; k < text.size(); ++k) {
    const char ch = text[k];
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (ch == '\n') {
      out += "\\n";
    } else if (ch == '/' && k > 0 && text[k - 1] == '<') {
      out += "\\/";
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      out += fmt::format("\\u{:04x}", static_cast<int>(ch));
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

}  // namespace clothlab
