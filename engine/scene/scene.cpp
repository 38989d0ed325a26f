#include "scene/scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <exception>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <optional>
#include <vector>

#include <pthread.h>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "clothlab/core/not_implemented.hpp"
#include "fast/engine.hpp"
#include "scene/scene_reader.hpp"
#include "scene/scene_tables.hpp"
#include "scene/scene_warnings.hpp"

namespace clothlab {

namespace {

// `text` with each NUL character written "^@", as a message shows every other control character
// (caret notation): what() hands the message on as a C string, which would end at the first NUL
// that a scene's string, key or table name carries ("\u0000"), and lose the rest of it.
std::string without_nul(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text)
    out += c == '\0' ? std::string_view("^@") : std::string_view(&c, 1);
  return out;
}

}  // namespace

SceneError::SceneError(const std::string& source, long line, long column,
                       const std::string& message)
    : std::runtime_error(without_nul(fmt::format("{}:{}:{}: {}", source, line, column, message))),
      source_(source),
      line_(line),
      column_(column),
      message_(without_nul(message)) {}

std::string SceneWarning::text() const {
  return fmt::format("{}:{}:{}: {}", source, line, column, message);
}

long Scene::step_count() const {
  // duration / dt rounded to the nearest whole step (1.0 / 0.01 is 100.00000000000001).
  return std::max(1L, std::lround(duration / dt));
}

namespace {

const toml::table& as_table(const void* node) {
  return *static_cast<const toml::table*>(node);
}

[[noreturn]] void fail_at(const std::string& source, const toml::source_region& where,
                          const std::string& message) {
  throw SceneError(source, static_cast<long>(where.begin.line),
                   static_cast<long>(where.begin.column), message);
}

std::string_view type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::table:
      return "a table";
    default:
      return "a date or time";
  }
}

// Calls fn(name) for each name in a list separated by spaces.
template <class Fn>
void for_each_name(std::string_view names, Fn fn) {
  while (!names.empty()) {
    const size_t end = std::min(names.find(' '), names.size());
    if (end > 0) fn(names.substr(0, end));
    names.remove_prefix(std::min(end + 1, names.size()));
  }
}

bool is_one_of(std::string_view name, std::string_view names) {
  bool found = false;
  for_each_name(names, [&](std::string_view n) { found = found || n == name; });
  return found;
}

std::string comma_list(std::string_view names) {
  std::string list;
  for_each_name(names, [&](std::string_view n) {
    if (!list.empty()) list += ", ";
    list += n;
  });
  return list;
}

std::string describe_range(const Range& r) {
  std::string text;
  const bool has_min = std::isfinite(r.min);
  const bool has_max = std::isfinite(r.max);
  if (has_min && has_max) {
    text = r.min_exclusive ? fmt::format("a number > {} and <= {}", r.min, r.max)
                           : fmt::format("a number from {} to {}", r.min, r.max);
  } else if (has_min) {
    text = fmt::format("a number {} {}", r.min_exclusive ? ">" : ">=", r.min);
  } else {
    text = "a finite number";
  }
  if (!r.unit.empty()) text += fmt::format(" [{}]", r.unit);
  return text;
}

}  // namespace

// --- SceneTable ------------------------------------------------------------------------------

SceneTable::SceneTable(const void* node, std::string display_name, const std::string& source)
    : node_(node), name_(std::move(display_name)), source_(source) {}

void SceneTable::fail(std::string_view key, const std::string& message) const {
  const toml::table& table = as_table(node_);
  const toml::node* value = table.get(key);
  fail_at(source_, value ? value->source() : table.source(), message);
}

void SceneTable::warn(Scene& scene, std::string_view key, const std::string& message,
                      std::optional<size_t> element) const {
  scene.warnings.push_back(at(key, message, element));
}

SceneWarning SceneTable::at(std::string_view key, const std::string& message,
                            std::optional<size_t> element) const {
  const toml::table& table = as_table(node_);
  const toml::node* value = table.get(key);
  if (value && element) {
    const toml::array* array = value->as_array();
    if (array && *element < array->size()) value = array->get(*element);
  }
  const toml::source_region where = value ? value->source() : table.source();
  return {source_, static_cast<long>(where.begin.line), static_cast<long>(where.begin.column),
          message};
}

namespace {

// Reads one number from `node`, checking type, finiteness and range.
double checked_number(const toml::node& node, const std::string& source, std::string_view what,
                      const Range& range) {
  double x = 0.0;
  if (const auto* i = node.as_integer()) {
    x = static_cast<double>(i->get());
  } else if (const auto* d = node.as_floating_point()) {
    x = d->get();
  } else {
    fail_at(source, node.source(),
            fmt::format("{} is {}; expected {}", what, type_name(node), describe_range(range)));
  }
  if (!std::isfinite(x)) {
    fail_at(source, node.source(),
            fmt::format("{} is {}; expected {}", what, x, describe_range(range)));
  }
  const bool below = range.min_exclusive ? !(x > range.min) : !(x >= range.min);
  if (below || x > range.max) {
    fail_at(source, node.source(),
            fmt::format("{} is {}; expected {}", what, x, describe_range(range)));
  }
  return x;
}

}  // namespace

void SceneTable::record_tunables(std::string_view keys, std::string path, bool defaults,
                                 std::vector<TunableNumber>& out) {
  tunable_keys_ = keys;
  path_ = std::move(path);
  record_defaults_ = defaults;
  tunables_ = &out;
  tunables_from_ = out.size();
}

void SceneTable::record(std::string_view key, std::optional<size_t> element, double value,
                        const Range& range, bool in_text) {
  if (!tunables_ || (!in_text && !record_defaults_)) return;
  if (!is_one_of(key, tunable_keys_)) return;
  std::string path = fmt::format("{}.{}", path_, key);
  if (element) path += fmt::format("[{}]", *element);
  TunableNumber number{
      path, value, range.min, range.max, range.min_exclusive, std::string(range.unit), in_text};
  // Only this table's own numbers can share its path: looking among them alone, and not through
  // every table read before, keeps a scene of many [[spring]] tables from taking time quadratic
  // in their number.
  for (size_t k = tunables_from_; k < tunables_->size(); ++k) {
    TunableNumber& known = (*tunables_)[k];
    if (known.path == number.path) {  // read twice: the last reading holds
      known = number;
      return;
    }
  }
  tunables_->push_back(std::move(number));
}

double SceneTable::number(std::string_view key, const Range& range, double fallback) {
  const toml::node* node = as_table(node_).get(key);
  if (!node) {
    record(key, std::nullopt, fallback, range, false);
    return fallback;
  }
  const double x = checked_number(*node, source_, fmt::format("'{}' in {}", key, name_), range);
  record(key, std::nullopt, x, range, true);
  return x;
}

double SceneTable::required_number(std::string_view key, const Range& range) {
  if (!as_table(node_).contains(key)) {
    fail(key,
         fmt::format("{} has no '{}'; expected {} = {}", name_, key, key, describe_range(range)));
  }
  return number(key, range, 0.0);
}

Vec3 SceneTable::vec3(std::string_view key, std::string_view unit, const Vec3& fallback) {
  const toml::node* node = as_table(node_).get(key);
  if (!node) {
    for (size_t k = 0; k < 3; ++k)
      record(key, k, fallback[static_cast<Index>(k)], Range::any(unit), false);
    return fallback;
  }
  const toml::array* array = node->as_array();
  const std::string expected = fmt::format("an array of three numbers [x, y, z] [{}]", unit);
  if (!array) {
    fail_at(source_, node->source(),
            fmt::format("'{}' in {} is {}; expected {}", key, name_, clothlab::type_name(*node),
                        expected));
  }
  if (array->size() != 3) {
    fail_at(source_, node->source(),
            fmt::format("'{}' in {} has {} elements; expected {}", key, name_, array->size(),
                        expected));
  }
  Vec3 result;
  for (int k = 0; k < 3; ++k) {
    result[k] = checked_number((*array)[static_cast<size_t>(k)], source_,
                               fmt::format("'{}[{}]' in {}", key, k, name_), Range::any(unit));
    record(key, static_cast<size_t>(k), result[k], Range::any(unit), true);
  }
  return result;
}

Vec3 SceneTable::required_vec3(std::string_view key, std::string_view unit) {
  if (!as_table(node_).contains(key)) {
    fail(key, fmt::format("{} has no '{}'; expected {} = [x, y, z] [{}]", name_, key, key, unit));
  }
  return vec3(key, unit, Vec3::Zero());
}

namespace {

long checked_integer(const toml::node& node, const std::string& source, std::string_view what,
                     long min, long max) {
  const auto* i = node.as_integer();
  if (const auto* d = node.as_floating_point()) {
    // "rows = 3.0" is a floating-point number in TOML; name it as written, with its point.
    std::string value = fmt::format("{}", d->get());
    if (value.find_first_of(".eni") == std::string::npos) value += ".0";
    fail_at(source, node.source(),
            fmt::format("{} is {}, not a whole number; expected a whole number from {} to {} "
                        "(written without a decimal point)",
                        what, value, min, max));
  }
  if (!i) {
    fail_at(source, node.source(),
            fmt::format("{} is {}; expected a whole number from {} to {}", what, type_name(node),
                        min, max));
  }
  const long value = static_cast<long>(i->get());
  if (value < min || value > max) {
    fail_at(source, node.source(),
            fmt::format("{} is {}; expected a whole number from {} to {}", what, value, min, max));
  }
  return value;
}

}  // namespace

long SceneTable::integer(std::string_view key, long min, long max, long fallback) {
  const toml::node* node = as_table(node_).get(key);
  if (!node) return fallback;
  return checked_integer(*node, source_, fmt::format("'{}' in {}", key, name_), min, max);
}

long SceneTable::required_integer(std::string_view key, long min, long max) {
  if (!has(key)) {
    fail(key, fmt::format("{} has no '{}'; expected {} = a whole number from {} to {}", name_, key,
                          key, min, max));
  }
  return integer(key, min, max, 0);
}

std::vector<long> SceneTable::integer_list(std::string_view key, long min, long max,
                                           std::string_view what) {
  std::vector<long> values;
  const toml::node* node = as_table(node_).get(key);
  if (!node) return values;
  const toml::array* array = node->as_array();
  if (!array) {
    fail_at(source_, node->source(),
            fmt::format("'{}' in {} is {}; expected an array of whole numbers from {} to {}", key,
                        name_, clothlab::type_name(*node), min, max));
  }
  for (size_t k = 0; k < array->size(); ++k) {
    values.push_back(checked_integer(
        (*array)[k], source_, fmt::format("{} '{}[{}]' in {}", what, key, k, name_), min, max));
  }
  return values;
}

std::vector<double> SceneTable::number_list(std::string_view key, const Range& range,
                                            std::string_view what) {
  std::vector<double> values;
  const toml::node* node = as_table(node_).get(key);
  if (!node) return values;
  const toml::array* array = node->as_array();
  if (!array) {
    fail_at(source_, node->source(),
            fmt::format("'{}' in {} is {}; expected an array of numbers, each {}", key, name_,
                        clothlab::type_name(*node), describe_range(range)));
  }
  for (size_t k = 0; k < array->size(); ++k) {
    values.push_back(checked_number((*array)[k], source_,
                                    fmt::format("{} '{}[{}]' in {}", what, key, k, name_), range));
  }
  return values;
}

std::vector<Vec3> SceneTable::vec3_list(std::string_view key, std::string_view unit) {
  std::vector<Vec3> values;
  const toml::node* node = as_table(node_).get(key);
  if (!node) return values;
  const std::string expected =
      fmt::format("an array of [x, y, z] arrays, each of three numbers [{}]", unit);
  const toml::array* array = node->as_array();
  if (!array) {
    fail_at(source_, node->source(),
            fmt::format("'{}' in {} is {}; expected {}", key, name_, clothlab::type_name(*node),
                        expected));
  }
  for (size_t k = 0; k < array->size(); ++k) {
    const toml::node& element = (*array)[k];
    const toml::array* xyz = element.as_array();
    if (!xyz || xyz->size() != 3) {
      fail_at(source_, element.source(),
              fmt::format("'{}[{}]' in {} is {}; expected {}", key, k, name_,
                          xyz ? fmt::format("an array of {} elements", xyz->size())
                              : std::string(clothlab::type_name(element)),
                          expected));
    }
    Vec3 v;
    for (int c = 0; c < 3; ++c) {
      v[c] = checked_number((*xyz)[static_cast<size_t>(c)], source_,
                            fmt::format("'{}[{}][{}]' in {}", key, k, c, name_), Range::any(unit));
    }
    values.push_back(v);
  }
  return values;
}

std::vector<SceneTable> SceneTable::tables(std::string_view key) {
  std::vector<SceneTable> found;
  const toml::node* node = as_table(node_).get(key);
  if (!node) return found;
  // "[cloth]" -> "cloth": the name of the parent table, for "[[cloth.pin_path]] #1".
  std::string parent = name_;
  std::erase_if(parent, [](char c) { return c == '[' || c == ']'; });
  if (const toml::table* one = node->as_table()) {
    found.emplace_back(one, fmt::format("[{}.{}]", parent, key), source_);
    return found;
  }
  if (!node->is_array_of_tables()) {
    fail_at(source_, node->source(),
            fmt::format("'{}' in {} is {}; expected one or more [[{}.{}]] tables", key, name_,
                        clothlab::type_name(*node), parent, key));
  }
  const toml::array& array = *node->as_array();
  for (size_t k = 0; k < array.size(); ++k) {
    found.emplace_back(array[k].as_table(), fmt::format("[[{}.{}]] #{}", parent, key, k + 1),
                       source_);
  }
  return found;
}

bool SceneTable::boolean(std::string_view key, bool fallback) {
  const toml::node* node = as_table(node_).get(key);
  if (!node) return fallback;
  if (const auto* b = node->as_boolean()) return b->get();
  fail_at(source_, node->source(),
          fmt::format("'{}' in {} is {}; expected true or false", key, name_,
                      clothlab::type_name(*node)));
}

bool SceneTable::has(std::string_view key) const {
  return as_table(node_).contains(key);
}

bool SceneTable::is_string(std::string_view key) const {
  const toml::node* node = as_table(node_).get(key);
  return node && node->is_string();
}

bool SceneTable::is_array(std::string_view key) const {
  const toml::node* node = as_table(node_).get(key);
  return node && node->is_array();
}

std::string_view SceneTable::type_name(std::string_view key) const {
  const toml::node* node = as_table(node_).get(key);
  return node ? clothlab::type_name(*node) : "missing";
}

std::optional<std::string> SceneTable::string(std::string_view key) {
  const toml::node* node = as_table(node_).get(key);
  if (!node) return std::nullopt;
  if (const auto* s = node->as_string()) return s->get();
  fail_at(
      source_, node->source(),
      fmt::format("'{}' in {} is {}; expected a string", key, name_, clothlab::type_name(*node)));
}

std::string SceneTable::choice(std::string_view key, const std::vector<std::string_view>& choices,
                               std::string_view fallback) {
  const std::optional<std::string> value = string(key);
  if (!value) return std::string(fallback);
  for (std::string_view c : choices) {
    if (*value == c) return *value;
  }
  fail(key, fmt::format("unknown {} '{}' in {}; expected one of: \"{}\"", key, *value, name_,
                        fmt::join(choices, "\", \"")));
}

void SceneTable::check_keys(std::string_view known) const {
  for (auto&& [key, value] : as_table(node_)) {
    if (is_one_of(key.str(), known)) continue;
    const std::string guess = nearest_name(key.str(), known);
    fail_at(source_, key.source(),
            fmt::format("unknown key '{}' in {}{}; expected one of: {}", key.str(), name_,
                        guess.empty() ? "" : fmt::format(" (did you mean '{}'?)", guess),
                        comma_list(known)));
  }
}

std::string nearest_name(std::string_view typo, std::string_view candidates) {
  // Levenshtein distance: the fewest single-letter edits that turn one word into the other.
  auto distance = [](std::string_view a, std::string_view b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j)
      row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      size_t diagonal = row[0];
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        const size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
        diagonal = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
      }
    }
    return row[b.size()];
  };
  std::string best;
  size_t best_distance = 3;  // more than two edits away is no longer a typo
  for_each_name(candidates, [&](std::string_view name) {
    const size_t d = distance(typo, name);
    if (d < best_distance) {
      best_distance = d;
      best = name;
    }
  });
  return best;
}

// --- Reading a whole scene -------------------------------------------------------------------

namespace {

// The text from LINE:COLUMN (1-based, columns counting characters as toml++ does) to the end of
// its line, or "" past the end of the text.
std::string_view rest_of_line(std::string_view text, const toml::source_position& at) {
  size_t k = 0;
  for (toml::source_index line = 1; line < at.line; ++line) {
    k = text.find('\n', k);
    if (k == std::string_view::npos) return {};
    ++k;
  }
  for (toml::source_index column = 1; column < at.column && k < text.size(); ++column) {
    ++k;  // one character: its first byte and any UTF-8 continuation bytes (10xxxxxx)
    while (k < text.size() && (static_cast<unsigned char>(text[k]) & 0xC0) == 0x80)
      ++k;
  }
  const std::string_view rest = text.substr(std::min(k, text.size()));
  return rest.substr(0, rest.find_first_of("\r\n"));
}

// A toml++ syntax error in the reader's words. toml++ says e.g. "Error while parsing array:
// expected comma or closing ']', saw 'm'", which already names what was expected; the mistakes
// whose wording is cryptic (an unclosed string, a key given twice, a word without quotes) are
// said here instead, and anything else gets an "expected" if it has none.
std::string explain_toml_error(std::string_view text, const toml::parse_error& error) {
  const std::string_view d = error.description();
  const toml::source_position at = error.source().begin;
  constexpr auto npos = std::string_view::npos;

  // An unclosed string: toml++ stops at the newline (a control character) or the end of file.
  if (d.find("parsing string") != npos || d.find("parsing literal string") != npos) {
    if (d.find("end-of-file") != npos) {
      return "the string is not closed before the end of the file; expected a closing quote";
    }
    if (d.find("control characters") != npos && rest_of_line(text, at).empty()) {
      return "the string is not closed on its line; expected a closing quote before the end of "
             "the line";
    }
  }
  // "cannot redefine existing table 'gravity'", "cannot redefine existing integer 'rows'".
  if (const size_t k = d.find("cannot redefine existing "); k != npos) {
    const size_t open = d.find('\'', k);
    const size_t close = open == npos ? npos : d.find('\'', open + 1);
    if (close != npos) {
      const std::string_view name = d.substr(open + 1, close - open - 1);
      if (d.substr(k).starts_with("cannot redefine existing table")) {
        return fmt::format(
            "[{}] is defined twice; expected each table once ([[{}]] for a table "
            "that repeats, one per item)",
            name, name);
      }
      return fmt::format("'{}' is given twice; expected each key once in a table", name);
    }
  }
  // mass = heavy: a word where a value belongs, usually a string without its quotes.
  if (d.find("could not determine value type") != npos) {
    std::string_view word = rest_of_line(text, at);
    word = word.substr(0, std::min(word.find_first_of(" \t,]}#"), size_t{40}));
    return fmt::format(
        "'{}' is not a value; expected a number, a \"quoted string\", true, false "
        "or an array",
        word);
  }
  std::string what(d);
  if (!what.empty()) what[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(what[0])));
  if (d.find("could not be interpreted as a value") != npos) {
    what += "; expected a number between -1.8e308 and 1.8e308";
  } else if (d.find("not representable in 64 bits") != npos) {
    what += "; expected a whole number between -9223372036854775808 and 9223372036854775807";
  } else if (d.find("expected") == npos) {
    what += "; expected valid TOML";
  }
  return what;
}

// How deep a scene may nest: arrays and inline tables inside each other, or the parts of one
// dotted key (a.b.c). A scene needs 3 or so; the TOML reader recurses once per level, so a file
// nested tens of thousands deep would overflow the stack before it could say what is wrong.
// The deepest tree these limits let through (a 65-part table header, then 64 inline tables in
// each other, each with a 65-part key: about 4,300 levels) is read in under 512 KiB of stack.
constexpr int kMaxNesting = 64;

// Fails at the first place `text` nests deeper than kMaxNesting, found without parsing: brackets
// and braces counted outside strings and comments, and the dots of a run of key parts. Strings
// are skipped as TOML 1.0's grammar has them, so that no quote the TOML reader takes for text
// can hide what follows from the count:
//   "basic" and 'literal' strings end on their line (a newline in one is an error);
//   a basic string's backslash escapes the next character ("a\"b" is one string);
//   """multi-line""" and '''multi-line''' strings end at the first three quotes not escaped,
//   which may follow one or two quotes of the string's own: """a"""" is the string a", so the
//   closing run of quotes is 3 to 5 long.
void check_nesting(std::string_view text, const std::string& source) {
  size_t k = 0;               // the byte looked at
  long line = 1, column = 1;  // of text[k]; columns count characters, as toml++ does
  int depth = 0, dots = 0;
  const auto fail = [&](std::string_view what) {
    throw SceneError(source, line, column,
                     fmt::format("{} nest more than {} deep; expected a scene that nests a few "
                                 "levels (the TOML reader stops here rather than run out of stack)",
                                 what, kMaxNesting));
  };
  const auto skip = [&](size_t n) {  // moves past n bytes
    for (; n > 0 && k < text.size(); --n, ++k) {
      const auto b = static_cast<unsigned char>(text[k]);
      if (b == '\n') {
        ++line;
        column = 1;
      } else if ((b & 0xC0) != 0x80) {  // not a UTF-8 continuation byte (10xxxxxx)
        ++column;
      }
    }
  };
  const auto at = [&](std::string_view s) { return text.substr(k, s.size()) == s; };
  while (k < text.size()) {
    const char c = text[k];
    if (c == '#') {  // a comment, to the end of its line
      while (k < text.size() && text[k] != '\n')
        skip(1);
      continue;
    }
    if (c == '"' || c == '\'') {
      const bool basic = c == '"';
      const std::string_view three = basic ? "\"\"\"" : "'''";
      if (at(three)) {
        for (skip(3); k < text.size();) {
          if (basic && text[k] == '\\') {
            skip(2);  // an escaped character, maybe a quote or a backslash
          } else if (at(three)) {
            size_t run = 3;  // the closing quotes: the last three of a run of up to five
            while (run < 5 && k + run < text.size() && text[k + run] == c)
              ++run;
            skip(run);
            break;
          } else {
            skip(1);
          }
        }
      } else {
        for (skip(1); k < text.size() && text[k] != '\n';) {
          const bool escape =
              basic && text[k] == '\\' && k + 1 < text.size() && text[k + 1] != '\n';
          const bool closes = text[k] == c;
          skip(escape ? 2 : 1);
          if (closes) break;
        }
      }
      continue;
    }
    if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) fail("arrays and inline tables");
      dots = 0;
    } else if (c == ']' || c == '}') {
      depth = std::max(0, depth - 1);
      dots = 0;
    } else if (c == '=' || c == ',' || c == '\n') {
      dots = 0;
    } else if (c == '.') {
      if (++dots > kMaxNesting) fail("the parts of a dotted key");
    }
    skip(1);
  }
}

// The stack the TOML reader and the scene's reading run on [bytes]: a size known in advance,
// whatever the process's own stack limit (ulimit -s) is, and 128 times what the deepest scene
// check_nesting lets through needs. It is reserved, not used: only the pages a parse touches
// cost memory.
constexpr size_t kReadStackBytes = size_t{64} << 20;

// Runs fn on a thread of its own with a stack of kReadStackBytes and rethrows what it throws; on
// this thread if the system will not start one (a limit on threads or on memory).
void on_large_stack(const std::function<void()>& fn) {
  struct Job {
    const std::function<void()>* fn;
    std::exception_ptr error;
  } job{&fn, nullptr};
  pthread_attr_t attr;
  pthread_t thread;
  bool started = false;
  if (pthread_attr_init(&attr) == 0) {
    const auto body = [](void* p) -> void* {
      Job& j = *static_cast<Job*>(p);
      try {
        (*j.fn)();
      } catch (...) {
        j.error = std::current_exception();
      }
      return nullptr;
    };
    started = pthread_attr_setstacksize(&attr, kReadStackBytes) == 0 &&
              pthread_create(&thread, &attr, body, &job) == 0;
    pthread_attr_destroy(&attr);
  }
  if (!started) return fn();
  pthread_join(thread, nullptr);
  if (job.error) std::rethrow_exception(job.error);
}

// Where a key of the table that made particle i is: the first of `keys` that its [[particle]]
// table, or its body's table ([rope], [cloth] or [solid]), holds; the table itself when it holds
// none. [[particle]] tables are read first, so particle i < their count is table #i + 1.
toml::source_region particle_key(const toml::table& root, const Scene& scene, Index i,
                                 std::initializer_list<std::string_view> keys) {
  const toml::table* t = nullptr;
  if (const toml::array* particles = root["particle"].as_array();
      particles && i < static_cast<Index>(particles->size())) {
    t = particles->get(static_cast<size_t>(i))->as_table();
  } else if (scene.rope && i >= scene.rope->first && i < scene.rope->first + scene.rope->count) {
    t = root["rope"].as_table();
  } else if (scene.cloth && i >= scene.cloth->first &&
             i < scene.cloth->first + scene.cloth->size()) {
    t = root["cloth"].as_table();
  } else {
    t = root["solid"].as_table();
  }
  if (!t) return {};
  for (std::string_view key : keys) {
    if (const toml::node* k = t->get(key)) return k->source();
  }
  return t->source();
}

// Where particle i was made: the key that places it (position; a rope's start; a cloth's origin,
// or its spacing; a solid's corner, or its size).
toml::source_region particle_source(const toml::table& root, const Scene& scene, Index i) {
  return particle_key(root, scene, i, {"position", "start", "origin", "spacing", "corner", "size"});
}

// The scene's energy at the start must be a number: a run takes it first (the guard measures
// growth from it, energy.csv writes it), and refused it at frame 0 when it overflowed. Refused
// here, at the key responsible: the kinetic energy 1/2 m |v|^2 of the particle with the most (its
// velocity, or its mass), or the potential energy of the effect that holds it (its constant).
void check_start_energy(const toml::table& root, const Scene& scene) {
  const World& world = scene.world;
  const Particles& p = world.particles;
  const auto fail = [&](const toml::source_region& where, const std::string& message) {
    fail_at(scene.source, where, message);
  };
  if (const double kinetic = world.kinetic_energy(); !std::isfinite(kinetic)) {
    Index i = 0;
    const VectorX each = 0.5 * p.m.array() * p.v.colwise().squaredNorm().transpose().array();
    each.maxCoeff(&i);
    fail(particle_key(root, scene, i, {"velocity", "spin", "mass", "density"}),
         fmt::format("the particles start with a kinetic energy of {} J, too large for a double; "
                     "particle {} ({}) has the most, 1/2 m |v|^2 = {:.3g} J with m = {:.3g} kg "
                     "and |v| = {:.3g} m/s; expected a smaller mass or speed",
                     kinetic, i, describe_particle(scene, i), each[i], p.m[i], p.v.col(i).norm()));
  }
  double total = world.kinetic_energy();
  for (const auto& effect : world.force_effects) {
    // [gravitation]'s energy sums over every pair: on a large scene, its run takes it (and its
    // warning says how long that is), not the reader.
    if (effect->name() == "gravitation" && p.size() > kAllPairsWarnAbove) continue;
    double energy = 0.0;
    try {
      energy = effect->potential_energy(p, p.x);
    } catch (const NotImplemented&) {
      continue;  // a student's unfinished energy kernel: the run names the exercise, not the reader
    }
    total += energy;
    if (std::isfinite(energy) && std::isfinite(total)) continue;
    const std::string_view name = effect->name();
    // The table that made the effect, and its constant.
    const std::string_view table = name == "springs" && !root.contains("springs") ? "spring" : name;
    const toml::node* node = root.get(table);
    if (const toml::array* list = node ? node->as_array() : nullptr; list && !list->empty()) {
      node = list->get(0);
    }
    const toml::table* t = node ? node->as_table() : nullptr;
    const toml::node* key = nullptr;
    for (std::string_view k : {"ks", "g", "G", "volume"}) {
      if (t && !key) key = t->get(k);
    }
    fail(key    ? key->source()
         : node ? node->source()
                : toml::source_region{},
         std::isfinite(energy)
             ? fmt::format("the scene's energy at the start sums to {} J once the potential "
                           "energy of {} ({:.3g} J) is added, too large for a double; expected "
                           "smaller constants, masses or distances",
                           total, name, energy)
             : fmt::format("the potential energy of {} at the start is {} J, too large for a "
                           "double; expected smaller constants, masses or distances",
                           name, energy));
  }
}

// The warnings that need the whole scene: particles that start at one point or inside a
// collider, and an all-pairs effect on many particles.
void warn_about_whole_scene(const toml::table& root, Scene& scene) {
  const auto warn = [&](const toml::source_region& where, const std::string& message) {
    scene.warnings.push_back({scene.source, static_cast<long>(where.begin.line),
                              static_cast<long>(where.begin.column), message});
  };
  const Matrix3X& x = scene.world.particles.x;
  if (const CoincidentParticles c = find_coincident_particles(x); c.count > 0) {
    const Vec3 at = x.col(c.second);
    warn(particle_source(root, scene, c.second),
         fmt::format("particle {} ({}) starts at ({}, {}, {}) m, exactly where particle {} ({}) "
                     "does ({} particle{} in all start where a lower-numbered one does); between "
                     "particles at one point a force has no direction (a spring has no rest "
                     "length, gravitation skips the pair): give each particle its own position",
                     c.second, describe_particle(scene, c.second), at.x(), at.y(), at.z(), c.first,
                     describe_particle(scene, c.first), c.count, c.count == 1 ? "" : "s"));
  }
  for (const StartInside& in : find_particles_inside(scene.world)) {
    const Index i = in.first;
    const Vec3 at = x.col(i);
    warn(particle_source(root, scene, i),
         fmt::format("particle {} ({}) starts at ({}, {}, {}) m, {:.3g} m inside {} ({} free "
                     "particle{} in all start inside it, the deepest {:.3g} m); its first contact "
                     "pushes them out to its surface at once, a jump that gives them energy no "
                     "force put in: start them outside it, or pin them",
                     i, describe_particle(scene, i), at.x(), at.y(), at.z(), in.depth, in.what,
                     in.count, in.count == 1 ? "" : "s", in.deepest));
  }
  if (const std::string cost = all_pairs_warning(scene); !cost.empty()) {
    warn(root["gravitation"].node()->source(), cost);
  }
}

}  // namespace

namespace {

// The scene in `text`, once check_nesting has passed it.
Scene read_scene(std::string_view text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& error) {
    fail_at(source, error.source(), "invalid TOML: " + explain_toml_error(text, error));
  }

  Scene scene;
  scene.source = source;
  const toml::source_region top{{1, 1}, {1, 1}, nullptr};

  // Every top-level key is a table this build knows, or the scene's title.
  for (auto&& [key, value] : root) {
    if (key.str() == "title") {
      if (!value.is_string()) {
        fail_at(source, value.source(),
                fmt::format("'title' is {}; expected a string", type_name(value)));
      }
      scene.title = value.as_string()->get();
      continue;
    }
    const SceneTableKind* kind = find_scene_table(key.str());
    if (!kind) {
      const std::string guess = nearest_name(key.str(), scene_table_names());
      fail_at(source, key.source(),
              fmt::format("unknown table [{}]{}; expected one of: {}", key.str(),
                          guess.empty() ? "" : fmt::format(" (did you mean [{}]?)", guess),
                          comma_list(scene_table_names())));
    }
    const bool is_array_of_tables = value.is_array_of_tables();
    if (kind->repeated ? !is_array_of_tables : !value.is_table()) {
      fail_at(source, value.source(),
              kind->repeated ? fmt::format("'{}' is {}; expected one or more [[{}]] tables",
                                           key.str(), type_name(value), key.str())
                             : fmt::format("'{}' is {}; expected a [{}] table", key.str(),
                                           type_name(value), key.str()));
    }
  }

  // The engine's fast path, unless [engine] says fast_path = false.
  scene.world.backend = fast::make_fast_engine();
  // Read the tables in the order the engine needs them (particles before the effects on them).
  for (const SceneTableKind& kind : scene_table_kinds()) {
    const toml::node* node = root.get(kind.name);
    if (!node) {
      if (kind.required) {
        fail_at(source, top,
                fmt::format("the scene has no [{}] table; expected {}", kind.name, kind.summary));
      }
      continue;
    }
    if (kind.repeated) {
      const toml::array& array = *node->as_array();
      for (size_t i = 0; i < array.size(); ++i) {
        SceneTable table(array[i].as_table(), fmt::format("[[{}]] #{}", kind.name, i + 1), source);
        table.check_keys(kind.keys);
        // A key absent from one of several tables cannot be added by its path: no defaults.
        table.record_tunables(kind.tunable, fmt::format("{}[{}]", kind.name, i), false,
                              scene.tunables);
        kind.read(table, scene);
      }
    } else {
      SceneTable table(node->as_table(), fmt::format("[{}]", kind.name), source);
      table.check_keys(kind.keys);
      table.record_tunables(kind.tunable, std::string(kind.name), !node->as_table()->is_inline(),
                            scene.tunables);
      kind.read(table, scene);
    }
  }
  finish_scene(scene, [&](const std::string& message) { fail_at(source, top, message); });
  check_start_energy(root, scene);
  warn_about_whole_scene(root, scene);
  return scene;
}

}  // namespace

Scene parse_scene(std::string_view text, const std::string& source) {
  check_nesting(text, source);
  // The TOML reader, the reading of the tables and the freeing of the TOML tree recurse once per
  // level of nesting: on a stack of a known size.
  std::optional<Scene> scene;
  on_large_stack([&] { scene = read_scene(text, source); });
  return std::move(*scene);
}

Scene load_scene_file(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const std::string name = path.string();
  // What the path is, before anything is read: a directory or a device (/dev/zero, a pipe)
  // is no scene, and a device could be read forever.
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (fs::is_directory(status)) {
    throw SceneError(name, 1, 1, "is a directory; expected a scene file (.toml)");
  }
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw SceneError(name, 1, 1,
                     "is not a regular file (a device, pipe or socket); expected a scene file "
                     "(.toml)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(name, 1, 1, "cannot open the file; expected a readable scene");
  // At most kMaxSceneBytes, read as such: the file may grow while it is read.
  std::string text(kMaxSceneBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  if (text.size() > kMaxSceneBytes) {
    throw SceneError(name, 1, 1,
                     fmt::format("is larger than {} MiB; expected a scene file (scenes are a few "
                                 "kilobytes: bodies are built from a few numbers, not listed)",
                                 kMaxSceneBytes >> 20));
  }
  return parse_scene(text, name);
}

}  // namespace clothlab
