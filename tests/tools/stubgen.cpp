// stubgen: turns an exercise (or solution) file back into its shipped stub.
//
//   clothlab-stubgen INPUT OUTPUT
//
// Every region
//     // BEGIN ex01.3: see lessons/01-particles-and-euler/README.md
//     ...whatever the student wrote...
//     // END ex01.3
// becomes
//     // BEGIN ex01.3: see lessons/01-particles-and-euler/README.md
//     CLOTHLAB_TODO("ex01.3", "lessons/01-particles-and-euler/README.md");
//     // END ex01.3
// with the indentation of the BEGIN line; everything outside the regions is copied as is. The
// grader builds the stubs this way to check that every exercise's tests can fail, even after a
// student has filled in exercises/. A marker it cannot pair up is an error (FILE:LINE: message,
// exit status 1) and no output is written.
#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <string_view>

namespace {

struct Error {
  int line;
  std::string message;
};

// A line "<indent>// BEGIN exNN.k: see LESSON" or "<indent>// END exNN.k". (Parsed by hand:
// g++ 12 warns inside <regex> when built with the sanitizers.)
struct Marker {
  bool begin = false;
  std::string indent, id, lesson;
};

bool is_exercise_id(std::string_view id) {
  auto digits = [](std::string_view s) {
    return !s.empty() &&
           std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  const auto dot = id.find('.');
  return id.starts_with("ex") && dot != std::string_view::npos && digits(id.substr(2, dot - 2)) &&
         digits(id.substr(dot + 1));
}

// Returns false for a line that is no marker; throws for one that tries to be and fails.
bool parse_marker(std::string_view line, int number, Marker& m) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) {
    line.remove_suffix(1);
  }
  const auto start = line.find_first_not_of(" \t");
  if (start == std::string_view::npos) return false;
  m.indent = std::string(line.substr(0, start));
  std::string_view text = line.substr(start);
  // "//BEGIN ex", "// END ex" and the like: a marker, even if misspelt.
  std::string_view word = text.starts_with("//") ? text.substr(2) : std::string_view();
  word.remove_prefix(std::min(word.find_first_not_of(" \t"), word.size()));
  const std::size_t keyword = word.starts_with("BEGIN") ? 5 : word.starts_with("END") ? 3 : 0;
  const std::string_view after = word.substr(keyword);
  const auto id = after.find_first_not_of(" \t");
  if (keyword == 0 || id == 0 || id == std::string_view::npos ||
      !after.substr(id).starts_with("ex")) {
    return false;  // prose such as "// END of the file"
  }

  const auto malformed =
      Error{number, "malformed marker: expected '// BEGIN exNN.k: see LESSON' or '// END exNN.k'"};
  m.begin = text.starts_with("// BEGIN ");
  if (m.begin) {
    const std::string_view rest = text.substr(9);
    const auto see = rest.find(": see ");
    if (see == std::string_view::npos) throw malformed;
    m.id = std::string(rest.substr(0, see));
    m.lesson = std::string(rest.substr(see + 6));
    if (m.lesson.empty() || m.lesson.find_first_of(" \t") != std::string::npos) throw malformed;
  } else if (text.starts_with("// END ")) {
    m.id = std::string(text.substr(7));
  } else {
    throw malformed;
  }
  if (!is_exercise_id(m.id)) throw malformed;
  return true;
}

std::string stub_of(const std::string& input) {
  std::istringstream in(input);
  std::string out;
  std::string line;
  int number = 0;
  std::string open_id;  // the region we are in, empty outside regions
  int open_line = 0;
  while (std::getline(in, line)) {
    ++number;
    Marker m;
    if (!parse_marker(line, number, m)) {
      if (open_id.empty()) out += line + "\n";
    } else if (m.begin) {
      if (!open_id.empty()) {
        throw Error{number, "BEGIN " + m.id + " inside region " + open_id + " (opened on line " +
                                std::to_string(open_line) + "): add its END line first"};
      }
      open_id = m.id;
      open_line = number;
      const std::string eol = line.ends_with('\r') ? "\r\n" : "\n";
      out += line + "\n";
      out += m.indent + "CLOTHLAB_TODO(\"" + m.id + "\", \"" + m.lesson + "\");" + eol;
    } else {
      if (open_id.empty()) throw Error{number, "END " + m.id + " without a BEGIN line"};
      if (m.id != open_id) {
        throw Error{number, "END " + m.id + " closes region " + open_id + " (opened on line " +
                                std::to_string(open_line) + ")"};
      }
      open_id.clear();
      out += line + "\n";
    }
  }
  if (!open_id.empty()) throw Error{open_line, "region " + open_id + " has no END line"};
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: clothlab-stubgen INPUT OUTPUT\n";
    return 2;
  }
  const std::string input_path = argv[1];
  std::ifstream in(input_path, std::ios::binary);
  if (!in) {
    std::cerr << input_path << ": cannot read this file\n";
    return 1;
  }
  std::ostringstream text;
  text << in.rdbuf();

  std::string stub;
  try {
    stub = stub_of(text.str());
  } catch (const Error& e) {
    std::cerr << input_path << ":" << e.line << ": " << e.message << "\n";
    return 1;
  }

  // An unchanged stub is left as it is, so that nothing built from it is rebuilt.
  {
    std::ifstream old(argv[2], std::ios::binary);
    std::ostringstream before;
    before << old.rdbuf();
    if (old && before.str() == stub) return 0;
  }
  std::ofstream out(argv[2], std::ios::binary);
  out << stub;
  if (!out.flush()) {
    std::cerr << argv[2] << ": cannot write this file\n";
    return 1;
  }
  return 0;
}
