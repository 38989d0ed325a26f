// json.hpp: the one JSON helper the engine's writers share (viewer page, grader results).
#pragma once

#include <string>
#include <string_view>

namespace clothlab {

// `text` as a JSON string literal, quotes included. Control characters are escaped, and "</" is
// written "<\/" so that the text can sit inside an HTML <script> element without closing it.
std::string json_string(std::string_view text);

}  // namespace clothlab
