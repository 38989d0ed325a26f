// Running a scene: the files it writes, and what is left when the guard stops it.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "clothlab/run.hpp"
#include "clothlab/scene.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<std::string> read_lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

std::vector<double> numbers(const std::string& csv_row) {
  std::vector<double> values;
  std::istringstream in(csv_row);
  for (std::string cell; std::getline(in, cell, ',');)
    values.push_back(std::stod(cell));
  return values;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("clothlab-test-" + name);
  fs::remove_all(dir);
  return dir;
}

}  // namespace

TEST_CASE("run: a scene writes one energy row and one position row per particle per frame") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0, 10, 0]
mass = 1
[[particle]]
position = [1, 10, 0]
velocity = [0, 0, 1]
mass = 2
[gravity]
[integrator]
dt = 0.01
duration = 1
[output]
fps = 10
)",
                                                "two.toml");
  const fs::path dir = fresh_dir("frames");
  const clothlab::RunReport report = clothlab::run_scene(scene, dir);
  CHECK(report.steps == 100);
  CHECK(report.frames == 11);  // t = 0, 0.1, ..., 1.0: a frame every 10 steps, and frame 0
  const auto energy = read_lines(dir / "energy.csv");
  const auto positions = read_lines(dir / "positions.csv");
  REQUIRE(energy.size() == 1 + 11);
  CHECK(energy[0] == "frame,t,kinetic,potential,total,px,py,pz");
  CHECK(positions.size() == 1 + 11 * 2);
  CHECK(positions[0] == "frame,t,particle,x,y,z");
  CHECK(positions[1].rfind("0,0,0,0,10,0", 0) == 0);
  // The last frame, t = 1 s: p_y = sum m (-g t) = 3 kg * -9.8 m/s = -29.4 kg m/s and
  // p_z = 2 kg * 1 m/s = 2 kg m/s (nothing acts along z).
  const std::vector<double> last = numbers(energy.back());
  REQUIRE(last.size() == 8);
  CHECK(last[0] == 10);
  CHECK(last[1] == doctest::Approx(1.0));
  CHECK(last[6] == doctest::Approx(-29.4));
  CHECK(last[7] == doctest::Approx(2.0));
}

TEST_CASE("run: when the guard stops a run the files hold every frame before it") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0, 0, 0]
mass = 1
[gravity]
[integrator]
dt = 0.01
duration = 10
[output]
fps = 100
[guard]
max_position = 1.0
)",
                                                "falls-out.toml");
  // Free fall passes 1 m after sqrt(2 / 9.8) = 0.45 s, at about step 45.
  const fs::path dir = fresh_dir("guard");
  long failed_step = -1;
  try {
    clothlab::run_scene(scene, dir);
  } catch (const clothlab::SimulationError& e) {
    failed_step = e.step();
  }
  REQUIRE(failed_step > 40);
  REQUIRE(failed_step < 50);
  const auto energy = read_lines(dir / "energy.csv");
  // One frame per step (fps = 1 / dt): frames 0 .. failed_step - 1, each complete.
  CHECK(energy.size() == static_cast<size_t>(1 + failed_step));
  for (const std::string& line : energy)
    CHECK(std::count(line.begin(), line.end(), ',') == 7);
  CHECK(energy.back().find("nan") == std::string::npos);
}
