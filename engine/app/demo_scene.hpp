// demo_scene.hpp: the scene `clothlab` runs when given no command.
// Its text is a lesson's scene file, copied in at build time (see engine/CMakeLists.txt).
#pragma once

#include <string_view>

namespace clothlab::app {
extern const std::string_view kDemoScene;   // the TOML text
extern const char* const kDemoSceneSource;  // the file it came from, for messages
}  // namespace clothlab::app
