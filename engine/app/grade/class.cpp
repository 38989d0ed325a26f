// class.cpp: `clothlab grade --class DIR` (class.hpp): finding the submissions, grading them a
// few at a time with a grader each, and the class's reports.
#include "app/grade/class.hpp"
#include "app/exit_codes.hpp"
#include "app/grade/exercises.hpp"
#include "app/grade/reports.hpp"
#include "app/grade/text.hpp"
#include "app/process.hpp"
#include "app/submission.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

extern char** environ;

namespace clothlab::app::grading {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

std::string dump(const Json& json) {
  return json.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// FNV-1a, 64 bits: a key that tells a changed file from an unchanged one (not a defence against
// someone who crafts a collision: a student gains nothing by one but a grade kept from before).
struct Hash {
  std::uint64_t h = 1469598103934665603ull;
  void add(std::string_view s) {
    for (const char ch : s) {
      h ^= static_cast<unsigned char>(ch);
      h *= 1099511628211ull;
    }
    add_separator();
  }
  void add_separator() {
    h ^= 0xff;
    h *= 1099511628211ull;
  }
  std::string hex() const { return fmt::format("{:016x}", h); }
};

// One submission of the class.
struct Student {
  std::string name;  // as the class names it: data, shown escaped in every report
  fs::path folder;   // absolute
  std::string id;    // its reports' file name: letters, digits, '_' and '-' alone
  std::string key;   // its files and the grading, hashed: unchanged means not graded again
  Json record;       // what its grader found, once graded (or resumed)
  bool resumed = false;
  std::string failure;  // why its grader left no record
};

// A report's file name for `name`: what of it is a letter, a digit, '-' or '_' (at most 40
// characters), then a hash of the whole name, so two names never share a file and no name can
// reach outside REPORT_DIR (no '/', no '.', no control character).
std::string file_id(const std::string& name) {
  std::string safe;
  for (const char ch : name) {
    if (safe.size() >= 40) break;
    const bool plain = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                       (ch >= '0' && ch <= '9') || ch == '-' || ch == '_';
    safe += plain ? ch : '_';
  }
  Hash h;
  h.add(name);
  return (safe.empty() ? std::string("student") : safe) + "-" + h.hex().substr(0, 10);
}

// A YAML scalar as Gradescope writes it: plain, 'single' or "double" quoted.
std::string unquote(std::string s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r'))
    s.pop_back();
  if (s.size() >= 2 && (s.front() == '\'' || s.front() == '"') && s.back() == s.front())
    s = s.substr(1, s.size() - 2);
  return s;
}

// Gradescope's export: submission_metadata.yml names each submission_<id>: folder's submitters
//   submission_123:
//     :submitters:
//     - :name: Jane Doe
//       :sid: '42'
// Returns folder -> "Jane Doe" (a group's names joined by ", "; the sid where there is no name).
std::map<std::string, std::string> gradescope_names(const fs::path& metadata) {
  std::map<std::string, std::string> names;
  std::ifstream in(metadata);
  std::string folder, sid;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != ' ' && line[0] != '-' && line.back() == ':') {
      folder = line.substr(0, line.size() - 1);
      continue;
    }
    if (folder.empty()) continue;
    const auto at = line.find(":name:");
    const auto sid_at = line.find(":sid:");
    if (at != std::string::npos) {
      std::string& n = names[folder];
      n += (n.empty() ? "" : ", ") + unquote(line.substr(line.find_first_not_of(' ', at + 6)));
    } else if (sid_at != std::string::npos && names[folder].empty()) {
      names[folder] = unquote(line.substr(line.find_first_not_of(' ', sid_at + 5)));
    }
  }
  return names;
}

// The submissions under `dir`: Gradescope's export (its submission_metadata.yml in `dir` or in
// the one assignment_*_export/ folder inside it), or a folder per student. Folders only, never
// through a symbolic link, none whose name starts with '.', and never `out`.
std::vector<Student> find_submissions(const fs::path& dir, const fs::path& out, std::string& layout,
                                      std::string& skipped) {
  std::error_code ec;
  fs::path root = dir;
  if (!fs::exists(dir / "submission_metadata.yml", ec)) {
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      if (entry.is_directory(ec) && !entry.is_symlink(ec) &&
          fs::exists(entry.path() / "submission_metadata.yml", ec))
        root = entry.path();
    }
  }
  const bool gradescope = fs::is_regular_file(root / "submission_metadata.yml", ec);
  layout = gradescope ? "Gradescope's export (submission_metadata.yml)" : "a folder per student";
  const std::map<std::string, std::string> names =
      gradescope ? gradescope_names(root / "submission_metadata.yml")
                 : std::map<std::string, std::string>{};
  const fs::path out_canonical = fs::weakly_canonical(out, ec);
  std::vector<Student> students;
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(".")) continue;
    const fs::file_status status = fs::symlink_status(entry.path(), ec);
    if (!fs::is_directory(status)) {
      if (fs::is_symlink(status))
        skipped += "  " + one_line(name) + " (a symbolic link: not followed)\n";
      continue;
    }
    if (fs::weakly_canonical(entry.path(), ec) == out_canonical) continue;
    Student s;
    const auto named = names.find(name);
    s.name = named != names.end() && !named->second.empty() ? named->second : name;
    s.folder = fs::absolute(entry.path());
    students.push_back(std::move(s));
  }
  std::sort(students.begin(), students.end(), [](const Student& a, const Student& b) {
    return a.name != b.name ? a.name < b.name : a.folder < b.folder;
  });
  for (Student& s : students)
    s.id = file_id(s.name + "\n" + s.folder.filename().string());
  return students;
}

// What a grading depends on besides a submission's files: the grading binary, the shipped stubs
// and the options that change a grade.
std::string grading_key(const ClassOptions& o) {
  Hash h;
  h.add("clothlab class 1");
  h.add(fmt::format("{} {} {:g} {}", o.hidden, o.exercise, o.timeout, o.sandbox));
  h.add(read_text(fs::path(build_dir()) / "grade-cases"));
  for (const KitExercise& x : kit_exercise_files()) {
    h.add(x.name);
    h.add(read_text(x.stub));
  }
  return h.hex();
}

// The key of one submission: its files (names, kinds and contents, links never followed) and
// the grading's key.
std::string submission_key(const fs::path& folder, const std::string& grading) {
  std::error_code ec;
  std::vector<std::pair<std::string, fs::path>> entries;
  for (auto it = fs::recursive_directory_iterator(
           folder, fs::directory_options::skip_permission_denied, ec);
       !ec && it != fs::recursive_directory_iterator() && entries.size() < 10000; it.increment(ec))
    entries.emplace_back(fs::relative(it->path(), folder, ec).string(), it->path());
  std::sort(entries.begin(), entries.end());
  Hash h;
  h.add(grading);
  for (const auto& [rel, path] : entries) {
    h.add(rel);
    const fs::file_status status = fs::symlink_status(path, ec);
    h.add(std::to_string(static_cast<int>(status.type())));
    if (fs::is_symlink(status)) h.add(fs::read_symlink(path, ec).string());
    if (!fs::is_regular_file(status)) continue;
    const std::uintmax_t size = fs::file_size(path, ec);
    h.add(size <= (1u << 20) ? read_text(path) : std::to_string(size));
  }
  return h.hex();
}

// Starts `args` with its output in `log`, stdin from /dev/null, and NO_COLOR set; returns its
// process id, or -1. No shell: each argument reaches the program as it is.
pid_t spawn(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> a = args;
  std::vector<char*> argv;
  for (std::string& s : a)
    argv.push_back(s.data());
  argv.push_back(nullptr);
  std::vector<std::string> env{"NO_COLOR=1"};
  for (char** e = environ; *e != nullptr; ++e) {
    if (!std::string_view(*e).starts_with("NO_COLOR=")) env.emplace_back(*e);
  }
  std::vector<char*> envp;
  for (std::string& s : env)
    envp.push_back(s.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

// --- A submission's record and status ----------------------------------------------------------

// A record's cases (none in a record without them).
const Json& cases_of(const Json& record) {
  static const Json none = Json::array();
  const auto it = record.find("cases");
  return it != record.end() && it->is_array() ? *it : none;
}

bool status_is(const Json& c, std::string_view prefix) {
  return c.value("status", "").starts_with(prefix);
}

// "graded", "not compiled" (nothing could be built), or "graded" with what went wrong beside it:
// the files that did not compile, the cases that timed out and that crashed.
std::string status_of(const Json& record) {
  const Json& cases = cases_of(record);
  if (cases.empty()) return "graded";
  int not_compiled = 0, timed_out = 0, crashed = 0;
  for (const Json& c : cases) {
    not_compiled += c.value("not_compiled", false) ? 1 : 0;
    timed_out += status_is(c, "timed out") ? 1 : 0;
    crashed += status_is(c, "crashed") ? 1 : 0;
  }
  if (not_compiled == static_cast<int>(cases.size())) return "not compiled";
  std::string s = "graded";
  auto add = [&](int n, const char* what) {
    if (n > 0) s += fmt::format("; {} {} {}", n, n == 1 ? "case" : "cases", what);
  };
  add(not_compiled, "not compiled");
  add(timed_out, "timed out");
  add(crashed, "crashed");
  return s;
}

int earned_of(const Json& record) {
  int total = 0;
  for (const Json& c : cases_of(record))
    total += c.value("passed", false) ? c.value("points", 0) : 0;
  return total;
}

// --- Grading the class ---------------------------------------------------------------------------

struct Running {
  pid_t pid;
  std::size_t student;
  Clock::time_point start;
};

void read_result(Student& s, const fs::path& record, const fs::path& log, int status,
                 double seconds) {
  std::error_code ec;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::exists(record, ec)) {
    try {
      s.record = Json::parse(read_text(record));
      s.record["wall_seconds"] = std::round(seconds * 10) / 10;
      return;
    } catch (const std::exception&) {
    }
  }
  std::string tail = read_text(log);
  if (tail.size() > 2000) tail = tail.substr(tail.size() - 2000);
  s.failure = WIFSIGNALED(status) ? fmt::format("its grader was killed by signal {}\n{}",
                                                WTERMSIG(status), printable(tail))
                                  : fmt::format("its grader exited with status {}\n{}",
                                                WEXITSTATUS(status), printable(tail));
}

// The final JSON of a submission: who, its key, status, points and the record.
Json final_json(const Student& s, const fs::path& class_dir) {
  Json j;
  j["student"] = valid_utf8(s.name);
  j["folder"] = valid_utf8(fs::relative(s.folder, class_dir).string());
  j["key"] = s.key;
  if (!s.failure.empty()) {
    j["status"] = "grader failed";
    j["failure"] = valid_utf8(s.failure);
    return j;
  }
  j["status"] = status_of(s.record);
  j["total"] = earned_of(s.record);
  for (auto it = s.record.begin(); it != s.record.end(); ++it)
    j[it.key()] = it.value();
  return j;
}

void grade_all(std::vector<Student>& students, const ClassOptions& o, const fs::path& work,
               const fs::path& subs, bool terminal) {
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  const long cores = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
  const int jobs = o.jobs > 0 ? o.jobs : static_cast<int>(cores);
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < students.size(); ++i)
    if (!students[i].resumed) todo.push_back(i);
  const std::size_t resumed = students.size() - todo.size();
  fmt::print(
      "{} submissions: {} to grade, {} graded before with the same files (kept), {} at a "
      "time\n",
      students.size(), todo.size(), resumed, jobs);
  std::fflush(stdout);
  std::vector<Running> running;
  std::vector<bool> slot_used(static_cast<std::size_t>(jobs), false);
  std::map<pid_t, std::size_t> slot_of;
  std::size_t next = 0, done = 0;
  while ((next < todo.size() && !g_interrupted) || !running.empty()) {
    while (next < todo.size() && static_cast<int>(running.size()) < jobs && !g_interrupted) {
      Student& s = students[todo[next]];
      const std::size_t slot = static_cast<std::size_t>(
          std::find(slot_used.begin(), slot_used.end(), false) - slot_used.begin());
      std::vector<std::string> args{self,
                                    "grade",
                                    "--submission",
                                    s.folder.string(),
                                    "--scratch",
                                    fmt::format("{}/grade-scratch-class-{}", build_dir(), slot),
                                    "--record",
                                    (work / (s.id + ".record.json")).string(),
                                    "--kit-ready",
                                    "--timeout",
                                    fmt::format("{:g}", o.timeout),
                                    "--build-timeout",
                                    fmt::format("{:g}", o.build_timeout),
                                    "--sandbox",
                                    o.sandbox};
      if (o.hidden) args.push_back("--hidden");
      if (o.kernels_as_root) args.push_back("--kernels-as-root");
      if (!o.exercise.empty()) {
        args.push_back("--exercise");
        args.push_back(o.exercise);
      }
      std::error_code ec;
      fs::remove(work / (s.id + ".record.json"), ec);
      const pid_t pid = spawn(args, work / (s.id + ".log"));
      if (pid < 0) fail(kExitBadInput, "cannot start " + self);
      slot_used[slot] = true;
      slot_of[pid] = slot;
      running.push_back({pid, todo[next], Clock::now()});
      ++next;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR && g_interrupted) {
        for (const Running& r : running)
          kill(r.pid, SIGTERM);  // each grader writes what it has and stops
      }
      if (errno == ECHILD) break;
      continue;
    }
    const auto it = std::find_if(running.begin(), running.end(),
                                 [&](const Running& r) { return r.pid == pid; });
    if (it == running.end()) continue;
    Student& s = students[it->student];
    const double seconds = std::chrono::duration<double>(Clock::now() - it->start).count();
    slot_used[slot_of[pid]] = false;
    running.erase(it);
    if (g_interrupted) continue;  // graded again next time
    read_result(s, work / (s.id + ".record.json"), work / (s.id + ".log"), status, seconds);
    write_file((subs / (s.id + ".json")).string(), dump(final_json(s, o.dir)));
    ++done;
    int max = 0;
    for (const Json& c : cases_of(s.record))
      max += c.value("points", 0);
    const std::string shown =
        s.failure.empty() ? fmt::format("{} / {} points, {}, {:.0f} s", earned_of(s.record), max,
                                        status_of(s.record), seconds)
                          : "its grader failed (see " + (subs / (s.id + ".json")).string() + ")";
    fmt::print("{}[{}/{}] {}: {}{}", terminal ? "\r\033[K" : "", done + resumed, students.size(),
               one_line(s.name).substr(0, 60), shown, terminal ? "" : "\n");
    std::fflush(stdout);
  }
  if (terminal) fmt::print("\n");
}

// --- Reports -------------------------------------------------------------------------------------

std::string html(const std::string& text) {
  std::string out;
  for (const char ch : valid_utf8(text)) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

// A CSV field: quoted, quotes doubled, and a leading = + - @ made text (a spreadsheet would
// otherwise run it as a formula).
std::string csv(const std::string& text) {
  std::string s = one_line(text);
  if (!s.empty() && (s[0] == '=' || s[0] == '+' || s[0] == '-' || s[0] == '@')) s = "'" + s;
  std::string out = "\"";
  for (const char ch : s)
    out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

// The exercises in the order of their cases, with their points, from the records.
std::vector<std::pair<std::string, int>> exercise_columns(const std::vector<Student>& students) {
  for (const Student& s : students) {
    if (!s.failure.empty() || cases_of(s.record).empty()) continue;
    std::vector<std::pair<std::string, int>> columns;
    for (const Json& c : cases_of(s.record)) {
      const std::string id = c.value("exercise", "");
      if (columns.empty() || columns.back().first != id) columns.emplace_back(id, 0);
      columns.back().second += c.value("points", 0);
    }
    return columns;
  }
  return {};
}

int exercise_points(const Json& record, const std::string& exercise) {
  int points = 0;
  for (const Json& c : cases_of(record)) {
    if (c.value("exercise", "") == exercise && c.value("passed", false))
      points += c.value("points", 0);
  }
  return points;
}

std::string class_csv(const std::vector<Student>& students, const fs::path& class_dir) {
  const auto columns = exercise_columns(students);
  std::string s = "student,folder";
  int max = 0;
  for (const auto& [id, points] : columns) {
    s += fmt::format(",{} ({} points)", id, points);
    max += points;
  }
  s += fmt::format(",total ({} points),seconds,status\n", max);
  for (const Student& st : students) {
    s += csv(st.name) + "," + csv(fs::relative(st.folder, class_dir).string());
    const bool ok = st.failure.empty();
    for (const auto& column : columns)
      s += ok ? fmt::format(",{}", exercise_points(st.record, column.first)) : std::string(",");
    s += ok ? fmt::format(",{},{:.1f},{}\n", earned_of(st.record),
                          st.record.value("wall_seconds", st.record.value("seconds", 0.0)),
                          csv(status_of(st.record)))
            : ",,," + csv("grader failed") + "\n";
  }
  return s;
}

// `text` with the student's name and folder replaced, so an example shows no one.
std::string anonymised(std::string text, const Student& s) {
  // The grading tests' files as the project names them (the scratch build sees them through
  // "../../../tests/...").
  for (auto at = text.find("../tests/"); at != std::string::npos; at = text.find("../tests/")) {
    std::size_t from = at;
    while (from >= 3 && text.compare(from - 3, 3, "../") == 0)
      from -= 3;
    text.erase(from, at + 3 - from);
  }
  for (const std::string& who :
       {s.folder.string(), s.name, s.folder.filename().string(), one_line(s.name)}) {
    if (who.size() < 3) continue;
    for (auto at = text.find(who); at != std::string::npos; at = text.find(who, at + 9))
      text.replace(at, who.size(), "<student>");
  }
  return text;
}

// A failing case of one exercise, over the class.
struct Failing {
  std::string name;
  int failed = 0;
  std::map<std::string, int> hints;  // diagnosis -> how many
  std::string example;               // one failure's message, anonymised
};

struct Wrong {
  std::string exercise;
  int max = 0;
  std::map<int, int> points;  // points -> students
  int not_started = 0, not_compiled = 0, students = 0;
  std::vector<Failing> failing;
};

std::vector<Wrong> what_went_wrong(const std::vector<Student>& students) {
  std::vector<Wrong> all;
  for (const auto& [id, max] : exercise_columns(students)) {
    Wrong w;
    w.exercise = id;
    w.max = max;
    std::map<std::string, Failing> failing;
    std::vector<std::string> order;
    for (const Student& s : students) {
      if (!s.failure.empty()) continue;
      ++w.students;
      ++w.points[exercise_points(s.record, id)];
      bool started = false, compiled = true;
      for (const Json& c : cases_of(s.record)) {
        if (c.value("exercise", "") != id) continue;
        started = started || !c.value("not_started", false);
        compiled = compiled && !c.value("not_compiled", false);
      }
      if (!compiled) {
        ++w.not_compiled;
        continue;
      }
      if (!started) {
        ++w.not_started;
        continue;
      }
      for (const Json& c : cases_of(s.record)) {
        if (c.value("exercise", "") != id || c.value("passed", false) ||
            c.value("not_started", false) || c.value("not_compiled", false))
          continue;
        const std::string name = c.value("name", "");
        if (!failing.count(name)) order.push_back(name);
        Failing& f = failing[name];
        f.name = name;
        ++f.failed;
        const std::string hint = c.value("diagnosis", "");
        if (f.hints[hint]++ == 0 && f.example.empty()) {
          std::string example = c.value("message", "");
          const std::string output = c.value("output", "");
          if (!output.empty()) example += "\noutput:\n" + output.substr(0, 1500);
          f.example = anonymised(example, s);
        }
      }
    }
    for (const std::string& name : order)
      w.failing.push_back(failing[name]);
    std::stable_sort(w.failing.begin(), w.failing.end(),
                     [](const Failing& a, const Failing& b) { return a.failed > b.failed; });
    all.push_back(std::move(w));
  }
  return all;
}

// The hints the students who fail a case got, the most common first, each with how many got it:
// where a case names the slips it knows, each slip is a line of its own.
std::vector<std::pair<int, std::string>> ranked_hints(const Failing& f) {
  std::vector<std::pair<int, std::string>> ranked;
  for (const auto& [hint, n] : f.hints)
    ranked.emplace_back(n, hint);
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  if (ranked.size() > 6) ranked.resize(6);
  return ranked;
}

std::string hints_html(const Failing& f);

std::string wrong_text(const std::vector<Wrong>& wrong) {
  std::string s = "What the class got wrong\n========================\n";
  for (const Wrong& w : wrong) {
    s += fmt::format("\n{} ({} points), {} students", w.exercise, w.max, w.students);
    if (w.not_started > 0) s += fmt::format(", {} not started", w.not_started);
    if (w.not_compiled > 0) s += fmt::format(", {} not compiled", w.not_compiled);
    s += "\n  points:";
    for (const auto& [points, n] : w.points)
      s += fmt::format("  {} pts x {}", points, n);
    s += "\n";
    for (const Failing& f : w.failing) {
      s += fmt::format("  {} failed by {}\n", one_line(f.name), f.failed);
      for (const auto& [n, hint] : ranked_hints(f))
        s += fmt::format("    {} x hint: {}\n", n, one_line(hint));
      s += "    for example:\n" + indent(f.example, "      ") + "\n";
    }
    if (w.failing.empty() && w.not_started + w.not_compiled < w.students)
      s += "  every student who started it passes every case\n";
  }
  return s;
}

// --- Similarity ----------------------------------------------------------------------------------

// The lines of `text`.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// The student's lines with those it shares with the stub (a longest common subsequence of lines,
// spaces aside) blanked: what is left is the student's own code, at its own line numbers.
std::vector<std::string> less_stub(const std::vector<std::string>& mine,
                                   const std::vector<std::string>& stub) {
  const std::size_t n = mine.size(), m = stub.size();
  if (n * m > 4'000'000) return mine;  // a file far larger than an exercise: compared whole
  std::vector<std::vector<std::uint16_t>> lcs(n + 1, std::vector<std::uint16_t>(m + 1, 0));
  for (std::size_t i = n; i-- > 0;) {
    for (std::size_t j = m; j-- > 0;) {
      lcs[i][j] = trimmed(mine[i]) == trimmed(stub[j])
                      ? static_cast<std::uint16_t>(lcs[i + 1][j + 1] + 1)
                      : std::max(lcs[i + 1][j], lcs[i][j + 1]);
    }
  }
  std::vector<std::string> out = mine;
  for (std::size_t i = 0, j = 0; i < n && j < m;) {
    if (trimmed(mine[i]) == trimmed(stub[j])) {
      out[i].clear();
      ++i;
      ++j;
    } else if (lcs[i + 1][j] >= lcs[i][j + 1]) {
      ++i;
    } else {
      ++j;
    }
  }
  return out;
}

// sim_c++ on the PATH, or "".
std::string find_sim() {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::string candidate = dir + "/sim_c++";
    if (!dir.empty() && access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

// One student's code as the comparison sees it: a file of it all, and where each of its lines
// came from.
struct Compared {
  std::size_t student;
  fs::path file;
  std::vector<std::pair<std::string, int>> origin;  // exercise file, line (from 1)
  std::vector<std::string> original;                // the lines as the student wrote them
  std::vector<bool> own;  // whether the line is the student's own: not blank, not the stub's
};

struct Region {
  int a_first, a_last, b_first, b_last, tokens;
};

struct Pair {
  std::size_t a, b;  // into the Compared list
  int a_in_b = 0, b_in_a = 0;
  std::vector<Region> regions;
};

// "s003.cpp: line 4-20   |s007.cpp: line 6-22   [87]" -> the two ranges and the tokens.
bool parse_region(const std::string& line, std::string& a, std::string& b, Region& r) {
  const auto bar = line.find('|');
  const auto open = line.rfind('[');
  if (bar == std::string::npos || open == std::string::npos || open < bar) return false;
  auto side = [](const std::string& s, std::string& file, int& first, int& last) {
    const auto at = s.find(": line ");
    if (at == std::string::npos) return false;
    file = s.substr(0, at);
    return std::sscanf(s.c_str() + at + 7, "%d-%d", &first, &last) == 2;
  };
  return side(line.substr(0, bar), a, r.a_first, r.a_last) &&
         side(line.substr(bar + 1, open - bar - 1), b, r.b_first, r.b_last) &&
         std::sscanf(line.c_str() + open + 1, "%d", &r.tokens) == 1;
}

struct Similarity {
  std::string missing;  // why there is no comparison
  std::vector<Compared> compared;
  std::vector<Pair> pairs;  // ranked, the first 30
  std::size_t pairs_found = 0;
  double seconds = 0;
};

Similarity compare(const std::vector<Student>& students, const fs::path& work) {
  Similarity result;
  const auto start = Clock::now();
  const std::string sim = find_sim();
  if (sim.empty()) {
    result.missing =
        "sim_c++ (Debian's similarity-tester) is not installed, so the submissions were not "
        "compared. Install it (sudo apt-get install similarity-tester) and run the same command "
        "again: the grades are kept, and only the comparison runs.";
    return result;
  }
  const fs::path dir = work / "similarity";
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  const std::vector<KitExercise> exercises = kit_exercise_files();
  for (std::size_t i = 0; i < students.size(); ++i) {
    Compared c;
    c.student = i;
    std::string text;
    for (const KitExercise& x : exercises) {
      std::string why;
      const fs::path found = find_exercise_file(students[i].folder, x.name, why);
      if (found.empty()) continue;
      const std::vector<std::string> mine = lines_of(read_text(found));
      const std::vector<std::string> own = less_stub(mine, lines_of(read_text(x.stub)));
      for (std::size_t k = 0; k < mine.size(); ++k) {
        c.origin.emplace_back(x.name, static_cast<int>(k + 1));
        c.original.push_back(mine[k]);
        c.own.push_back(!trimmed(own[k]).empty());
        text += own[k] + "\n";
      }
    }
    if (trimmed(text).empty() || text.find_first_not_of(" \t\r\n") == std::string::npos) continue;
    c.file = dir / fmt::format("s{:04}.cpp", i);
    std::ofstream(c.file) << text;
    result.compared.push_back(std::move(c));
  }
  if (result.compared.size() < 2) {
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
  }
  auto index_of = [&](const std::string& file) -> std::ptrdiff_t {
    for (std::size_t k = 0; k < result.compared.size(); ++k)
      if (result.compared[k].file.filename() == fs::path(file).filename())
        return static_cast<std::ptrdiff_t>(k);
    return -1;
  };
  std::vector<std::string> args{sim, "-p", "-e", "-a", "-s", "-t", "10"};
  for (const Compared& c : result.compared)
    args.push_back(c.file.filename().string());
  // -p: percentages, "A consists for x % of B material"; -e: each file against each other
  // alone; -a: both ways round; -s: not a file against itself; -t 10: 10 % or more.
  // sim_c++ names the files as given: run in their folder, so the names are ours alone.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  const ProcessResult percentages = run_process(args, 600);
  std::map<std::pair<std::size_t, std::size_t>, Pair> pairs;
  for (const std::string& line : lines_of(percentages.output)) {
    const auto consists = line.find(" consists for ");
    const auto of = line.find(" % of ");
    const auto material = line.rfind(" material");
    if (consists == std::string::npos || of == std::string::npos || material == std::string::npos)
      continue;
    const auto a = index_of(line.substr(0, consists));
    const auto b = index_of(line.substr(of + 6, material - of - 6));
    if (a < 0 || b < 0 || a == b) continue;
    const int percent = std::atoi(line.c_str() + consists + 14);
    const auto lo = static_cast<std::size_t>(std::min(a, b));
    const auto hi = static_cast<std::size_t>(std::max(a, b));
    Pair& p = pairs[{lo, hi}];
    p.a = lo;
    p.b = hi;
    int& share = a < b ? p.a_in_b : p.b_in_a;  // how much of the first file is in the second
    share = std::max(share, percent);
  }
  for (auto& [key, p] : pairs)
    result.pairs.push_back(p);
  std::stable_sort(result.pairs.begin(), result.pairs.end(), [](const Pair& x, const Pair& y) {
    return std::max(x.a_in_b, x.b_in_a) > std::max(y.a_in_b, y.b_in_a);
  });
  result.pairs_found = result.pairs.size();
  if (result.pairs.size() > 30) result.pairs.resize(30);
  // The matching regions of the pairs shown.
  for (Pair& p : result.pairs) {
    const ProcessResult runs =
        run_process({sim, "-e", "-s", "-n", result.compared[p.a].file.filename().string(),
                     result.compared[p.b].file.filename().string()},
                    120);
    for (const std::string& line : lines_of(runs.output)) {
      std::string fa, fb;
      Region r{};
      if (!parse_region(line, fa, fb, r)) continue;
      if (index_of(fa) == static_cast<std::ptrdiff_t>(p.b)) {
        std::swap(r.a_first, r.b_first);
        std::swap(r.a_last, r.b_last);
      }
      p.regions.push_back(r);
    }
  }
  fs::current_path(cwd);
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

// Lines first..last of a compared file, as the student wrote them, each with its file and line.
// A run of two or more lines that are not the student's own (shared with the shipped stub, or
// blank) is folded into one line that counts them: the comparison left them out, and a region
// that spans two exercises would otherwise show the whole file between them.
std::string region_text(const Compared& c, int first, int last) {
  std::string s;
  const int end = std::min(last, static_cast<int>(c.original.size()));
  for (int k = std::max(first, 1); k <= end;) {
    int run = 0;  // the lines from k on that are not the student's own
    while (k + run <= end && !c.own[static_cast<std::size_t>(k + run - 1)])
      ++run;
    if (run >= 2) {
      s += fmt::format("        ... {} lines as in the shipped stub, or blank\n", run);
      k += run;
      continue;
    }
    const auto& [file, line] = c.origin[static_cast<std::size_t>(k - 1)];
    s += fmt::format("{}:{:<4} {}\n", file.substr(0, 2), line,
                     c.original[static_cast<std::size_t>(k - 1)]);
    ++k;
  }
  return s;
}

std::string similarity_text(const Similarity& sim, const std::vector<Student>& students) {
  std::string s = "Similar code (sim_c++, the shipped stubs left out)\n";
  if (!sim.missing.empty()) return s + sim.missing + "\n";
  s += fmt::format("{} submissions compared, {} pairs of 10 % or more (at most 30 shown)\n",
                   sim.compared.size(), sim.pairs_found);
  for (const Pair& p : sim.pairs) {
    s += fmt::format("  {:>3} % of {} is in {}; {:>3} % the other way\n", p.a_in_b,
                     one_line(students[sim.compared[p.a].student].name),
                     one_line(students[sim.compared[p.b].student].name), p.b_in_a);
  }
  return s;
}

std::string hints_html(const Failing& f) {
  std::string h;
  for (const auto& [n, hint] : ranked_hints(f))
    h += fmt::format("{} &times; {}<br>", n, html(one_line(hint)));
  return h;
}

// The start of a report page, with the style the class's pages share.
std::string page_head(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + html(title) +
         "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:110em}"
         "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;"
         "text-align:right;vertical-align:top}td.l,th.l{text-align:left}pre{margin:0;"
         "font-size:85%;white-space:pre-wrap}.bad{color:#a00}.side td{text-align:left}"
         "</style></head><body>\n";
}

// The tokens of a pair's matching regions, summed.
int tokens_of(const Pair& p) {
  int tokens = 0;
  for (const Region& r : p.regions)
    tokens += r.tokens;
  return tokens;
}

// The page of the pair ranked `rank` (from 0) in the similarity report, in REPORT_DIR/pairs/:
// its name is the rank alone, never a student's name.
std::string pair_file(std::size_t rank) {
  return fmt::format("pair-{:02}.html", rank + 1);
}

// A pair's matching regions side by side, each line as the student wrote it. They are a page of
// their own, linked from the class's page: a region can run to a whole file, and thirty of them
// side by side made the class's page megabytes long.
std::string pair_page(const Similarity& sim, const std::vector<Student>& students,
                      std::size_t rank) {
  const Pair& p = sim.pairs[rank];
  const Compared& a = sim.compared[p.a];
  const Compared& b = sim.compared[p.b];
  const std::string name_a = one_line(students[a.student].name);
  const std::string name_b = one_line(students[b.student].name);
  std::string h = page_head("clothlab: similar code, " + name_a + " and " + name_b);
  h += fmt::format(
      "<p><a href=\"../index.html#similar\">&larr; the class</a></p>\n<h1>{} % / {} %: {} and "
      "{}</h1>\n<p>Pair {} of the class's ranking: {} % of the first student's code is found in "
      "the second's, and {} % the other way. sim_c++ matched {} regions ({} tokens), shown as the "
      "two wrote them, each line with its file (the lesson's number) and line. Runs of lines as "
      "in the shipped stub are folded: the comparison left them out.</p>\n<table "
      "class=\"side\"><tr><th class=\"l\">{}</th><th class=\"l\">{}</th></tr>\n",
      p.a_in_b, p.b_in_a, html(name_a), html(name_b), rank + 1, p.a_in_b, p.b_in_a,
      p.regions.size(), tokens_of(p), html(name_a), html(name_b));
  for (const Region& r : p.regions) {
    h += fmt::format("<tr><td><pre>{}</pre></td><td><pre>{}</pre></td></tr>\n",
                     html(region_text(a, r.a_first, r.a_last)),
                     html(region_text(b, r.b_first, r.b_last)));
  }
  return h + "</table>\n</body></html>\n";
}

std::string page(const std::vector<Student>& students, const std::vector<Wrong>& wrong,
                 const Similarity& sim, const std::string& summary) {
  std::string h = page_head("clothlab: the class") + "<h1>The class</h1>\n<pre>" + html(summary) +
                  "</pre>\n<h2>Grades</h2>\n<table><tr><th class=\"l\">student</th>";
  const auto columns = exercise_columns(students);
  int max = 0;
  for (const auto& [id, points] : columns) {
    h += "<th>" + html(id) + "<br>" + std::to_string(points) + "</th>";
    max += points;
  }
  h += fmt::format("<th>total<br>{}</th><th>time [s]</th><th class=\"l\">status</th></tr>\n", max);
  for (const Student& s : students) {
    h += "<tr><td class=\"l\">" + html(one_line(s.name)) + "</td>";
    if (!s.failure.empty()) {
      h += fmt::format("<td colspan=\"{}\" class=\"l bad\"><pre>{}</pre></td></tr>\n",
                       columns.size() + 3, html("grader failed: " + s.failure));
      continue;
    }
    for (const auto& column : columns)
      h += fmt::format("<td>{}</td>", exercise_points(s.record, column.first));
    const std::string status = status_of(s.record);
    h += fmt::format("<td>{}</td><td>{:.1f}</td><td class=\"l{}\">{}</td></tr>\n",
                     earned_of(s.record),
                     s.record.value("wall_seconds", s.record.value("seconds", 0.0)),
                     status == "graded" ? "" : " bad", html(status));
  }
  h += "</table>\n<h2>What the class got wrong</h2>\n";
  for (const Wrong& w : wrong) {
    h +=
        fmt::format("<h3>{} ({} points)</h3>\n<p>{} students", html(w.exercise), w.max, w.students);
    if (w.not_started > 0) h += fmt::format(", {} not started", w.not_started);
    if (w.not_compiled > 0) h += fmt::format(", {} not compiled", w.not_compiled);
    h += ". Points: ";
    for (const auto& [points, n] : w.points)
      h += fmt::format("{} points &times; {}; ", points, n);
    h += "</p>\n";
    if (w.failing.empty()) continue;
    h += "<table><tr><th class=\"l\">case</th><th>students failing</th><th class=\"l\">the "
         "grader's hint</th><th class=\"l\">one failure (anonymised)</th></tr>\n";
    for (const Failing& f : w.failing) {
      h += fmt::format(
          "<tr><td class=\"l\">{}</td><td>{}</td><td class=\"l\">{}<br>{}</td><td "
          "class=\"l\"><pre>{}</pre></td></tr>\n",
          html(one_line(f.name)), f.failed, hints_html(f), html(lesson_hint(w.exercise)),
          html(f.example));
    }
    h += "</table>\n";
  }
  h += "<h2 id=\"similar\">Similar code</h2>\n";
  if (!sim.missing.empty()) {
    h += "<p class=\"bad\">" + html(sim.missing) + "</p>\n";
  } else {
    h += fmt::format(
        "<p>{} submissions compared by sim_c++ (similarity-tester), token by token, on the "
        "students' own lines: the lines each shares with the shipped stub are left out. "
        "&ldquo;A in B&rdquo; is the share of A's code also found in B. Code close to the "
        "reference solution is similar in every student who wrote it: read the regions "
        "before you conclude: each pair's link opens them side by side. {} pairs of 10 % or "
        "more{}.</p>\n",
        sim.compared.size(), sim.pairs_found,
        sim.pairs_found > sim.pairs.size() ? fmt::format(", the first {} shown", sim.pairs.size())
                                           : std::string());
    if (!sim.pairs.empty()) {
      h += "<table><tr><th>pair</th><th>A in B</th><th>B in A</th><th class=\"l\">A</th><th "
           "class=\"l\">B</th><th>regions</th><th>tokens</th><th class=\"l\"></th></tr>\n";
    }
    for (std::size_t k = 0; k < sim.pairs.size(); ++k) {
      const Pair& p = sim.pairs[k];
      h += fmt::format(
          "<tr><td>{}</td><td>{} %</td><td>{} %</td><td class=\"l\">{}</td><td "
          "class=\"l\">{}</td><td>{}</td><td>{}</td><td class=\"l\"><a href=\"pairs/{}\">side by "
          "side</a></td></tr>\n",
          k + 1, p.a_in_b, p.b_in_a, html(one_line(students[sim.compared[p.a].student].name)),
          html(one_line(students[sim.compared[p.b].student].name)), p.regions.size(), tokens_of(p),
          pair_file(k));
    }
    if (!sim.pairs.empty()) h += "</table>\n";
  }
  return h + "</body></html>\n";
}

}  // namespace

std::string submission_record(const std::vector<Case>& cases, const std::string& notes,
                              double build_seconds, double seconds) {
  Json j;
  j["notes"] = valid_utf8(notes);
  j["seconds"] = std::round(seconds * 100) / 100;
  j["build_seconds"] = std::round(build_seconds * 100) / 100;
  j["cases"] = Json::array();
  for (const Case& c : cases) {
    Json k;
    k["exercise"] = valid_utf8(c.exercise);
    k["name"] = one_line(c.name);
    k["points"] = c.points;
    k["passed"] = c.passed;
    k["status"] = valid_utf8(c.status);
    k["not_started"] = c.not_started;
    k["not_compiled"] = c.not_compiled;
    k["diagnosis"] = valid_utf8(c.diagnosis);
    k["message"] = valid_utf8(c.message.substr(0, 4000));
    k["output"] = valid_utf8(c.output.substr(0, 4000));
    k["seconds"] = std::round(c.seconds * 1000) / 1000;
    j["cases"].push_back(std::move(k));
  }
  return dump(j);
}

void grade_class(const ClassOptions& given) {
  ClassOptions o = given;
  std::error_code ec;
  if (!fs::is_directory(o.dir, ec)) fail(kExitBadInput, "--class " + o.dir + ": no such folder");
  o.dir = fs::absolute(o.dir).lexically_normal().string();
  if (o.out.empty())
    o.out = (fs::path(o.dir).parent_path() / (fs::path(o.dir).filename().string() + "-report"))
                .string();
  const fs::path out = fs::absolute(o.out);
  const fs::path subs = out / "submissions", work = out / "work";
  fs::create_directories(subs, ec);
  fs::create_directories(work, ec);
  if (ec || !fs::is_directory(subs) || fs::is_symlink(fs::symlink_status(out)))
    fail(kExitBadInput, "--out " + o.out + ": cannot make the report folder there");
  std::string layout, skipped;
  std::vector<Student> students = find_submissions(o.dir, out, layout, skipped);
  if (students.empty())
    fail(kExitBadInput, "--class " + o.dir +
                            ": no submission folder in it (expected a folder per student, or "
                            "Gradescope's export with its submission_metadata.yml)");
  fmt::print("the class in {}: {}\n", one_line(o.dir), layout);
  if (!skipped.empty()) fmt::print("skipped:\n{}", skipped);

  // The grading binary and the engine, built once for the whole class.
  const auto start = Clock::now();
  const std::string why = update_grade_kit(o.build_timeout);
  if (!why.empty()) fail(kExitBadInput, why);
  const std::string grading = grading_key(o);
  for (Student& s : students) {
    s.key = submission_key(s.folder, grading);
    const fs::path saved = subs / (s.id + ".json");
    if (!fs::exists(saved, ec)) continue;
    try {
      Json j = Json::parse(read_text(saved));
      if (j.value("key", "") != s.key || !j.contains("cases")) continue;
      s.record = j;
      s.resumed = true;
    } catch (const std::exception&) {
    }
  }

  g_interrupted = 0;
  InterruptGuard guard;
  const bool terminal = isatty(STDOUT_FILENO) != 0;
  grade_all(students, o, work, subs, terminal);
  if (g_interrupted)
    fail(kExitInterrupted, "interrupted: the submissions graded so far are kept in " +
                               subs.string() + ", and the same command grades the rest");
  const double grading_seconds = std::chrono::duration<double>(Clock::now() - start).count();

  const Similarity sim = compare(students, work);
  const std::vector<Wrong> wrong = what_went_wrong(students);
  // Where the time went, over the submissions graded in this run.
  double build = 0, cases = 0;
  int graded = 0;
  for (const Student& s : students) {
    if (s.resumed || !s.failure.empty()) continue;
    ++graded;
    build += s.record.value("build_seconds", 0.0);
    for (const Json& c : cases_of(s.record))
      cases += c.value("seconds", 0.0);
  }
  std::string summary = fmt::format(
      "{} submissions ({}), {} graded in this run, {} kept from before\n"
      "grading: {:.0f} s of wall time; the graders spent {:.0f} s building kernels and {:.0f} s "
      "running cases (summed over the submissions, {} at a time)\n"
      "similarity: {:.1f} s\n",
      students.size(), layout, graded, students.size() - static_cast<std::size_t>(graded),
      grading_seconds, build, cases,
      o.jobs > 0 ? o.jobs : static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)), sim.seconds);
  int failed = 0;
  for (const Student& s : students)
    failed += s.failure.empty() ? 0 : 1;
  if (failed > 0)
    summary += fmt::format("{} submissions could not be graded (see the table)\n", failed);

  write_file((out / "class.csv").string(), class_csv(students, o.dir));
  write_file((out / "what-went-wrong.txt").string(), wrong_text(wrong));
  write_file((out / "similarity.txt").string(), similarity_text(sim, students));
  // The pairs' pages of this run alone: those of a run before it would name other pairs.
  const fs::path pairs_dir = out / "pairs";
  fs::remove_all(pairs_dir, ec);
  if (!sim.pairs.empty()) {
    fs::create_directories(pairs_dir, ec);
    for (std::size_t k = 0; k < sim.pairs.size(); ++k)
      write_file((pairs_dir / pair_file(k)).string(), pair_page(sim, students, k));
  }
  write_file((out / "index.html").string(), page(students, wrong, sim, summary));
  fmt::print("\n{}", summary);
  if (!sim.missing.empty()) fmt::print("{}\n", sim.missing);
  fmt::print(
      "wrote {}/: index.html, pairs/*.html, class.csv, what-went-wrong.txt, similarity.txt, "
      "submissions/*.json\n",
      one_line(out.string()));
}

}  // namespace clothlab::app::grading
