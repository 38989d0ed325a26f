// Bad scenes: one file per mistake under tests/scenes/bad/, each starting with the line
//   # expect: LINE:COL: message
// The test loads the file and checks the error is exactly FILE:LINE:COL: message.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;

namespace {

std::string expected_error(const fs::path& file) {
  std::ifstream in(file);
  std::string first;
  std::getline(in, first);
  const std::string marker = "# expect: ";
  REQUIRE_MESSAGE(first.rfind(marker, 0) == 0, file.string() << " must start with '# expect: '");
  return file.string() + ":" + first.substr(marker.size());
}

void check_bad_scene(const std::string& name) {
  const fs::path file = fs::path(CLOTHLAB_TEST_SCENES) / "bad" / name;
  REQUIRE(fs::exists(file));
  const std::string expected = expected_error(file);
  try {
    (void)clothlab::load_scene_file(file);
    FAIL("the scene loaded, but it should have been rejected with: " << expected);
  } catch (const clothlab::SceneError& e) {
    CHECK(std::string(e.what()) == expected);
  }
}

}  // namespace

// One test case per message, so a report names the message that changed.
TEST_CASE("scene error: TOML syntax error") {
  check_bad_scene("syntax_error.toml");
}
TEST_CASE("scene error: unknown table") {
  check_bad_scene("unknown_table.toml");
}
TEST_CASE("scene error: unknown key") {
  check_bad_scene("unknown_key.toml");
}
TEST_CASE("scene error: wrong type") {
  check_bad_scene("wrong_type.toml");
}
TEST_CASE("scene error: missing required key") {
  check_bad_scene("missing_mass.toml");
}
TEST_CASE("scene error: zero mass") {
  check_bad_scene("zero_mass.toml");
}
TEST_CASE("scene error: negative dt") {
  check_bad_scene("negative_dt.toml");
}
TEST_CASE("scene error: zero dt") {
  check_bad_scene("zero_dt.toml");
}
TEST_CASE("scene error: NaN in a vector") {
  check_bad_scene("nan_velocity.toml");
}
TEST_CASE("scene error: infinite number") {
  check_bad_scene("infinite_g.toml");
}
TEST_CASE("scene error: unknown integrator") {
  check_bad_scene("unknown_integrator.toml");
}
TEST_CASE("scene error: no integrator table") {
  check_bad_scene("no_integrator.toml");
}
TEST_CASE("scene error: no particles") {
  check_bad_scene("no_particles.toml");
}
TEST_CASE("scene error: a vector of two numbers") {
  check_bad_scene("short_vector.toml");
}
TEST_CASE("scene error: [particle] instead of [[particle]]") {
  check_bad_scene("particle_not_array.toml");
}
TEST_CASE("scene error: dt longer than the duration") {
  check_bad_scene("dt_longer_than_duration.toml");
}
TEST_CASE("scene error: negative gravitational constant") {
  check_bad_scene("negative_G.toml");
}

TEST_CASE("scene error: negative spring constant") {
  check_bad_scene("negative_stiffness.toml");
}
TEST_CASE("scene error: pin index out of range") {
  check_bad_scene("pin_out_of_range.toml");
}
TEST_CASE("scene error: a grid smaller than 2 x 2") {
  check_bad_scene("grid_too_small.toml");
}
TEST_CASE("scene error: both mass and density") {
  check_bad_scene("mass_and_density.toml");
}
TEST_CASE("scene error: unknown pin set") {
  check_bad_scene("unknown_pin_set.toml");
}
TEST_CASE("scene error: aerodynamics without a cloth") {
  check_bad_scene("aerodynamics_without_cloth.toml");
}
TEST_CASE("scene error: springs without a cloth or rope") {
  check_bad_scene("springs_without_cloth.toml");
}
TEST_CASE("scene error: a spring from a particle to itself") {
  check_bad_scene("spring_to_itself.toml");
}
TEST_CASE("scene error: a spring to a particle that does not exist") {
  check_bad_scene("spring_index_out_of_range.toml");
}
TEST_CASE("scene error: a rope of no length") {
  check_bad_scene("rope_of_no_length.toml");
}

TEST_CASE("scene error: restitution above 1") {
  check_bad_scene("restitution_above_one.toml");
}
TEST_CASE("scene error: dynamic friction above static friction") {
  check_bad_scene("dynamic_above_static_friction.toml");
}
TEST_CASE("scene error: the simple model's friction in the Coulomb model") {
  check_bad_scene("friction_in_coulomb_model.toml");
}
TEST_CASE("scene error: a sphere of radius 0") {
  check_bad_scene("sphere_without_radius.toml");
}

TEST_CASE("scene error: plasticity without springs") {
  check_bad_scene("plasticity_without_springs.toml");
}
TEST_CASE("scene error: a yield strain above 0.99") {
  check_bad_scene("yield_strain_out_of_range.toml");
}
TEST_CASE("scene error: a negative tearing strain") {
  check_bad_scene("negative_tear_strain.toml");
}

// TOML syntax.
TEST_CASE("scene error: a string not closed on its line") {
  check_bad_scene("unterminated_string.toml");
}
TEST_CASE("scene error: a table header without its closing bracket") {
  check_bad_scene("bad_table_header.toml");
}
TEST_CASE("scene error: a key given twice") {
  check_bad_scene("duplicate_key.toml");
}
TEST_CASE("scene error: a table given twice") {
  check_bad_scene("duplicate_table.toml");
}
TEST_CASE("scene error: a word without quotes where a value belongs") {
  check_bad_scene("value_without_quotes.toml");
}
TEST_CASE("scene error: a number beyond the range of a double") {
  check_bad_scene("number_too_large.toml");
}

// Unknown names.
TEST_CASE("scene error: an unknown key with no near name") {
  check_bad_scene("unknown_key_far_from_any.toml");
}

// Wrong types.
TEST_CASE("scene error: a boolean where a number belongs") {
  check_bad_scene("bool_for_number.toml");
}
TEST_CASE("scene error: a string where a vector belongs") {
  check_bad_scene("string_for_vector.toml");
}
TEST_CASE("scene error: a vector of four numbers") {
  check_bad_scene("long_vector.toml");
}
TEST_CASE("scene error: a fractional number of rows") {
  check_bad_scene("fractional_rows.toml");
}
TEST_CASE("scene error: a string where true or false belongs") {
  check_bad_scene("string_for_bool.toml");
}
TEST_CASE("scene error: a title that is not a string") {
  check_bad_scene("title_not_string.toml");
}
TEST_CASE("scene error: pins that are neither a name nor an array") {
  check_bad_scene("pins_wrong_type.toml");
}

// Out of range.
TEST_CASE("scene error: negative friction in the simple model") {
  check_bad_scene("negative_friction.toml");
}
TEST_CASE("scene error: a negative static friction coefficient") {
  check_bad_scene("negative_static_friction.toml");
}
TEST_CASE("scene error: a negative damping rate") {
  check_bad_scene("negative_damping.toml");
}
TEST_CASE("scene error: a negative damping constant on a spring") {
  check_bad_scene("negative_spring_damping.toml");
}
TEST_CASE("scene error: zero frames per second") {
  check_bad_scene("zero_fps.toml");
}
TEST_CASE("scene error: a solver tolerance of 0") {
  check_bad_scene("zero_tolerance.toml");
}
TEST_CASE("scene error: a solver limit of 0 iterations") {
  check_bad_scene("zero_max_iterations.toml");
}
TEST_CASE("scene error: more than 1e9 steps") {
  check_bad_scene("too_many_steps.toml");
}
TEST_CASE("scene error: a solver tolerance for an explicit method") {
  check_bad_scene("tolerance_without_implicit.toml");
}
TEST_CASE("scene error: a solver iteration limit for the default method") {
  check_bad_scene("max_iterations_without_implicit.toml");
}
TEST_CASE("scene error: substeps for a method other than xpbd") {
  check_bad_scene("substeps_without_xpbd.toml");
}
TEST_CASE("scene error: iterations for a method other than xpbd or local-global or vbd") {
  check_bad_scene("iterations_without_xpbd.toml");
}
TEST_CASE("scene error: xpbd with 0 substeps") {
  check_bad_scene("zero_substeps.toml");
}
TEST_CASE("scene error: local-global with 0 iterations") {
  check_bad_scene("zero_iterations_local_global.toml");
}
TEST_CASE("scene error: substeps for local-global") {
  check_bad_scene("substeps_with_local_global.toml");
}
TEST_CASE("scene error: vbd with 0 iterations") {
  check_bad_scene("zero_iterations_vbd.toml");
}
TEST_CASE("scene error: substeps for vbd") {
  check_bad_scene("substeps_with_vbd.toml");
}

// Not finite, or overflowing.
TEST_CASE("scene error: a mass of nan") {
  check_bad_scene("nan_mass.toml");
}
TEST_CASE("scene error: an infinite duration") {
  check_bad_scene("infinite_duration.toml");
}
TEST_CASE("scene error: a spacing so large the cloth leaves the guard's bounds") {
  check_bad_scene("cloth_spacing_overflow.toml");
}
TEST_CASE("scene error: a density and spacing whose mass overflows") {
  check_bad_scene("cloth_density_overflow.toml");
}

// Masses.
TEST_CASE("scene error: negative mass") {
  check_bad_scene("negative_mass.toml");
}
TEST_CASE("scene error: negative density") {
  check_bad_scene("negative_density.toml");
}
TEST_CASE("scene error: a mass too small to divide by") {
  check_bad_scene("particle_mass_too_small.toml");
}
TEST_CASE("scene error: a cloth mass too small to share among its particles") {
  check_bad_scene("cloth_mass_too_small.toml");
}

// Degenerate cloths and ropes.
TEST_CASE("scene error: a cloth with no columns") {
  check_bad_scene("cols_too_small.toml");
}
TEST_CASE("scene error: a cloth of spacing 0") {
  check_bad_scene("zero_spacing.toml");
}
TEST_CASE("scene error: a rope of one particle") {
  check_bad_scene("rope_of_one_particle.toml");
}
TEST_CASE("scene error: a cloth of more than a million particles") {
  check_bad_scene("cloth_too_large.toml");
}

// Pins.
TEST_CASE("scene error: a rope pin index past the last particle") {
  check_bad_scene("rope_pin_out_of_range.toml");
}
TEST_CASE("scene error: a negative pin index") {
  check_bad_scene("negative_pin_index.toml");
}
TEST_CASE("scene error: an unknown rope pin set") {
  check_bad_scene("unknown_rope_pin_set.toml");
}

// Springs.
TEST_CASE("scene error: a spring with one particle in the scene") {
  check_bad_scene("spring_needs_two_particles.toml");
}
TEST_CASE("scene error: a spring to particle -1") {
  check_bad_scene("spring_negative_index.toml");
}

// Contradictions.
TEST_CASE("scene error: Coulomb friction in the simple model") {
  check_bad_scene("coulomb_key_in_simple_model.toml");
}
TEST_CASE("scene error: bending without a cloth or rope") {
  check_bad_scene("bending_without_cloth.toml");
}
TEST_CASE("scene error: tearing without springs") {
  check_bad_scene("tearing_without_springs.toml");
}
TEST_CASE("scene error: a pinned particle with a velocity") {
  check_bad_scene("pinned_particle_with_velocity.toml");
}
TEST_CASE("scene error: a particle that starts beyond the guard's bounds") {
  check_bad_scene("particle_beyond_guard.toml");
}
TEST_CASE("scene error: a velocity beyond the guard's max_speed") {
  check_bad_scene("velocity_beyond_guard.toml");
}

// Strain limiting and soft solids (lesson 09).
TEST_CASE("scene error: strain limiting without springs") {
  check_bad_scene("strain_limit_without_springs.toml");
}
TEST_CASE("scene error: a negative largest strain") {
  check_bad_scene("negative_max_strain.toml");
}
TEST_CASE("scene error: a largest compression above 1") {
  check_bad_scene("max_compression_above_one.toml");
}
TEST_CASE("scene error: strain limiting with 0 sweeps") {
  check_bad_scene("zero_strain_iterations.toml");
}
TEST_CASE("scene error: a misspelt key in [strain_limit]") {
  check_bad_scene("strain_limit_unknown_key.toml");
}
TEST_CASE("scene error: a solid one particle thick") {
  check_bad_scene("solid_flat.toml");
}
TEST_CASE("scene error: a solid with two particle counts") {
  check_bad_scene("solid_two_counts.toml");
}
TEST_CASE("scene error: a solid without its particle counts") {
  check_bad_scene("solid_without_particles.toml");
}
TEST_CASE("scene error: a solid of zero height") {
  check_bad_scene("solid_zero_size.toml");
}
TEST_CASE("scene error: an unknown solid pin set") {
  check_bad_scene("solid_unknown_pin_set.toml");
}

// Self-collision (lesson 10).
TEST_CASE("scene error: self-collision without a thickness") {
  check_bad_scene("self_collision_without_thickness.toml");
}
TEST_CASE("scene error: a self-collision thickness of zero") {
  check_bad_scene("zero_thickness.toml");
}
TEST_CASE("scene error: a self-collision thickness too small for the guard's box") {
  check_bad_scene("self_collision_thickness_too_small.toml");
}
TEST_CASE("scene error: a self-collision restitution above 1") {
  check_bad_scene("self_collision_restitution_above_one.toml");
}
TEST_CASE("scene error: self-collision with 0 passes") {
  check_bad_scene("zero_self_collision_iterations.toml");
}
TEST_CASE("scene error: a misspelt key in [self_collision]") {
  check_bad_scene("self_collision_unknown_key.toml");
}

// Bodies that start moving, pins that move, wind that changes, masses by area, what a run writes.
TEST_CASE("scene error: a solid's velocity of two numbers") {
  check_bad_scene("solid_velocity_two_numbers.toml");
}
TEST_CASE("scene error: a spin that starts the cloth's rim beyond the guard's max_speed") {
  check_bad_scene("cloth_spin_beyond_guard.toml");
}
TEST_CASE("scene error: a pin path's times that do not increase") {
  check_bad_scene("pin_path_times_not_increasing.toml");
}
TEST_CASE("scene error: a pin path with fewer offsets than times") {
  check_bad_scene("pin_path_offsets_per_time.toml");
}
TEST_CASE("scene error: a pin path with keyframes and a circle") {
  check_bad_scene("pin_path_keyframes_and_circle.toml");
}
TEST_CASE("scene error: a pin circle of period 0") {
  check_bad_scene("pin_path_zero_period.toml");
}
TEST_CASE("scene error: a pin circle given a radius") {
  check_bad_scene("pin_path_radius.toml");
}
TEST_CASE("scene error: a gust without its period") {
  check_bad_scene("gust_without_period.toml");
}
TEST_CASE("scene error: a steady wind and winds at times") {
  check_bad_scene("wind_and_wind_values.toml");
}
TEST_CASE("scene error: an unknown way to share the cloth's mass") {
  check_bad_scene("unknown_mass_by.toml");
}
TEST_CASE("scene error: springs output that is not true or false") {
  check_bad_scene("output_springs_not_bool.toml");
}

// Scenes that once crashed the reader (a stack overflow in the TOML library), 80 KB each, made by
//   python3 -c 'print("a." * 40000 + "b = 1")'  and  'print("x = " + "[" * 40000 + "]" * 40000)'
// under their "# expect:" line: refused at the 65th level, before the TOML reader sees them.
TEST_CASE("scene error: a dotted key 40,000 parts deep") {
  check_bad_scene("deep_dotted_key.toml");
}
TEST_CASE("scene error: an array nested 40,000 deep") {
  check_bad_scene("deep_array.toml");
}

// The same key after a multi-line string that ends in a quote of its own (TOML 1.0 lets it end
// in one or two): the check took that quote for the start of a one-line string, which it read on
// across the lines, so the key went uncounted and crashed the TOML reader (SIGSEGV).
TEST_CASE("scene error: a deep key after a multi-line string that ends in an extra quote") {
  check_bad_scene("deep_key_after_multiline_string.toml");
  check_bad_scene("deep_key_after_multiline_literal.toml");
}

// Starts that `validate` once passed and `run` refused at its first step or frame: a pin path
// beyond the guard's bounds (blamed on "your own code") or faster than its max_speed, and an
// energy at the start too large for a double.
TEST_CASE("scene error: a pin path that leaves the guard's bounds, at its start or later") {
  check_bad_scene("pin_path_beyond_guard.toml");
  check_bad_scene("pin_circle_beyond_guard.toml");
}
TEST_CASE("scene error: a pin path faster than the guard's max_speed") {
  check_bad_scene("pin_path_too_fast.toml");
}
TEST_CASE("scene error: a wind or a gust faster than the guard's max_speed") {
  check_bad_scene("wind_beyond_guard.toml");
  check_bad_scene("gust_beyond_guard.toml");
}
TEST_CASE("scene error: an energy at the start too large for a double") {
  check_bad_scene("infinite_kinetic_energy.toml");
  check_bad_scene("infinite_spring_energy.toml");
}

TEST_CASE("scene error: every bad scene file has a test case") {
  // A file added to tests/scenes/bad/ without a test above would never be checked.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(CLOTHLAB_TEST_SCENES) / "bad")) {
    if (entry.path().extension() == ".toml") ++files;
  }
  CHECK(files == 126);
}

TEST_CASE("scene error: a missing file") {
  CHECK_THROWS_WITH_AS((void)clothlab::load_scene_file("no/such/scene.toml"),
                       "no/such/scene.toml:1:1: cannot open the file; expected a readable scene",
                       clothlab::SceneError);
}

// ---- Inputs that would crash or hang the reader ------------------------------------------------

TEST_CASE("scene error: nesting tens of thousands deep is refused before the TOML reader") {
  // Once a stack overflow inside the TOML library: a dotted key 40,000 parts deep.
  std::string dotted = "title = \"deep\"\n";
  for (int k = 0; k < 40000; ++k)
    dotted += "a.";
  dotted += "b = 1\n";
  CHECK_THROWS_WITH_AS((void)clothlab::parse_scene(dotted, "deep.toml"),
                       doctest::Contains("deep.toml:2:130: the parts of a dotted key nest more "
                                         "than 64 deep"),
                       clothlab::SceneError);
  // Arrays in arrays, and inline tables in inline tables.
  const std::string arrays = "x = " + std::string(100000, '[') + std::string(100000, ']') + "\n";
  CHECK_THROWS_WITH_AS((void)clothlab::parse_scene(arrays, "arrays.toml"),
                       doctest::Contains("arrays.toml:1:69: arrays and inline tables nest more "
                                         "than 64 deep"),
                       clothlab::SceneError);
  std::string tables = "x = ";
  for (int k = 0; k < 50000; ++k)
    tables += "{a = ";
  CHECK_THROWS_WITH_AS((void)clothlab::parse_scene(tables, "tables.toml"),
                       doctest::Contains("tables.toml:1:"), clothlab::SceneError);
  // Brackets and dots inside strings and comments are text, not nesting: this scene is fine.
  const std::string quoted = "title = \"" + std::string(200, '[') + "\" # " +
                             std::string(200, '{') +
                             "\n[[particle]]\nposition = [0.5, 1.5, 2.5]\n"
                             "mass = 1.0\n[integrator]\ndt = 0.001\nduration = 0.01\n";
  CHECK_NOTHROW((void)clothlab::parse_scene(quoted, "quoted.toml"));
}

TEST_CASE("scene error: the nesting check reads TOML's strings as the TOML reader does") {
  // Each line below ends its string where TOML 1.0 ends it; a key of 100 parts follows on the
  // next line, which the check must see. Had the check read a string on past its end, the key
  // would have hidden in it, and its 40,000-part form would have crashed the TOML reader.
  std::string key;
  for (int k = 0; k < 99; ++k)
    key += "a.";
  key += "a = 1\n";
  const char* strings[] = {
      R"(s = """a"""")",       // one quote of the string's own, then the closer: a"
      R"(s = """a""""")",      // two of its own: a""
      R"(s = '''a'''')",       // the same for multi-line literal strings
      R"(s = '''a''''')",      //
      R"(s = """a\"""")",      // an escaped quote, then the closer: a"
      R"(s = """a\\""")",      // an escaped backslash, then the closer (not an escaped quote)
      R"(s = "a\"b")",         // an escaped quote inside a one-line string
      R"(s = "a\\")",          // an escaped backslash at its end
      R"(s = 'a\')",           // a literal string has no escapes
      R"("a.b" = '[{')",       // a quoted key's dots and a literal's brackets are text
      R"(s = 1 # "unclosed)",  // a quote in a comment opens nothing
      "s = \"\"\"\na\"\"\n\"\"\"\"",  // a multi-line string over lines, quotes in it and after
      "s = '''\na''\n'''''",          //
      "s = \"a\\",                    // one-line strings left open end with their line, where
      "s = 'a",                       // the TOML reader stops with an error: they do not
      "s = \"a",                      // swallow the lines after them
  };
  for (const char* s : strings) {
    CAPTURE(s);
    CHECK_THROWS_WITH_AS((void)clothlab::parse_scene(std::string(s) + "\n" + key, "s.toml"),
                         doctest::Contains("the parts of a dotted key nest more than 64 deep"),
                         clothlab::SceneError);
  }
}

TEST_CASE("scene error: no string the TOML reader accepts hides a deep key from the check") {
  // Random runs of quotes (one or three), backslashes, comments and newlines, then a key of 100
  // parts. Whatever they are, either the check refuses the key, or the TOML reader refuses them:
  // had the reader accepted them and the check not seen the key, the scene would be refused for
  // its table [a] instead (and a key of 40,000 parts would have crashed the reader). The check
  // before this one missed the key in 232 of these 40,000 inputs.
  std::string key;
  for (int k = 0; k < 99; ++k)
    key += "a.";
  key += "a = 1\n";
  const std::vector<std::string> pieces = {"\"", "'", "\"\"\"", "\'\'\'", "\\",
                                           "\n", "#", "a",      " "};
  std::mt19937 random(40);
  std::uniform_int_distribution<size_t> piece(0, pieces.size() - 1), length(1, 8);
  int checked = 0, refused_by_reader = 0;
  for (int n = 0; n < 40000; ++n) {
    std::string text = "s = ";
    for (size_t k = length(random); k > 0; --k)
      text += pieces[piece(random)];
    text += "\n" + key;
    try {
      (void)clothlab::parse_scene(text, "random.toml");
      FAIL("a scene of no table loaded: " << text);
    } catch (const clothlab::SceneError& e) {
      const std::string what = e.what();
      const bool nesting =
          what.find("the parts of a dotted key nest more than 64") != std::string::npos;
      const bool invalid = what.find("invalid TOML") != std::string::npos;
      if (!nesting && !invalid) FAIL_CHECK("the key went unseen in:\n" << text << "\n" << what);
      checked += nesting;
      refused_by_reader += invalid;
    }
  }
  // Both kinds of input occur: the test is not vacuous.
  CHECK(checked > 1000);
  CHECK(refused_by_reader > 500);
}

TEST_CASE("scene error: a particle on two long pin paths is found without comparing every pair") {
  // Two paths of 200,000 pins each, the second ending on a particle of the first: comparing each
  // pin with every earlier one made 4e10 comparisons before the error; one mark each is instant.
  std::string first = "[", second = "[";
  for (int k = 0; k < 200000; ++k) {
    first += std::to_string(k) + ", ";
    second += std::to_string(200000 + k) + ", ";
  }
  const std::string text =
      "[cloth]\nrows = 400\ncols = 1000\nspacing = 0.01\nmass = 1\n"
      "[[cloth.pin_path]]\npins = " +
      first + "]\ntimes = [0]\noffsets = [[0, 0, 0]]\n" + "[[cloth.pin_path]]\npins = " + second +
      "7]\ntimes = [0]\noffsets = [[0, 0, 0]]\n"
      "[integrator]\ndt = 0.01\nduration = 1\n";
  CHECK_THROWS_WITH_AS((void)clothlab::parse_scene(text, "paths.toml"),
                       "paths.toml:11:8: particle 7 of [[cloth.pin_path]] #2 is on an earlier path "
                       "already; expected each particle on one path at most",
                       clothlab::SceneError);
}

TEST_CASE(
    "scene error: a NUL in a string, a key or a table's name is shown as ^@, the message whole") {
  // what() hands the message on as a C string: a raw NUL ("\u0000" in TOML) ended it there, and
  // the rest, what was expected, was lost.
  const std::string particle = "[[particle]]\nposition = [0, 1, 0]\nmass = 1\n";
  const std::string integrator = "[integrator]\ndt = 0.01\nduration = 0.1\n";
  CHECK_THROWS_WITH_AS(
      (void)clothlab::parse_scene(particle + integrator + "method = \"symplectic-euler\\u0000\"\n",
                                  "nul.toml"),
      doctest::Contains("nul.toml:7:10: unknown method 'symplectic-euler^@' in [integrator]; "
                        "expected one of: "),
      clothlab::SceneError);
  CHECK_THROWS_WITH_AS(
      (void)clothlab::parse_scene(particle + integrator + "\"k\\u0000x\" = 1\n", "nul.toml"),
      doctest::Contains("'k^@x' in [integrator]; expected "), clothlab::SceneError);
  CHECK_THROWS_WITH_AS(
      (void)clothlab::parse_scene(particle + integrator + "[\"t\\u0000x\"]\na = 1\n", "nul.toml"),
      doctest::Contains("nul.toml:7:2: unknown table [t^@x]; expected one of: "),
      clothlab::SceneError);
  try {
    (void)clothlab::parse_scene(particle + "[\"\\u0000\"]\n" + integrator, "nul.toml");
    FAIL("a table named NUL loaded");
  } catch (const clothlab::SceneError& e) {
    CHECK(e.message().find('\0') == std::string::npos);
    CHECK(std::string(e.what()).ends_with(e.message()));
  }
}

TEST_CASE("scene error: a directory, a device and a huge file are refused before reading") {
  const fs::path dir = test::scratch_path("scene-inputs");
  fs::create_directories(dir);
  CHECK_THROWS_WITH_AS(
      (void)clothlab::load_scene_file(dir),
      (dir.string() + ":1:1: is a directory; expected a scene file (.toml)").c_str(),
      clothlab::SceneError);
  // Once read forever.
  CHECK_THROWS_WITH_AS((void)clothlab::load_scene_file("/dev/zero"),
                       "/dev/zero:1:1: is not a regular file (a device, pipe or socket); expected "
                       "a scene file (.toml)",
                       clothlab::SceneError);
  const fs::path huge = dir / "huge.toml";
  {
    std::ofstream out(huge);
    out << "title = \"huge\"\n";
  }
  fs::resize_file(huge, clothlab::kMaxSceneBytes + 1);  // sparse: costs no disk
  CHECK_THROWS_WITH_AS((void)clothlab::load_scene_file(huge),
                       doctest::Contains(":1:1: is larger than 16 MiB; expected a scene file"),
                       clothlab::SceneError);
  fs::remove_all(dir);
}
