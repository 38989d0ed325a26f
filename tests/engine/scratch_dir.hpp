// scratch_dir.hpp: where a test writes its files. Every test process has a folder of its own,
// <temp>/clothlab-tests-<pid>, removed with everything in it when the process ends: two test
// processes at once (ctest -j, or a sanitizer build's tests beside a plain build's) never write
// into one folder, and a run leaves nothing behind in the temporary directory (a test that
// crashes leaves its process's folder, named by its pid).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace test {

// `name` inside this process's folder, which exists; `name` itself does not (anything a test
// left there before is removed), so that a test can check what creates it.
inline std::filesystem::path scratch_path(const std::string& name) {
  namespace fs = std::filesystem;
  static const struct Root {
    fs::path path = fs::temp_directory_path() / ("clothlab-tests-" + std::to_string(::getpid()));
    Root() { fs::create_directories(path); }
    ~Root() {
      std::error_code ignored;  // a destructor at exit has no one to tell
      fs::remove_all(path, ignored);
    }
  } root;
  const fs::path path = root.path / name;
  fs::remove_all(path);
  return path;
}

}  // namespace test
