// text.cpp: the grader's text helpers (text.hpp).
#include "app/grade/text.hpp"

#include <CLI/CLI.hpp>

#include <cstddef>
#include <iostream>

namespace clothlab::app::grading {

[[noreturn]] void fail(int exit_code, const std::string& message) {
  std::cout << std::flush;
  std::cerr << "clothlab grade: " << message << "\n";
  throw CLI::RuntimeError(exit_code);
}

// JSON and XML want valid UTF-8; a crashing case can print anything.
std::string valid_utf8(const std::string& in) {
  std::string out;
  for (std::size_t i = 0; i < in.size();) {
    const auto b = static_cast<unsigned char>(in[i]);
    const std::size_t n = b < 0x80           ? 1
                          : (b >> 5) == 0x6  ? 2
                          : (b >> 4) == 0xE  ? 3
                          : (b >> 3) == 0x1E ? 4
                                             : 0;
    bool ok = n > 0 && i + n <= in.size();
    for (std::size_t k = 1; ok && k < n; ++k)
      ok = (static_cast<unsigned char>(in[i + k]) >> 6) == 0x2;
    out += ok ? in.substr(i, n) : "?";
    i += ok ? n : 1;
  }
  return out;
}

// Text a submission wrote (its messages, its output, the compiler's quotes of its code) made
// safe for a terminal: valid UTF-8, with control characters shown in caret notation ("^[" for
// an escape), so that it cannot move the cursor, clear the screen or draw a fake result.
std::string printable(const std::string& text, bool keep_lines) {
  const std::string in = valid_utf8(text);
  std::string out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto b = static_cast<unsigned char>(in[i]);
    if (keep_lines && (b == '\n' || b == '\t')) {
      out += in[i];
    } else if (b < 0x20 || b == 0x7f) {
      out += '^';
      out += static_cast<char>(b == 0x7f ? '?' : b + 64);
    } else if (b == 0xc2 && i + 1 < in.size() && static_cast<unsigned char>(in[i + 1]) >= 0x80 &&
               static_cast<unsigned char>(in[i + 1]) <= 0x9f) {
      out += "^?";  // a C1 control (U+0080 to U+009F), which some terminals obey
      ++i;
    } else {
      out += in[i];
    }
  }
  return out;
}

std::string indent(const std::string& text, const std::string& prefix) {
  std::string out = prefix;
  for (char ch : text)
    out += ch == '\n' ? "\n" + prefix : std::string(1, ch);
  return out;
}

std::string relative_path(const std::string& file) {
  const std::string root = std::string(CLOTHLAB_SOURCE_DIR) + "/";
  return file.starts_with(root) ? file.substr(root.size()) : file;
}

}  // namespace clothlab::app::grading
