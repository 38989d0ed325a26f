// json.hpp: JSON text that may sit inside an HTML <script> element (the viewer page's data).
#pragma once

#include <string>

namespace clothlab {

// `json` (JSON text) with every '<', '>' and '&' written as its \u escape, which a JSON parser
// reads as the same text: no string in it (a title "</script>" or "<!--<script>", say) can close
// the <script> element it sits in, or put the page's parser into another state.
std::string script_safe_json(std::string json);

}  // namespace clothlab
