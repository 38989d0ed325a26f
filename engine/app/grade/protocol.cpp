// protocol.cpp: reading the grading binary's line protocol (protocol.hpp).
#include "app/grade/protocol.hpp"

#include <cstddef>

namespace clothlab::app::grading {

namespace {

constexpr std::string_view kTag = "@clothlab\t";

}  // namespace

Fields split_event(std::string_view line) {
  Fields fields(1);
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '\t') {
      fields.emplace_back();
    } else if (c == '\\' && i + 1 < line.size()) {
      const char e = line[++i];
      fields.back() += e == 't' ? '\t' : e == 'n' ? '\n' : e == 'r' ? '\r' : e;
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

// The reporter's events, from the pipe only the grading binary writes (see grade_main.cpp).
std::vector<Fields> parse_events(const std::string& text) {
  std::vector<Fields> events;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + begin, end - begin);
    if (line.starts_with(kTag)) events.push_back(split_event(line.substr(kTag.size())));
    begin = end + 1;
  }
  return events;
}

}  // namespace clothlab::app::grading
