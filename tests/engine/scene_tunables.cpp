// What a running program may change in a scene: the scene reader declares the tunable keys of
// each table (SceneTableKind::tunable) and records each number it reads under them, with the
// values it accepts. A live page offers its sliders from that list alone.
#include <doctest/doctest.h>

#include <algorithm>
#include <limits>
#include <string>

#include "scene/scene.hpp"
#include "scene/scene_tables.hpp"

namespace {

const clothlab::TunableNumber* find(const clothlab::Scene& scene, const std::string& path) {
  const auto it = std::ranges::find(scene.tunables, path, &clothlab::TunableNumber::path);
  return it == scene.tunables.end() ? nullptr : &*it;
}

bool contains_word(std::string_view words, std::string_view word) {
  size_t at = 0;
  while (at < words.size()) {
    const size_t end = std::min(words.find(' ', at), words.size());
    if (words.substr(at, end - at) == word) return true;
    at = end + 1;
  }
  return false;
}

}  // namespace

TEST_CASE("scene tunables: every tunable key is a key of its table, and every effect has some") {
  // The tables that set up bodies, the step, the output and the engine hold no physics a slider
  // should turn while the motion goes on; every other table is an effect and offers its numbers.
  const std::string_view settings = "guard particle rope cloth solid integrator output engine";
  for (const clothlab::SceneTableKind& kind : clothlab::scene_table_kinds()) {
    CAPTURE(kind.name);
    size_t at = 0, count = 0;
    while (at < kind.tunable.size()) {
      const size_t end = std::min(kind.tunable.find(' ', at), kind.tunable.size());
      const std::string_view key = kind.tunable.substr(at, end - at);
      CAPTURE(key);
      CHECK(contains_word(kind.keys, key));
      ++count;
      at = end + 1;
    }
    if (contains_word(settings, kind.name)) {
      CHECK(count == 0);
    } else {
      CHECK(count > 0);
    }
  }
}

TEST_CASE("scene tunables: the numbers read, with their ranges, defaults and vector elements") {
  const clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 3
cols = 3
spacing = 0.1
mass = 0.01
pins = [0]
[springs]
ks = 200
[strain_limit]
max_strain = 0.1
[aerodynamics]
wind = [1, 0, 2]
[[plane]]
point = [0, -1, 0]
normal = [0, 1, 0]
e = 0.25
[integrator]
method = "symplectic-euler"
dt = 0.001
duration = 0.01
)",
                                                      "tunables.toml");
  const clothlab::TunableNumber* ks = find(scene, "springs.ks");
  REQUIRE(ks);
  CHECK(ks->value == 200.0);
  CHECK(ks->in_text);
  CHECK(ks->min == 0.0);
  CHECK(ks->max == std::numeric_limits<double>::infinity());

  // Lesson 09's strain limit: the table is [strain_limit], its bound zero or more.
  const clothlab::TunableNumber* strain = find(scene, "strain_limit.max_strain");
  REQUIRE(strain);
  CHECK(strain->value == 0.1);
  CHECK(strain->min == 0.0);
  CHECK_FALSE(strain->min_exclusive);

  // A key the text lacks comes with the reader's default, to be added under its table.
  const clothlab::TunableNumber* kd = find(scene, "springs.kd");
  REQUIRE(kd);
  CHECK_FALSE(kd->in_text);
  CHECK(kd->value == 0.0);

  // A vector's elements, each its own number.
  const clothlab::TunableNumber* wind_z = find(scene, "aerodynamics.wind[2]");
  REQUIRE(wind_z);
  CHECK(wind_z->value == 2.0);

  // A repeated table by its index; only what its text holds.
  const clothlab::TunableNumber* e = find(scene, "plane[0].e");
  REQUIRE(e);
  CHECK(e->value == 0.25);
  CHECK(e->max == 1.0);
  CHECK_FALSE(find(scene, "plane[0].mu_s"));

  // The geometry, the step and the output are not offered.
  CHECK_FALSE(find(scene, "cloth.spacing"));
  CHECK_FALSE(find(scene, "integrator.dt"));
}

TEST_CASE(
    "scene tunables: a scene of many [[spring]] tables is read in time linear in their number" *
    doctest::timeout(60)) {
  // Each spring's ks is a tunable number. Looking for its path among every number recorded
  // before (to let a second reading of a key replace the first) made the reading quadratic:
  // 60,000 springs took 2.7 s, 300,000 more than a minute; looking among the table's own numbers
  // alone takes a second or two.
  constexpr int kSprings = 300000;
  std::string text =
      "[[particle]]\nposition = [0, 0, 0]\nmass = 1\n"
      "[[particle]]\nposition = [1, 0, 0]\nmass = 1\n";
  for (int k = 0; k < kSprings; ++k)
    text += "[[spring]]\ni = 0\nj = 1\nks = " + std::to_string(k + 1) + "\n";
  text += "[integrator]\ndt = 0.001\nduration = 0.002\n";
  const clothlab::Scene scene = clothlab::parse_scene(text, "springs.toml");
  CHECK(std::ranges::count_if(scene.tunables, [](const clothlab::TunableNumber& number) {
          return number.path.starts_with("spring[");
        }) == kSprings);
  const clothlab::TunableNumber* last = find(scene, "spring[299999].ks");
  REQUIRE(last);
  CHECK(last->value == kSprings);
}
