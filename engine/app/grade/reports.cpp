// reports.cpp: every report of a grading (reports.hpp): the summary table, the points table,
// Gradescope's results.json, JUnit XML, Autolab's line and a GitHub Classroom workflow, and how a
// report file is written.
#include "app/grade/reports.hpp"
#include "app/exit_codes.hpp"
#include "app/grade/exercises.hpp"
#include "app/grade/text.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <fmt/color.h>
#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <utility>

namespace clothlab::app::grading {

namespace fs = std::filesystem;

namespace {

std::string paint(bool colour, fmt::text_style style, const std::string& text) {
  return colour ? fmt::format(style, "{}", text) : text;
}

using Json = nlohmann::ordered_json;  // keeps the keys in the order they are set

// A report's JSON text. Its strings were made valid UTF-8 (valid_utf8) when they were set; the
// error handler replaces anything invalid that is left instead of throwing, all the same.
std::string json_dump(const Json& json, int indent) {
  return json.dump(indent, ' ', false, Json::error_handler_t::replace);
}

// Text made fit for XML 1.0, whose characters are tab, line feed, carriage return, U+0020 to
// U+D7FF, U+E000 to U+FFFD and U+10000 to U+10FFFF: anything else (invalid UTF-8, a surrogate, an
// overlong form, a control character, U+FFFE or U+FFFF) becomes "?", even escaped. In an
// attribute, line breaks and tabs are written as references, which a parser keeps (it turns the
// characters themselves into spaces).
std::string xml_escape(const std::string& text, bool attribute = false) {
  std::string out;
  const std::string in = valid_utf8(text);  // well-formed: no surrogate, nothing past U+10FFFF
  for (std::size_t i = 0; i < in.size(); ++i) {
    const char ch = in[i];
    const auto b = static_cast<unsigned char>(ch);
    if (ch == '&') {
      out += "&amp;";
    } else if (ch == '<') {
      out += "&lt;";
    } else if (ch == '>') {
      out += "&gt;";
    } else if (ch == '"') {
      out += "&quot;";
    } else if (ch == '\r' || (attribute && (ch == '\n' || ch == '\t'))) {
      out += fmt::format("&#{};", static_cast<int>(ch));
    } else if (b < 0x20 && ch != '\n' && ch != '\t') {
      out += '?';
    } else if (b == 0xEF && i + 2 < in.size() && in[i + 1] == '\xBF' &&
               (in[i + 2] == '\xBE' || in[i + 2] == '\xBF')) {
      out += '?';  // U+FFFE or U+FFFF
      i += 2;
    } else {
      out += ch;
    }
  }
  return out;
}

// The cases grouped by exercise, in the order of their first case.
std::vector<Exercise> group(const std::vector<const Case*>& cases) {
  std::vector<Exercise> exercises;
  for (const Case* c : cases) {
    auto it = std::find_if(exercises.begin(), exercises.end(),
                           [&](const Exercise& x) { return x.id == c->exercise; });
    if (it == exercises.end()) it = exercises.insert(exercises.end(), Exercise{c->exercise, {}});
    it->cases.push_back(c);
    it->max += c->points;
    if (c->passed) {
      it->earned += c->points;
      ++it->passed;
    }
  }
  return exercises;
}

// The text a report shows for one case: its status, first failure and own output.
std::string case_report(const Case& c, bool with_output) {
  std::string s = c.status + "\n";
  if (!c.message.empty()) s += c.message + "\n";
  if (!c.passed && !c.not_started && !c.not_compiled) {
    const std::string hint = lesson_hint(c.exercise);
    if (!hint.empty()) s += hint + "\n";
  }
  if (with_output && !c.output.empty()) s += "\noutput:\n" + c.output.substr(0, 8000);
  return s;
}

}  // namespace

std::vector<Exercise> by_exercise(const std::vector<Case>& cases) {
  std::vector<const Case*> all;
  for (const Case& c : cases)
    all.push_back(&c);
  return group(all);
}

void print_points_table(const std::vector<Case>& cases) {
  std::size_t width = 4;
  for (const Case& c : cases)
    width = std::max(width, one_line(c.name).size());
  fmt::print("{:<10} {:<{}} {:>6}  {}\n", "Exercise", "Case", width, "Points", "Visibility");
  int total = 0, hidden = 0;
  for (const Case& c : cases) {
    fmt::print("{:<10} {:<{}} {:>6}  {}\n", c.exercise, one_line(c.name), width, c.points,
               c.visibility);
    total += c.points;
    hidden += c.visibility == "visible" ? 0 : c.points;
  }
  fmt::print("\nTotal: {} points in {} cases\n", total, cases.size());
  if (hidden > 0)
    fmt::print("of which in hidden tests, not shown to students before the due date: {} points\n",
               hidden);
}

std::string summary(const std::vector<Case>& cases, bool colour, Audience audience) {
  std::vector<const Case*> shown;
  for (const Case& c : cases) {
    if (audience == Audience::grader || c.visibility == "visible") shown.push_back(&c);
  }
  const auto red = fmt::fg(fmt::terminal_color::red);
  const auto green = fmt::fg(fmt::terminal_color::green);
  const auto yellow = fmt::fg(fmt::terminal_color::yellow);
  std::string s = fmt::format("{:<10} {:>9} {:>9}   {}\n", "Exercise", "Points", "Cases", "Status");
  int earned = 0, max = 0;
  std::vector<std::string> shown_errors;  // a file's compile error, once for its exercises
  for (const Exercise& x : group(shown)) {
    earned += x.earned;
    max += x.max;
    const Case* first = nullptr;
    bool all_not_started = true, all_run = true, not_compiled = false;
    for (const Case* c : x.cases) {
      if (!c->passed && first == nullptr) first = c;
      all_not_started = all_not_started && c->not_started;
      all_run = all_run && c->done;
      not_compiled = not_compiled || c->not_compiled;
    }
    std::string status;
    if (not_compiled)
      status = paint(colour, red, "not compiled");
    else if (first == nullptr)
      status = paint(colour, green, "done");
    else if (all_not_started)
      status = paint(colour, yellow, "not started: " + lesson_hint(x.id));
    else if (!all_run)
      status = paint(colour, yellow, "not run");
    else
      status = paint(colour, red, "failing");
    s += fmt::format("{:<10} {:>9} {:>9}   {}\n", x.id, fmt::format("{} / {}", x.earned, x.max),
                     fmt::format("{} / {}", x.passed, x.cases.size()), status);
    // A submission that does not build says why once, above the table; an exercise file of the
    // student's own that does not compile says it here, under the first of its exercises.
    if (not_compiled && first != nullptr && first->broken_file) {
      if (std::find(shown_errors.begin(), shown_errors.end(), first->message) ==
          shown_errors.end()) {
        shown_errors.push_back(first->message);
        s += indent(first->message, "    ") + "\n";
      }
    } else if (first != nullptr && !all_not_started && first->done && !not_compiled) {
      // The first failing case in full: what was computed, what was expected, where to read.
      s += fmt::format("    {}: {}\n", paint(colour, fmt::emphasis::bold, one_line(first->name)),
                       paint(colour, red, first->status));
      if (!first->message.empty()) s += indent(first->message, "      ") + "\n";
      const std::string hint = lesson_hint(x.id);
      if (!hint.empty()) s += "      " + hint + "\n";
      // Every other one in a line: its name and what went wrong.
      for (const Case* c : x.cases) {
        if (c == first || c->passed || !c->done || c->not_compiled) continue;
        s += fmt::format("    {}: {}{}\n", paint(colour, fmt::emphasis::bold, one_line(c->name)),
                         paint(colour, red, c->status),
                         c->diagnosis.empty() ? "" : ": " + c->diagnosis);
      }
    }
  }
  // Appended piece by piece: GCC 12 warns (-Wrestrict, wrongly) on "\n" + std::string here.
  s += '\n';
  s += paint(colour, fmt::emphasis::bold, fmt::format("Total: {} / {} points", earned, max));
  s += '\n';
  // Of the cases not shown, their number alone: not which, nor their points.
  const std::size_t not_shown = cases.size() - shown.size();
  if (not_shown > 0) {
    s += fmt::format(
        "{} more case{} graded, not shown here: {} results are shown after the due date, or "
        "not at all\n",
        not_shown, not_shown == 1 ? " is" : "s are", not_shown == 1 ? "its" : "their");
  }
  return s;
}

// A report goes only to a new file or over a regular one: never through a symbolic link, and
// never onto a device (as root, `--results /dev/null` would otherwise replace /dev/null).
void check_report_path(const std::string& option, const std::string& path) {
  if (path.empty()) return;
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (ec || !fs::exists(status)) return;
  if (fs::is_symlink(status))
    fail(kExitBadInput,
         fmt::format("{} {}: is a symbolic link; give the path of a new or a regular file", option,
                     path));
  if (!fs::is_regular_file(status))
    fail(kExitBadInput,
         fmt::format("{} {}: is not a regular file (a device or a folder?); give the path of a "
                     "new or a regular file",
                     option, path));
}

// Written to a new file beside `path` (created here, so no one else's file or link is
// written through), then renamed over it: a reader never sees half a file.
void write_file(const std::string& path, const std::string& text) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (!ec && fs::exists(status) && !fs::is_regular_file(status))
    fail(kExitBadInput, "not writing " + path + ": it is no longer a regular file");
  const std::string tmp = fmt::format("{}.{}.tmp", path, getpid());
  const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) fail(kExitBadInput, "cannot write " + tmp + ": " + std::strerror(errno));
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      close(fd);
      fs::remove(tmp, ec);
      fail(kExitBadInput, "cannot write " + tmp + ": " + std::strerror(errno));
    }
    written += static_cast<std::size_t>(n);
  }
  close(fd);
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    fail(kExitBadInput, "cannot write " + path + ": " + ec.message());
  }
}

std::string gradescope_json(const std::vector<Case>& cases, double seconds,
                            const std::string& notes) {
  Json json;
  json["score"] = 0;  // set below, and first in the file
  json["execution_time"] = std::round(seconds * 1000) / 1000;
  // Shown to every student at once: only the cases visible now. (Gradescope itself hides the
  // total score from a student while a test is hidden.)
  json["output"] = valid_utf8(notes + summary(cases, false, Audience::student));
  // What the grader prints (the whole summary) is the instructor's.
  json["stdout_visibility"] = "hidden";
  json["tests"] = Json::array();
  int score = 0;
  for (const Case& c : cases) {
    score += c.passed ? c.points : 0;
    Json test;
    test["name"] = one_line(c.name);
    test["number"] = valid_utf8(number_of(c.exercise));
    test["score"] = c.passed ? c.points : 0;
    test["max_score"] = c.points;
    test["status"] = c.passed ? "passed" : "failed";
    test["output"] = valid_utf8(case_report(c, true));
    test["visibility"] = c.visibility;
    json["tests"].push_back(std::move(test));
  }
  json["score"] = score;
  return json_dump(json, 2) + "\n";
}

std::string junit_xml(const std::vector<Case>& cases, double seconds) {
  std::string suites;
  int failures = 0;
  for (const Exercise& x : by_exercise(cases)) {
    std::string body;
    double time = 0;
    for (const Case* c : x.cases) {
      time += c->seconds;
      body += fmt::format(
          "    <testcase classname=\"{}\" name=\"{}\" file=\"{}\" line=\"{}\" time=\"{:.3f}\">\n",
          xml_escape(x.id, true), xml_escape(one_line(c->name), true), xml_escape(c->file, true),
          c->line, c->seconds);
      if (!c->passed) {
        const std::string first_line =
            c->status +
            (c->message.empty() ? "" : ": " + c->message.substr(0, c->message.find('\n')));
        body += fmt::format("      <failure message=\"{}\" type=\"{}\">{}</failure>\n",
                            xml_escape(first_line, true),
                            xml_escape(c->status.substr(0, c->status.find(':')), true),
                            xml_escape(case_report(*c, false)));
      }
      if (!c->output.empty())
        body += fmt::format("      <system-out>{}</system-out>\n", xml_escape(c->output));
      body += "    </testcase>\n";
    }
    const int failed = static_cast<int>(x.cases.size()) - x.passed;
    failures += failed;
    suites += fmt::format(
        "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" time=\"{:.3f}\">\n{}  "
        "</testsuite>\n",
        xml_escape(x.id, true), x.cases.size(), failed, time, body);
  }
  return fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<testsuites name=\"clothlab grade\" tests=\"{}\" failures=\"{}\" errors=\"0\" "
      "time=\"{:.3f}\">\n{}</testsuites>\n",
      cases.size(), failures, seconds, suites);
}

// Autolab reads the last line of the grader's output: {"scores": {...}, "scoreboard": [...]},
// one score per exercise (the problem names an Autolab course defines), the total on the
// scoreboard.
std::string autolab_line(const std::vector<Case>& cases) {
  Json json;
  json["scores"] = Json::object();
  int total = 0;
  for (const Exercise& x : by_exercise(cases)) {
    json["scores"][valid_utf8(x.id)] = x.earned;
    total += x.earned;
  }
  json["scoreboard"] = Json::array({total});
  return json_dump(json, -1);  // one line
}

// A GitHub Classroom autograding workflow with one step per exercise, worth that exercise's
// points (of the visible cases: the hidden ones are not in a student's repository). Each step
// passes only when every case of its exercise passes.
std::string classroom_workflow(const std::vector<Case>& cases) {
  std::string steps, env, runners;
  for (const Exercise& x : by_exercise(cases)) {
    int points = 0;
    for (const Case* c : x.cases)
      points += c->visibility == "visible" ? c->points : 0;
    if (points == 0) continue;
    std::string id = x.id;
    std::replace(id.begin(), id.end(), '.', '-');
    steps += fmt::format(
        "    - name: {0}\n"
        "      id: {1}\n"
        "      uses: classroom-resources/autograding-command-grader@v1\n"
        "      with:\n"
        "        test-name: {0}\n"
        "        setup-command: ''\n"
        "        command: ./build/clothlab grade --exercise {0} --require-full\n"
        "        timeout: 10\n"
        "        max-score: {2}\n",
        x.id, id, points);
    std::string upper = id;
    std::transform(upper.begin(), upper.end(), upper.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::toupper(ch)); });
    env += fmt::format("        {}_RESULTS: \"${{{{steps.{}.outputs.result}}}}\"\n", upper, id);
    runners += (runners.empty() ? "" : ",") + id;
  }
  return fmt::format(
      "# GitHub Classroom autograding for clothlab, written by `clothlab grade --classroom PATH`\n"
      "# from the grading tests' points: one step per exercise, worth its points when every case\n"
      "# of the exercise passes. `./build/clothlab grade` shows a student the same cases.\n"
      "name: Autograding Tests\n"
      "'on':\n"
      "  - push\n"
      "  - workflow_dispatch\n"
      "  - repository_dispatch\n"
      "permissions:\n"
      "  checks: write\n"
      "  actions: read\n"
      "  contents: read\n"
      "jobs:\n"
      "  run-autograding-tests:\n"
      "    runs-on: ubuntu-latest\n"
      "    if: github.actor != 'github-classroom[bot]'\n"
      "    steps:\n"
      "    - name: Checkout code\n"
      "      uses: actions/checkout@v4\n"
      "    - name: Install the packages\n"
      "      run: sudo apt-get update && sudo apt-get install -y --no-install-recommends g++ "
      "cmake\n"
      "        make libeigen3-dev doctest-dev libfmt-dev libtomlplusplus-dev libcli11-dev\n"
      "        nlohmann-json3-dev\n"
      "    - name: Build the grader\n"
      "      run: cmake -S . -B build && cmake --build build --parallel 4 --target clothlab\n"
      "        grade-kit\n"
      "{}"
      "    - name: Autograding Reporter\n"
      "      uses: classroom-resources/autograding-grader-reporter@v1\n"
      "      env:\n"
      "{}"
      "      with:\n"
      "        runners: {}\n",
      steps, env, runners);
}

}  // namespace clothlab::app::grading
