#include "io/json.hpp"

namespace clothlab {

std::string script_safe_json(std::string json) {
  // '<', '>' and '&' occur only inside strings (JSON has them nowhere else), where \u003c, \u003e
  // and \u0026 are escapes of the same characters.
  std::string safe;
  safe.reserve(json.size());
  for (const char c : json) {
    if (c == '<') {
      safe += "\\u003c";
    } else if (c == '>') {
      safe += "\\u003e";
    } else if (c == '&') {
      safe += "\\u0026";
    } else {
      safe += c;
    }
  }
  return safe;
}

}  // namespace clothlab
