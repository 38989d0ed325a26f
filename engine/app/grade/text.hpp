// text.hpp: the grader's text helpers: how it gives up (fail), and text a submission wrote made
// safe for the reports (valid UTF-8) and for a terminal (no control characters).
#pragma once

#include <string>

namespace clothlab::app::grading {

// Says "clothlab grade: MESSAGE" on standard error, then throws CLI::RuntimeError(exit_code),
// which ends the command with that status (exit_codes.hpp).
[[noreturn]] void fail(int exit_code, const std::string& message);

// JSON and XML want valid UTF-8; a crashing case can print anything: every byte that does not
// start a valid sequence becomes "?".
std::string valid_utf8(const std::string& in);

// Text a submission wrote made safe for a terminal: valid UTF-8, with control characters shown in
// caret notation ("^[" for an escape). Newlines and tabs are kept, unless `keep_lines` is false
// (then "^J" and "^I"): for text that one line of a message quotes, a title or a path.
std::string printable(const std::string& text, bool keep_lines = true);

// `text` with `prefix` before each of its lines.
std::string indent(const std::string& text, const std::string& prefix);

// A path inside the project, relative to its root ("tests/grade/01_particles.cpp").
std::string relative_path(const std::string& file);

}  // namespace clothlab::app::grading
