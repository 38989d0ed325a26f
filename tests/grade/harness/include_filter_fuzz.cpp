// include_filter_fuzz.cpp COMPILER WORK_DIR: the include filter (app/include_filter.hpp) against
// the preprocessor itself.
//
// Many spellings of a directive (a byte-order mark; CR LF, LF or lone CR lines; a splice whose
// backslash is followed by spaces, tabs, form feeds or vertical tabs; form feeds, vertical tabs
// and comments around the '#'; the digraph %:; a comment that spans lines inside the directive;
// lines before it that hold raw strings, digit separators and comments that fool a naive reader)
// are combined with the ways of naming a file (#include, #include_next, #import, a macro, a
// __has_include, _Pragma and #pragma GCC dependency, #line and line markers, import) and with
// targets inside and outside what an exercise may read. Each variant is preprocessed by the
// compiler (COMPILER -E) and checked by the filter:
//  - whenever the compiler read or probed a file outside (its text in the output, the probe's
//    marker, or its date compared), the filter must have refused the variant;
//  - a plain #include or __has_include of an allowed header, however it is spelled, must pass.
// Every variant that breaks either rule is printed; the program exits 1 if there is one. The
// variants are each option alone and a few hundred drawn at random (RANDOM_VARIANTS, 250 unless
// told).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "app/include_filter.hpp"

namespace fs = std::filesystem;

namespace {

struct Target {
  std::string name;  // with its <> or quotes
  bool outside;      // a file an exercise may not read
};

// How the target is named: a few lines with TARGET and DIRECTIVE in them. DIRECTIVE is the
// spelled-out "# include" (or the form's own name after the '#').
struct Form {
  const char* name;
  const char* directive;   // the directive's name, spelled by the variant; "" for none
  const char* lines;       // with DIRECTIVE and TARGET, lines separated by '\n'
  bool quoted_only;        // the target must be a "..." name
  bool allowed_must_pass;  // with an allowed target, the filter must let it through
};

const Form kForms[] = {
    {"include", "include", "DIRECTIVE TARGET", false, true},
    {"include_next", "include_next", "DIRECTIVE TARGET", false, false},
    {"import directive", "import", "DIRECTIVE TARGET", false, false},
    {"macro", "include", "#define H TARGET\nDIRECTIVE H", false, false},
    {"function macro", "include", "#define H(x) x\nDIRECTIVE H(TARGET)", false, false},
    {"__has_include", "if", "DIRECTIVE __has_include(TARGET)\nPROBED\n#endif", false, true},
    {"__has_include by macro", "if",
     "#define Q(x) __has_include(x)\nDIRECTIVE Q(TARGET)\nPROBED\n#endif", false, false},
    {"pasted __has_include", "if",
     "#define P(a, b) a ## b\nDIRECTIVE P(__has_, include)(TARGET)\nPROBED\n#endif", false, false},
    {"pragma dependency", "pragma", "DIRECTIVE GCC dependency TARGET", true, false},
    {"_Pragma by macro", "", "#define DO(x) _Pragma(#x)\nDO(GCC dependency TARGET)", true, false},
    {"_Pragma", "", "_Pragma(\"GCC dependency \\\"INNER\\\"\")", true, false},
    {"#line", "line", "DIRECTIVE 1 TARGET\n#error here", true, false},
    {"line marker", "", "# 1 TARGET\n#error here", true, false},
    {"import", "", "import TARGET;", false, false},
};

// Lines put before the directive: each must leave it a directive (or show that it is not one).
const char* const kBefore[] = {
    "",
    "const char* s = R\"(a\" /* )\";",
    "const char* s = R\"x(\n)\" /* \n)x\";",
    "int q = 1'000; int w = '/*';",
    "int q = 0x1'e+1; char c = '\"';",
    "/* a comment\n   on two lines */",
    "// a comment that goes on \\\n onto the next line",
    "const char* s = \"/* not a comment\";",
    "const char* s = u8R\"--(#define X /*)--\";",
};

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// The text with line ends and other control characters written out (\n, \r, \x0c).
std::string shown(const std::string& text) {
  std::string s;
  for (const char c : text) {
    if (c == '\n') {
      s += "\\n";
    } else if (c == '\r') {
      s += "\\r";
    } else if (c >= 32 && c < 127) {
      s += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(c));
      s += hex;
    }
  }
  return s;
}

// One way to spell the directive's '#', the blanks around it, its name and the file's lines.
struct Spelling {
  std::string bom, before_hash, hash, after_hash, splice, newline;
  std::string describe() const {
    std::string s;
    for (const std::string* part : {&bom, &before_hash, &hash, &after_hash, &splice, &newline})
      s.append("[").append(shown(*part)).append("]");
    return s;
  }
};

const std::vector<std::string> kBoms{"", "\xEF\xBB\xBF"};
const std::vector<std::string> kBeforeHash{"", " ", "\t", "\f", "\v", "/* c */", "/**/ "};
const std::vector<std::string> kHashes{"#", "%:"};
const std::vector<std::string> kAfterHash{"",     " ",      "\t",        "\f",        "\v",
                                          "/**/", "/*\n*/", "  \f\v\t ", "/* \r\n */"};
// Inside the directive's name, after its first two letters: none, or a backslash, blanks, and a
// line's end.
const std::vector<std::string> kSplices{"",         "\\\n",   "\\\r\n", "\\\r",   "\\ \n",
                                        "\\\t\r\n", "\\\f\n", "\\\v\r", "\\ \t\n"};
const std::vector<std::string> kNewlines{"\n", "\r\n", "\r"};

std::string spell(const Form& form, const Target& target, const std::string& before,
                  const Spelling& sp) {
  std::string directive = form.directive;
  if (!directive.empty()) {
    if (directive.size() > 2) directive.insert(2, sp.splice);
    directive = sp.before_hash + sp.hash + sp.after_hash + directive;
  }
  std::string lines = replaced(form.lines, "DIRECTIVE", directive);
  lines = replaced(lines, "INNER", target.name.substr(1, target.name.size() - 2));
  lines = replaced(lines, "TARGET", target.name);
  std::string text = sp.bom + (before.empty() ? "" : before + "\n") + lines + "\n";
  return replaced(text, "\n", sp.newline);
}

std::string run(const std::string& command) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (p == nullptr) return out;
  char buffer[4096];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, p))
    out.append(buffer, n);
  pclose(p);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 && argc != 4) {
    std::cerr << "usage: include-filter-fuzz COMPILER WORK_DIR [RANDOM_VARIANTS]\n";
    return 2;
  }
  const std::size_t random_count = argc == 4 ? std::stoul(argv[3]) : 250;
  const std::string compiler = argv[1];
  const fs::path work = fs::absolute(argv[2]);
  fs::remove_all(work);
  fs::create_directories(work / "sys");
  fs::create_directories(work / "engine" / "clothlab");
  fs::create_directories(work / "exercises");
  std::ofstream(work / "sys" / "okstd.h") << "int allowed_std;\n";
  std::ofstream(work / "engine" / "clothlab" / "ok.hpp") << "int allowed_engine;\n";
  std::ofstream(work / "bait.h") << "int BAIT_READ;\n";
  std::ofstream(work / "exercises" / "near.h") << "int BAIT_READ;\n";
  // Newer than every variant: a #pragma GCC dependency on it says so, which shows it was read.
  for (const fs::path& bait : {work / "bait.h", work / "exercises" / "near.h"})
    fs::last_write_time(bait, fs::file_time_type::clock::now() + std::chrono::hours(1));

  const std::vector<Target> targets{
      {"\"" + (work / "bait.h").string() + "\"", true},
      {"\"../bait.h\"", true},
      {"<../bait.h>", true},
      {"\"near.h\"", true},
      {"<" + (work / "bait.h").string() + ">", true},
      {"<okstd.h>", false},
      {"<clothlab/ok.hpp>", false},
      {"\"clothlab/ok.hpp\"", false},
  };

  // Each option alone (eight spellings an earlier filter let through among them), with a target
  // outside and an allowed one; each line before, and each form with each target, plainly spelled;
  // then `random_count` variants drawn at random from every option of every part.
  struct Variant {
    std::string text, what;
    const Target* target;
    const Form* form;
  };
  std::vector<Variant> variants;
  const auto add = [&](const Form& form, const Target& target, const char* before,
                       const Spelling& sp) {
    if (form.quoted_only && target.name.front() != '"') return;
    variants.push_back({spell(form, target, before, sp),
                        std::string(form.name) + " " + target.name + " " + sp.describe() +
                            " after [" + shown(before) + "]",
                        &target, &form});
  };
  const Spelling plain{"", "", "#", " ", "", "\n"};
  std::vector<Spelling> singles;
  for (const std::string& s : kBoms)
    singles.push_back({s, "", "#", " ", "", "\n"});
  for (const std::string& s : kBeforeHash)
    singles.push_back({"", s, "#", " ", "", "\n"});
  for (const std::string& s : kHashes)
    singles.push_back({"", "", s, " ", "", "\n"});
  for (const std::string& s : kAfterHash)
    singles.push_back({"", "", "#", s, "", "\n"});
  for (const std::string& s : kSplices)
    singles.push_back({"", "", "#", " ", s, "\n"});
  for (const std::string& s : kNewlines)
    singles.push_back({"", "", "#", " ", "", s});
  for (const Spelling& sp : singles) {
    add(kForms[0], targets.front(), "", sp);
    add(kForms[0], targets.back(), "", sp);
  }
  for (const char* before : kBefore) {
    add(kForms[0], targets.front(), before, plain);
    add(kForms[0], targets.back(), before, plain);
  }
  for (const Form& form : kForms) {
    for (const Target& target : targets)
      add(form, target, "", plain);
  }
  const std::size_t fixed_count = variants.size();
  std::mt19937 random(39);
  const auto index = [&](std::size_t size) {
    return std::uniform_int_distribution<std::size_t>(0, size - 1)(random);
  };
  const auto pick = [&](const std::vector<std::string>& from) { return from[index(from.size())]; };
  while (variants.size() < fixed_count + random_count) {
    const Spelling sp{pick(kBoms),      pick(kBeforeHash), pick(kHashes),
                      pick(kAfterHash), pick(kSplices),    pick(kNewlines)};
    add(kForms[index(std::size(kForms))], targets[index(targets.size())],
        kBefore[index(std::size(kBefore))], sp);
  }

  int reached = 0, refused_right = 0, allowed = 0, wrong = 0;
  for (std::size_t k = 0; k < variants.size(); ++k) {
    const Variant& v = variants[k];
    const std::string name = std::to_string(k) + "-variant.cpp";
    std::ofstream(work / "exercises" / name, std::ios::binary) << v.text;
    const std::string out = run(
        "cd '" + (work / "exercises").string() + "' && '" + compiler +
        "' -std=c++20 -E -P -fdiagnostics-color=never -nostdinc -isystem '" +
        (work / "sys").string() + "' -I '" + (work / "engine").string() + "' " + name + " 2>&1");
    const bool read_outside = out.find("BAIT_READ") != std::string::npos ||
                              out.find("older than") != std::string::npos ||
                              (v.target->outside && out.find("PROBED") != std::string::npos);
    const std::string verdict = clothlab::app::include_problem(name, v.text);
    const bool refused = !verdict.empty();
    bool ok = true;
    if (read_outside) {
      ++reached;
      if (refused) ++refused_right;
      ok = refused;
    } else if (!v.target->outside && v.form->allowed_must_pass) {
      ++allowed;
      ok = !refused;
    }
    if (!ok) {
      ++wrong;
      std::cout << (refused ? "refused an allowed header: " : "let through a file outside: ")
                << v.what << "\n  text: " << shown(v.text) << "\n  filter: " << verdict
                << "\n  compiler: " << shown(out.substr(0, 400)) << "\n";
    }
  }
  std::cout << variants.size() << " variants: the compiler read or probed a file outside in "
            << reached << ", the filter refused " << refused_right << " of them; " << allowed
            << " spellings of an allowed header, " << (wrong == 0 ? "all" : "not all")
            << " let through\n";
  if (reached == 0) {
    std::cout << "no variant reached a file outside: the compiler or the setup is not what the "
                 "test expects\n";
    return 1;
  }
  return wrong == 0 ? 0 : 1;
}
