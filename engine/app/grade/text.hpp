// text.hpp: the grader's text helpers: how it gives up (fail), and text a submission wrote made
// safe for the reports (valid UTF-8) and for a terminal (no control characters).
#pragma once

#include <string>

namespace clothlab::app::grading {

// Says "clothlab grade: MESSAGE" on standard error, then throws CLI::RuntimeError(exit_code),
// which ends the command with that status (exit_codes.hpp).
[[noreturn]] void fail(int exit_code, const std::string& message);

// JSON and XML want valid UTF-8; a crashing case can print anything: every byte that does not
// start a well-formed sequence (RFC 3629: no overlong form, no surrogate, nothing past U+10FFFF)
// becomes "?".
std::string valid_utf8(const std::string& in);

// Text a submission wrote made safe for a terminal: valid UTF-8, with control characters shown in
// caret notation ("^[" for an escape), line breaks and tabs kept (for output and quoted code,
// which a report shows indented or in a section of its own).
std::string printable(const std::string& text);

// A piece of data (a name, a message, a file name) shown on one line: valid UTF-8, with a line
// break, tab or carriage return written as \n, \t, \r, other control characters in caret
// notation ("^[") and the characters that reorder or break lines (U+2028, U+202E, ...) as
// \u2028 and the like. Such text then cannot start a line of a report, so it cannot draw a
// fake one ("Total: 130 / 130 points") or move what follows it.
std::string one_line(const std::string& text);

// `text` with `prefix` before each of its lines.
std::string indent(const std::string& text, const std::string& prefix);

// A path inside the project, relative to its root ("tests/grade/01_particles.cpp").
std::string relative_path(const std::string& file);

}  // namespace clothlab::app::grading
