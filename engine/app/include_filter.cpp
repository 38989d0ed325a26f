// include_filter.cpp: see include_filter.hpp.
#include "app/include_filter.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cstddef>
#include <string_view>
#include <vector>

namespace clothlab::app {
namespace {

// --- Translation phases 1 and 2: lines and splices -------------------------------------------

// The file's characters after phases 1 and 2, each with where it was in the file.
struct Spliced {
  std::string text;             // every line ending a '\n'; splices removed
  std::vector<std::size_t> at;  // at[i]: the offset in the file of text[i]
};

// GCC's horizontal whitespace: what may stand between a backslash and the line's end of a
// splice, and between the tokens of a directive.
bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\f' || c == '\v' || c == '\0';
}

// The length of the line ending at `i` of `file` (CR LF, LF, or a lone CR), 0 if there is none.
std::size_t newline_at(std::string_view file, std::size_t i) {
  if (i >= file.size()) return 0;
  if (file[i] == '\n') return 1;
  if (file[i] == '\r') return i + 1 < file.size() && file[i + 1] == '\n' ? 2 : 1;
  return 0;
}

// The offset where the file's text starts: after a UTF-8 byte-order mark, which GCC skips.
std::size_t text_start(std::string_view file) {
  return file.starts_with("\xEF\xBB\xBF") ? 3 : 0;
}

Spliced splice(std::string_view file) {
  Spliced s;
  for (std::size_t i = text_start(file); i < file.size();) {
    if (const std::size_t n = newline_at(file, i)) {
      s.text += '\n';
      s.at.push_back(i);
      i += n;
      continue;
    }
    if (file[i] == '\\') {
      std::size_t j = i + 1;
      while (j < file.size() && is_blank(file[j]))
        ++j;
      if (const std::size_t n = newline_at(file, j)) {
        i = j + n;  // a splice: the backslash, the blanks and the line's end go
        continue;
      }
    }
    s.text += file[i];
    s.at.push_back(i);
    ++i;
  }
  return s;
}

// --- Translation phase 3: preprocessing tokens ------------------------------------------------

enum class Tok { Identifier, Number, String, Char, HeaderName, Punct, Other };

struct Token {
  Tok kind;
  std::string text;
  std::size_t at;  // offset in the file
  bool first;      // the first token of its line
};

bool is_ident_start(char c) {
  const auto u = static_cast<unsigned char>(c);
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '$' || u >= 0x80;
}
bool is_ident(char c) {
  return is_ident_start(c) || (c >= '0' && c <= '9');
}
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

class Lexer {
 public:
  Lexer(std::string_view file, const Spliced& s) : file_(file), s_(s) {}

  // The tokens of the file, in order.
  std::vector<Token> tokens() {
    std::vector<Token> out;
    bool first = true;
    int directive_tokens = -1;  // tokens read of the directive this line is, -1 in none
    while (i_ < s_.text.size()) {
      const char c = s_.text[i_];
      if (c == '\n') {
        first = true;
        directive_tokens = -1;
        ++i_;
        continue;
      }
      if (is_blank(c)) {
        ++i_;
        continue;
      }
      if (c == '/' && next(1) == '/') {
        while (i_ < s_.text.size() && s_.text[i_] != '\n')
          ++i_;
        continue;
      }
      if (c == '/' && next(1) == '*') {
        // One space, however many lines it spans: a directive goes on after it.
        const std::size_t end = s_.text.find("*/", i_ + 2);
        i_ = end == std::string::npos ? s_.text.size() : end + 2;
        continue;
      }
      // After "# include" (and its kin), and in "__has_include (", comes a header name, read as
      // one token.
      const bool header_next =
          (c == '<' || c == '"') &&
          ((directive_tokens == 2 && is_file_directive(out.back().text)) ||
           (out.size() >= 2 && out.back().text == "(" && is_file_query(out[out.size() - 2].text)));
      Token t = header_next ? header_name() : next_token();
      t.first = first;
      first = false;
      if (t.first && (t.text == "#" || t.text == "%:")) directive_tokens = 0;
      if (directive_tokens >= 0) ++directive_tokens;
      out.push_back(std::move(t));
    }
    return out;
  }

  static bool is_file_directive(const std::string& name) {
    return name == "include" || name == "include_next" || name == "import" || name == "embed";
  }
  static bool is_file_query(const std::string& name) {
    return name == "__has_include" || name == "__has_include_next" || name == "__has_embed";
  }

 private:
  char next(std::size_t k) const { return i_ + k < s_.text.size() ? s_.text[i_ + k] : '\0'; }

  Token make(Tok kind, std::size_t begin) const {
    return {kind, s_.text.substr(begin, i_ - begin), s_.at[begin], false};
  }

  // <...> or "..." on one line, no escapes.
  Token header_name() {
    const std::size_t begin = i_;
    const char closer = s_.text[i_] == '<' ? '>' : '"';
    std::size_t j = i_ + 1;
    while (j < s_.text.size() && s_.text[j] != closer && s_.text[j] != '\n')
      ++j;
    if (j >= s_.text.size() || s_.text[j] != closer) return next_token();  // not a header name
    i_ = j + 1;
    return make(Tok::HeaderName, begin);
  }

  // A quoted literal from i_ (at its opening quote) to its closing one, or to the line's end
  // when it has none (GCC then takes the rest of the line as one token).
  void quoted(char quote) {
    ++i_;
    while (i_ < s_.text.size() && s_.text[i_] != '\n') {
      const char c = s_.text[i_++];
      if (c == '\\' && i_ < s_.text.size() && s_.text[i_] != '\n') {
        ++i_;
      } else if (c == quote) {
        return;
      }
    }
  }

  // A raw string literal from i_ (at its opening quote): between the quotes the splices of
  // phase 2 are undone, so it is read in the file's own text, up to )delimiter".
  void raw_string() {
    const std::size_t open = s_.at[i_];
    std::size_t j = open + 1;
    while (j < file_.size() && file_[j] != '(' && j - open <= 17)
      ++j;
    std::size_t end = file_.size();
    if (j < file_.size() && file_[j] == '(') {
      std::string closer = ")";
      closer.append(file_.substr(open + 1, j - open - 1));
      closer += '"';
      const std::size_t found = file_.find(closer, j + 1);
      if (found != std::string_view::npos) end = found + closer.size();
    } else {
      // Not a raw string after all (no '(' within 16 characters): GCC reads it as a string.
      quoted('"');
      return;
    }
    // Back in the spliced text: the first character that comes from past the literal.
    i_ =
        static_cast<std::size_t>(std::lower_bound(s_.at.begin(), s_.at.end(), end) - s_.at.begin());
  }

  Token next_token() {
    const std::size_t begin = i_;
    const char c = s_.text[i_];
    if (is_ident_start(c)) {
      while (i_ < s_.text.size() && is_ident(s_.text[i_]))
        ++i_;
      const std::string_view word(s_.text.data() + begin, i_ - begin);
      const char q = i_ < s_.text.size() ? s_.text[i_] : '\0';
      const bool raw = word == "R" || word == "u8R" || word == "uR" || word == "UR" || word == "LR";
      const bool encoding = word == "u8" || word == "u" || word == "U" || word == "L";
      if (raw && q == '"') {
        raw_string();
        return make(Tok::String, begin);
      }
      if (encoding && (q == '"' || q == '\'')) {
        quoted(q);
        return make(q == '"' ? Tok::String : Tok::Char, begin);
      }
      return make(Tok::Identifier, begin);
    }
    if (is_digit(c) || (c == '.' && is_digit(next(1)))) {
      // pp-number: digits, letters, '.', digit separators and signed exponents.
      ++i_;
      while (i_ < s_.text.size()) {
        const char d = s_.text[i_];
        const char e = next(1);
        if ((d == 'e' || d == 'E' || d == 'p' || d == 'P') && (e == '+' || e == '-')) {
          i_ += 2;
        } else if (d == '\'' && is_ident(e)) {
          i_ += 2;
        } else if (is_ident(d) || d == '.') {
          ++i_;
        } else {
          break;
        }
      }
      return make(Tok::Number, begin);
    }
    if (c == '"' || c == '\'') {
      quoted(c);
      return make(c == '"' ? Tok::String : Tok::Char, begin);
    }
    // Punctuators that matter here: # ## %: %:%:.
    const std::string_view rest(s_.text.data() + i_, s_.text.size() - i_);
    for (const std::string_view p : {"%:%:", "##", "%:", "#"}) {
      if (rest.starts_with(p)) {
        i_ += p.size();
        return make(Tok::Punct, begin);
      }
    }
    ++i_;
    return make(Tok::Other, begin);
  }

  std::string_view file_;
  const Spliced& s_;
  std::size_t i_ = 0;
};

// --- The checks --------------------------------------------------------------------------------

// Why a header name (with its < > or quotes) may not be read, or "".
std::string header_problem(const std::string& header) {
  const char opener = header.front();
  const std::string name = header.substr(1, header.size() - 2);
  const bool climbs = name.empty() || name.front() == '/' || name.find("..") != std::string::npos ||
                      name.find('\\') != std::string::npos;
  const bool allowed = opener == '<' || name.starts_with("clothlab/");
  if (!climbs && allowed) return "";
  return fmt::format(
      "{} is outside the standard library and the engine's headers; an exercise may include "
      "<...> headers and \"clothlab/...\" ones, by a name without \"..\"",
      header);
}

// The text of a string literal's contents, destringized as _Pragma does (\" and \\ undone).
std::string destringized(const std::string& literal) {
  const std::size_t open = literal.find('"');
  std::string out;
  for (std::size_t i = open + 1; i + 1 < literal.size(); ++i) {
    if (literal[i] == '\\' && (literal[i + 1] == '"' || literal[i + 1] == '\\')) ++i;
    out += literal[i];
  }
  return out;
}

// Why the tokens of a pragma (after "#pragma" or in _Pragma's string) may not be compiled, or "".
std::string pragma_problem(const std::vector<Token>& pragma) {
  for (const Token& t : pragma) {
    if (t.kind == Tok::Identifier && (t.text == "dependency" || t.text == "pch_preprocess"))
      return fmt::format("'#pragma ... {}' names a file; an exercise may not use it", t.text);
  }
  return "";
}

// The tokens of a line of text (a _Pragma's string, destringized).
std::vector<Token> tokens_of(const std::string& text) {
  const Spliced s = splice(text);
  return Lexer(text, s).tokens();
}

// Why the file may not be compiled, with the offset it concerns, or "".
struct Problem {
  std::string what;
  std::size_t at = 0;
};

Problem find_problem(std::string_view file) {
  const Spliced s = splice(file);
  const std::vector<Token> tokens = Lexer(file, s).tokens();
  const auto token = [&](std::size_t k) -> const Token* {
    return k < tokens.size() ? &tokens[k] : nullptr;
  };
  // The tokens of the line that starts at k, k included.
  const auto line_from = [&](std::size_t k) {
    std::vector<Token> line;
    for (std::size_t j = k; j < tokens.size() && (j == k || !tokens[j].first); ++j)
      line.push_back(tokens[j]);
    return line;
  };
  for (std::size_t k = 0; k < tokens.size(); ++k) {
    const Token& t = tokens[k];
    const Token* n1 = token(k + 1);
    const bool n1_same_line = n1 != nullptr && !n1->first;
    if (t.text.find("incbin") != std::string::npos)
      return {"'.incbin' reads a file into the program; an exercise may not use it", t.at};
    if (t.kind == Tok::Punct && (t.text == "##" || t.text == "%:%:")) {
      return {
          "the token-pasting operator ## may build a name that reads a file; an exercise "
          "may not use it",
          t.at};
    }
    if (t.kind == Tok::Identifier && Lexer::is_file_query(t.text)) {
      // __has_include ( header-name ), the name written out and one an #include may name.
      const Token* open = n1_same_line ? n1 : nullptr;
      const Token* name = open != nullptr && open->text == "(" ? token(k + 2) : nullptr;
      if (t.text != "__has_include" || name == nullptr || name->first ||
          name->kind != Tok::HeaderName) {
        return {fmt::format("'{}' may only ask for a header an exercise may include, written "
                            "out: __has_include(<vector>)",
                            t.text),
                t.at};
      }
      if (std::string why = header_problem(name->text); !why.empty())
        return {"__has_include: " + why, t.at};
    }
    if (t.kind == Tok::Identifier && t.text == "_Pragma") {
      const Token* open = n1_same_line ? n1 : nullptr;
      const Token* literal = open != nullptr && open->text == "(" ? token(k + 2) : nullptr;
      if (literal == nullptr || literal->kind != Tok::String) {
        return {"_Pragma may only take a string written out: _Pragma(\"GCC diagnostic ...\")",
                t.at};
      }
      if (std::string why = pragma_problem(tokens_of(destringized(literal->text))); !why.empty())
        return {why, t.at};
    }
    if (t.first && t.kind == Tok::Identifier &&
        (t.text == "import" || (t.text == "export" && n1_same_line && n1->kind == Tok::Identifier &&
                                n1->text == "import"))) {
      return {
          "an import declaration is not allowed in an exercise file; include a header by "
          "name: #include <vector>",
          t.at};
    }
    if (!t.first || (t.text != "#" && t.text != "%:") || !n1_same_line) continue;
    // A directive.
    const Token& d = *n1;
    const Token* operand = token(k + 2) != nullptr && !token(k + 2)->first ? token(k + 2) : nullptr;
    if (d.kind == Tok::Number || (d.kind == Tok::Identifier && d.text == "line")) {
      return {
          "'#line' and line markers make the compiler's messages quote another file; an "
          "exercise may not use them",
          t.at};
    }
    if (d.kind == Tok::Identifier && d.text == "pragma") {
      const std::vector<Token> line = line_from(k);
      if (std::string why = pragma_problem(line); !why.empty()) return {why, t.at};
    }
    if (d.kind != Tok::Identifier || !Lexer::is_file_directive(d.text)) continue;
    if (d.text != "include" || operand == nullptr || operand->kind != Tok::HeaderName) {
      return {fmt::format("'#{}' with what follows it is not allowed in an exercise file; "
                          "include a header by name: #include <vector> or #include "
                          "\"clothlab/...\"",
                          d.text),
              t.at};
    }
    if (std::string why = header_problem(operand->text); !why.empty())
      return {"#include " + why, t.at};
  }
  return {};
}

}  // namespace

std::string include_problem(const std::string& name, const std::string& text) {
  const Problem p = find_problem(text);
  if (p.what.empty()) return "";
  // The line of the offset, counting CR LF, LF and a lone CR as the ends of lines.
  int line = 1;
  for (std::size_t i = 0; i < p.at && i < text.size(); ++i) {
    if (text[i] == '\n' || (text[i] == '\r' && (i + 1 >= text.size() || text[i + 1] != '\n')))
      ++line;
  }
  return fmt::format("exercises/{}:{}: error: {}", name, line, p.what);
}

}  // namespace clothlab::app
