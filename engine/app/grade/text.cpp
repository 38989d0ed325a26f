// text.cpp: the grader's text helpers (text.hpp).
#include "app/grade/text.hpp"

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <cstddef>
#include <iostream>

namespace clothlab::app::grading {

[[noreturn]] void fail(int exit_code, const std::string& message) {
  std::cout << std::flush;
  std::cerr << "clothlab grade: " << message << "\n";
  throw CLI::RuntimeError(exit_code);
}

namespace {

// The length of the well-formed UTF-8 sequence at in[i] (RFC 3629, table 3-7 of the Unicode
// standard), or 0 when none starts there: the bytes a lead byte allows next exclude overlong
// forms (C0, C1, E0 80..9F, F0 80..8F), surrogates (ED A0..BF) and code points past U+10FFFF
// (F4 90..BF, F5..FF).
std::size_t sequence_length(const std::string& in, std::size_t i) {
  const auto b = static_cast<unsigned char>(in[i]);
  if (b < 0x80) return 1;
  std::size_t n = 0;
  unsigned char low = 0x80, high = 0xBF;  // the bounds of the second byte
  if (b >= 0xC2 && b <= 0xDF) {
    n = 2;
  } else if (b >= 0xE0 && b <= 0xEF) {
    n = 3;
    low = b == 0xE0 ? 0xA0 : 0x80;
    high = b == 0xED ? 0x9F : 0xBF;
  } else if (b >= 0xF0 && b <= 0xF4) {
    n = 4;
    low = b == 0xF0 ? 0x90 : 0x80;
    high = b == 0xF4 ? 0x8F : 0xBF;
  } else {
    return 0;
  }
  if (i + n > in.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    const auto c = static_cast<unsigned char>(in[i + k]);
    if (c < (k == 1 ? low : 0x80) || c > (k == 1 ? high : 0xBF)) return 0;
  }
  return n;
}

// The code point of the well-formed sequence of n bytes at s.
char32_t code_point(const char* s, std::size_t n) {
  const auto b = [&](std::size_t k) {
    return static_cast<char32_t>(static_cast<unsigned char>(s[k]));
  };
  if (n == 1) return b(0);
  char32_t cp = b(0) & (0x7F >> n);
  for (std::size_t k = 1; k < n; ++k)
    cp = (cp << 6) | (b(k) & 0x3F);
  return cp;
}

// Text made safe for a terminal; with `lines`, line breaks and tabs are kept, else every
// character that moves to another line or reorders text is written as an escape.
std::string shown(const std::string& text, bool lines) {
  const std::string in = valid_utf8(text);
  std::string out;
  for (std::size_t i = 0; i < in.size();) {
    const std::size_t n = sequence_length(in, i);  // never 0: `in` is valid
    const char32_t cp = code_point(in.data() + i, n);
    if (lines && (cp == U'\n' || cp == U'\t')) {
      out += in[i];
    } else if (cp == U'\n' || cp == U'\t' || cp == U'\r') {
      out += cp == U'\n' ? "\\n" : cp == U'\t' ? "\\t" : "\\r";
    } else if (cp < 0x20 || cp == 0x7F) {
      out += '^';
      out += static_cast<char>(cp == 0x7F ? '?' : cp + 64);
    } else if (cp >= 0x80 && cp <= 0x9F) {
      out += "^?";  // a C1 control (U+0080 to U+009F), which some terminals obey
    } else if (!lines && (cp == 0x2028 || cp == 0x2029 || (cp >= 0x202A && cp <= 0x202E) ||
                          (cp >= 0x2066 && cp <= 0x2069))) {
      out += fmt::format("\\u{:04X}", static_cast<unsigned>(cp));  // a line break or a bidi control
    } else {
      out.append(in, i, n);
    }
    i += n;
  }
  return out;
}

}  // namespace

// JSON and XML want valid UTF-8; a crashing case can print anything.
std::string valid_utf8(const std::string& in) {
  std::string out;
  for (std::size_t i = 0; i < in.size();) {
    const std::size_t n = sequence_length(in, i);
    if (n == 0) {
      out += '?';
      ++i;
    } else {
      out.append(in, i, n);
      i += n;
    }
  }
  return out;
}

// Text a submission wrote (its output, the compiler's quotes of its code) made safe for a
// terminal: valid UTF-8, with control characters shown in caret notation ("^[" for an escape), so
// that it cannot move the cursor or clear the screen. It keeps its line breaks, so a report shows
// it indented or in a section of its own; a name or a message goes through one_line instead.
std::string printable(const std::string& text) {
  return shown(text, true);
}

std::string one_line(const std::string& text) {
  return shown(text, false);
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
