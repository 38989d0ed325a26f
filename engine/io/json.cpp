#include "io/json.hpp"

namespace clothlab {

std::string script_safe_json(std::string json) {
  // "</" occurs only inside strings (JSON has no other '<'), where "\/" is the escape of '/'.
  for (std::size_t at = json.find("</"); at != std::string::npos; at = json.find("</", at + 3))
    json.insert(at + 1, 1, '\\');
  return json;
}

}  // namespace clothlab
