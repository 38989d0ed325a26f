// protocol.hpp: the line protocol of a grading binary's "clothlab" reporter, which writes one
// event a line to a pipe of its own (tests/grade/harness/grade_main.cpp describes the events).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace clothlab::app::grading {

// An event's fields: its kind ("case", "start", "fail", ...), then what it says.
using Fields = std::vector<std::string>;

// One event line without its tag: the fields between tabs, with \t, \n, \r and \\ unescaped.
Fields split_event(std::string_view line);

// The reporter's events, from the pipe only the grading binary writes (see grade_main.cpp): the
// lines that start with the tag "@clothlab\t".
std::vector<Fields> parse_events(const std::string& text);

}  // namespace clothlab::app::grading
