// grade_main.cpp: the main of every grading binary, and the reporter the grader reads.
//
// Run by hand, a grading binary behaves like any doctest program (console reporter, filters,
// ctest discovery). `clothlab grade` runs it with --reporters=clothlab instead, which prints one
// event per line, fields separated by tabs:
//
//   @clothlab  case       SUITE  NAME  FILE  LINE  POINTS  VISIBILITY
//                                                              (--list-test-cases; POINTS is
//                                                               empty without POINTS(n), and
//                                                               VISIBILITY without
//                                                               POINTS_VISIBILITY(n, v))
//   @clothlab  start      NAME
//   @clothlab  fail       FILE  LINE  MACRO  EXPRESSION  VALUES  CONTEXT...
//                                                              (FAIL("text"): EXPRESSION empty,
//                                                               the text in VALUES)
//   @clothlab  note       FILE  LINE  TEXT  CONTEXT...        (MESSAGE and WARN: not failures)
//   @clothlab  exception  throw|crash  TEXT  CONTEXT...
//   @clothlab  end        passed|failed  SECONDS
//   @clothlab  suite      SUITE                                 (--list-test-suites)
//
// CONTEXT fields are the INFO/CAPTURE messages in scope, which carry the teaching hints. In
// every field a backslash, tab, newline and carriage return are written as \\ \t \n \r.
// Each line is written at once, so a case that crashes still leaves what it reported.
//
// The grader reads these lines from a pipe of their own: the descriptor named by the
// environment's CLOTHLAB_EVENTS_FD, which no other process gets (the exercise kernels run in a
// process of their own, started without it, see kernel_wire.hpp). What the test prints on its
// standard output and error is only shown, never read for a verdict. Without CLOTHLAB_EVENTS_FD
// (a run by hand) the lines go to the standard output, tagged "@clothlab".
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '\\':
        out += "\\\\";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The value of "key=" in a description ("points=3 visibility=hidden", key "points" -> "3"): the
// letters, digits and underscores after it; empty when the description does not give it.
std::string field_of(const char* description, const std::string& key) {
  const std::string d = description ? description : "";
  const auto at = d.find(key + "=");
  if (at == std::string::npos) return "";
  std::string value;
  for (auto i = at + key.size() + 1;
       i < d.size() && (std::isalnum(static_cast<unsigned char>(d[i])) || d[i] == '_'); ++i)
    value += d[i];
  return value;
}

// What a failed assertion found, in the words of doctest's console reporter.
std::string values_of(const doctest::AssertData& a) {
  using doctest::assertType::is_nothrow;
  using doctest::assertType::is_throws;
  using doctest::assertType::is_throws_as;
  using doctest::assertType::is_throws_with;
  const std::string thrown = a.m_exception.c_str();
  if (a.m_at & is_throws) return "did not throw at all";
  if (a.m_at & (is_throws_as | is_throws_with)) {
    return a.m_threw ? "threw a different exception: " + thrown : "did not throw at all";
  }
  if (a.m_at & is_nothrow) return "threw exception: " + thrown;
  if (a.m_threw) return "threw exception: " + thrown;
  return a.m_decomp.c_str();
}

struct ClothlabReporter : public doctest::IReporter {
  std::ostream& out;
  const doctest::ContextOptions& opt;

  int events_fd = -1;  // the grader's pipe for events, or -1: the standard output

  explicit ClothlabReporter(const doctest::ContextOptions& in) : out(*in.cout), opt(in) {
    if (const char* fd = std::getenv("CLOTHLAB_EVENTS_FD"); fd != nullptr && *fd != '\0') {
      events_fd = std::atoi(fd);
      // Kept from every program this one starts.
      if (events_fd < 3 || fcntl(events_fd, F_SETFD, FD_CLOEXEC) != 0) events_fd = -1;
    }
  }

  void emit(const std::vector<std::string>& fields) {
    std::string line = "@clothlab";
    for (const auto& f : fields)
      line += '\t' + escape(f);
    line += '\n';
    if (events_fd < 0) {
      out << line << std::flush;
      return;
    }
    for (std::size_t done = 0; done < line.size();) {
      const ssize_t n = write(events_fd, line.data() + done, line.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
  }

  // The INFO/CAPTURE messages in scope right now (for a failed assertion).
  static void add_active_contexts(std::vector<std::string>& fields) {
    const int n = get_num_active_contexts();
    const doctest::IContextScope* const* contexts = get_active_contexts();
    for (int i = 0; i < n; ++i) {
      std::ostringstream s;
      contexts[i]->stringify(&s);
      fields.push_back(s.str());
    }
  }

  // After an exception the scopes are gone; doctest kept their text, innermost last.
  static void add_stringified_contexts(std::vector<std::string>& fields) {
    const int n = get_num_stringified_contexts();
    const doctest::String* contexts = get_stringified_contexts();
    for (int i = 0; i < n; ++i)
      fields.push_back(contexts[i].c_str());
  }

  void report_query(const doctest::QueryData& in) override {
    if (opt.list_test_cases || opt.count) {
      for (unsigned i = 0; i < in.num_data; ++i) {
        const doctest::TestCaseData& tc = *in.data[i];
        emit({"case", tc.m_test_suite, tc.m_name, tc.m_file.c_str(), std::to_string(tc.m_line),
              field_of(tc.m_description, "points"), field_of(tc.m_description, "visibility")});
      }
    } else if (opt.list_test_suites) {
      for (unsigned i = 0; i < in.num_data; ++i)
        emit({"suite", in.data[i]->m_test_suite});
    }
  }

  void test_run_start() override {}
  void test_run_end(const doctest::TestRunStats&) override {}

  void test_case_start(const doctest::TestCaseData& in) override { emit({"start", in.m_name}); }
  void test_case_reenter(const doctest::TestCaseData&) override {}

  void test_case_end(const doctest::CurrentTestCaseStats& st) override {
    emit({"end", st.testCaseSuccess ? "passed" : "failed", std::to_string(st.seconds)});
  }

  void test_case_exception(const doctest::TestCaseException& e) override {
    std::vector<std::string> fields = {"exception", e.is_crash ? "crash" : "throw",
                                       e.error_string.c_str()};
    add_stringified_contexts(fields);
    emit(fields);
  }

  void subcase_start(const doctest::SubcaseSignature&) override {}
  void subcase_end() override {}

  void log_assert(const doctest::AssertData& a) override {
    if (!a.m_failed) return;
    std::vector<std::string> fields = {
        "fail",   a.m_file,    std::to_string(a.m_line), doctest::assertString(a.m_at),
        a.m_expr, values_of(a)};
    add_active_contexts(fields);
    emit(fields);
  }

  void log_message(const doctest::MessageData& m) override {
    std::vector<std::string> fields;
    if (m.m_severity & doctest::assertType::is_warn) {
      fields = {"note", m.m_file, std::to_string(m.m_line), m.m_string.c_str()};
    } else {  // FAIL or FAIL_CHECK
      const bool require = m.m_severity & doctest::assertType::is_require;
      fields = {
          "fail", m.m_file,          std::to_string(m.m_line), require ? "FAIL" : "FAIL_CHECK",
          "",     m.m_string.c_str()};
    }
    add_active_contexts(fields);
    emit(fields);
  }

  void test_case_skipped(const doctest::TestCaseData&) override {}
};

}  // namespace

DOCTEST_REGISTER_REPORTER("clothlab", 0, ClothlabReporter);
