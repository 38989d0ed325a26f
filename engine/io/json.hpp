// json.hpp: JSON text that may sit inside an HTML <script> element (the viewer page's data).
#pragma once

#include <string>

namespace clothlab {

// `json` (JSON text) with every "</" written "<\/", which a JSON parser reads as the same text,
// so that no string in it (a title "</script>", say) can close the <script> element it sits in.
std::string script_safe_json(std::string json);

}  // namespace clothlab
