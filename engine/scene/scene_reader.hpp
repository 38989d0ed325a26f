// scene_reader.hpp: how one table of a scene file is read, checked and reported on.
//
// Each table a scene may hold has a reader function (see scene_tables.cpp) that asks its
// SceneTable for typed values. Every value is checked where it is read (type, finiteness,
// range), and every failure becomes a SceneError pointing at the offending line and column.
// Before any value is read, check_keys() rejects a key the table does not know, so a typo
// ("mas = 1") is reported as itself rather than as a missing "mass".
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.hpp"

namespace clothlab {

// The values a number may take. `unit` is printed in messages, e.g. "kg".
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;  // true: value must be > min; false: >= min
  std::string_view unit;

  static Range positive(std::string_view unit) { return {0.0, Range{}.max, true, unit}; }
  static Range non_negative(std::string_view unit) { return {0.0, Range{}.max, false, unit}; }
  static Range any(std::string_view unit) { return {Range{}.min, Range{}.max, false, unit}; }
};

class SceneTable {
 public:
  // `node` is an opaque pointer to the toml++ table; only scene.cpp knows its type.
  SceneTable(const void* node, std::string display_name, const std::string& source);

  // Numbers: integers are accepted wherever a number is expected.
  double number(std::string_view key, const Range& range, double fallback);
  double required_number(std::string_view key, const Range& range);
  Vec3 vec3(std::string_view key, std::string_view unit, const Vec3& fallback);
  Vec3 required_vec3(std::string_view key, std::string_view unit);
  // Whole numbers from min to max (inclusive).
  long integer(std::string_view key, long min, long max, long fallback);
  long required_integer(std::string_view key, long min, long max);
  // An array of whole numbers, each from min to max; `what` names one element in messages.
  std::vector<long> integer_list(std::string_view key, long min, long max, std::string_view what);
  // An array of numbers, each in range; `what` names one element in messages.
  std::vector<double> number_list(std::string_view key, const Range& range, std::string_view what);
  // An array of [x, y, z] arrays [unit].
  std::vector<Vec3> vec3_list(std::string_view key, std::string_view unit);
  // The tables under `key`, [[parent.key]] tables or one inline table, each named in messages
  // "[[parent.key]] #n"; none when the key is absent.
  std::vector<SceneTable> tables(std::string_view key);
  bool boolean(std::string_view key, bool fallback);
  std::optional<std::string> string(std::string_view key);
  bool has(std::string_view key) const;
  bool is_string(std::string_view key) const;
  bool is_array(std::string_view key) const;
  // "a string", "an integer", ...: the TOML type of `key`, for messages.
  std::string_view type_name(std::string_view key) const;
  // A string that must be one of `choices`.
  std::string choice(std::string_view key, const std::vector<std::string_view>& choices,
                     std::string_view fallback);

  // Raises a SceneError at `key` (or at the table itself when the key is absent).
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;

  // Adds a warning at `key` (at its element `element`, if given, when it is an array; at the
  // table itself when the key is absent) to `scene`.
  void warn(Scene& scene, std::string_view key, const std::string& message,
            std::optional<size_t> element = std::nullopt) const;
  // The same warning, returned: `message` at `key` (or at the table).
  SceneWarning at(std::string_view key, const std::string& message,
                  std::optional<size_t> element = std::nullopt) const;

  // Raises a SceneError for the first key that is not in `known` (names separated by spaces),
  // suggesting the nearest known name.
  void check_keys(std::string_view known) const;

  const std::string& display_name() const { return name_; }

  // From now on, each number (or element of a vector) this table reads under one of the keys
  // in `keys` (names separated by spaces) is recorded in `out`, as `path.key`: `path` is where
  // the table is ("springs", "plane[1]"). A key the text lacks is recorded with its default
  // when `defaults` is true (a program may add it under the table).
  void record_tunables(std::string_view keys, std::string path, bool defaults,
                       std::vector<TunableNumber>& out);

 private:
  void record(std::string_view key, std::optional<size_t> element, double value, const Range& range,
              bool in_text);

  const void* node_;
  std::string name_;  // "[gravity]" or "[[particle]] #2"
  const std::string& source_;
  std::string_view tunable_keys_;  // record_tunables()
  std::string path_;
  bool record_defaults_ = false;
  std::vector<TunableNumber>* tunables_ = nullptr;
  size_t tunables_from_ = 0;  // the first of `tunables_` this table recorded
};

// The name in `candidates` (separated by spaces) nearest to `typo`, or "" if none is close.
std::string nearest_name(std::string_view typo, std::string_view candidates);

}  // namespace clothlab
