// Bad scenes: one file per mistake under tests/scenes/bad/, each starting with the line
//   # expect: LINE:COL: message
// The test loads the file and checks the error is exactly FILE:LINE:COL: message.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "clothlab/scene.hpp"

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

TEST_CASE("scene error: every bad scene file has a test case") {
  // A file added to tests/scenes/bad/ without a test above would never be checked.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(CLOTHLAB_TEST_SCENES) / "bad")) {
    if (entry.path().extension() == ".toml") ++files;
  }
  CHECK(files == 34);
}

TEST_CASE("scene error: a missing file") {
  CHECK_THROWS_WITH_AS((void)clothlab::load_scene_file("no/such/scene.toml"),
                       "no/such/scene.toml:1:1: cannot open the file; expected a readable scene",
                       clothlab::SceneError);
}
