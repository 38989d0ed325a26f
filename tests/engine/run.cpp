// Running a scene: the files it writes, and what is left when the guard stops it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "clothlab/after_step/tearing.hpp"
#include "clothlab/core/kernel_answer.hpp"
#include "io/run.hpp"
#include "scene/scene.hpp"
#include "scratch_dir.hpp"

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

// One particle falling from the origin, a frame every step of 0.01 s, until the guard stops it
// when it has fallen 1 m.
clothlab::Scene falls_out() {
  return clothlab::parse_scene(R"(
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
  const fs::path dir = test::scratch_path("frames");
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
  clothlab::Scene scene = falls_out();
  // Free fall passes 1 m after sqrt(2 / 9.8) = 0.45 s, at about step 45.
  const fs::path dir = test::scratch_path("guard");
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

TEST_CASE("run: OBJ and VTK frames carry the mesh, normals, velocities and strains") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 3
cols = 4
spacing = 0.1
mass = 0.12
pins = "top-corners"
[springs]
ks = 50
[gravity]
[integrator]
dt = 0.001
duration = 0.01
[output]
fps = 500
)",
                                                "small.toml");
  const fs::path dir = test::scratch_path("meshes");
  clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
  outputs.obj = outputs.vtk = true;
  const clothlab::RunReport report = clothlab::run_scene(scene, outputs);
  REQUIRE(report.frames == 6);  // t = 0, 0.002, ..., 0.01
  // OBJ: 12 vertices, 12 normals, 2 triangles per cell of the 2 x 3 cells, counted from 1.
  const auto obj = read_lines(dir / "frames" / "frame_0001.obj");
  const auto count = [&](const std::vector<std::string>& lines, const std::string& prefix) {
    return std::count_if(lines.begin(), lines.end(),
                         [&](const std::string& l) { return l.rfind(prefix, 0) == 0; });
  };
  CHECK(count(obj, "v ") == 12);
  CHECK(count(obj, "vn ") == 12);
  CHECK(count(obj, "f ") == 12);
  CHECK(std::find(obj.begin(), obj.end(), "f 1//1 5//5 2//2") != obj.end());
  // A vertical cloth in the x-y plane: every normal is +-z.
  CHECK(std::find(obj.begin(), obj.end(), "vn 0 0 1") != obj.end());
  CHECK(fs::exists(dir / "frames" / "frame_0006.obj"));
  // VTK: the springs (structural 3*3 + 2*4 = 17, shear 2*2*3 = 12) as lines, with strain 0 at
  // rest in the first frame, and a velocity per point.
  const auto vtk = read_lines(dir / "frames" / "frame_0001.vtk");
  CHECK(std::find(vtk.begin(), vtk.end(), "LINES 29 87") != vtk.end());
  CHECK(std::find(vtk.begin(), vtk.end(), "POLYGONS 12 48") != vtk.end());
  CHECK(std::find(vtk.begin(), vtk.end(), "CELL_DATA 41") != vtk.end());
  CHECK(std::find(vtk.begin(), vtk.end(), "VECTORS velocity double") != vtk.end());
  const auto strain = std::find(vtk.begin(), vtk.end(), "LOOKUP_TABLE default");
  REQUIRE(strain != vtk.end());
  for (int k = 1; k <= 29; ++k)
    CHECK(std::abs(std::stod(*(strain + k))) < 1e-12);
  // The series index lists the six files with their times.
  const auto series = read_lines(dir / "frames" / "frames.vtk.series");
  CHECK(count(series, "    {\"name\": \"frame_") == 6);
  CHECK(fs::exists(dir / "view.html"));
}

TEST_CASE("run: the viewer page embeds every frame and names the scene") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
title = "a </script> or <!--<script> in a title must not end the page's script & data"
[[particle]]
position = [0, 0, 0]
velocity = [1, 0, 0]
mass = 1
[integrator]
dt = 0.1
duration = 1
[output]
fps = 10
)",
                                                "page.toml");
  const fs::path dir = test::scratch_path("page");
  clothlab::run_scene(scene, dir);
  std::ifstream in(dir / "view.html");
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(page.find("/*CLOTHLAB_DATA*/") == std::string::npos);  // the marker was replaced
  CHECK(page.find("\"particles\":1,") != std::string::npos);
  CHECK(page.find("\"times\":[0.0,0.1,") != std::string::npos);
  CHECK(page.find("a \\u003c/script\\u003e or \\u003c!--\\u003cscript\\u003e in a title") !=
        std::string::npos);
  CHECK(page.find("</script> or") == std::string::npos);
  CHECK(page.find("<!--<script>") == std::string::npos);
  // The page's data, up to the end of its <script> element, is JSON, and the title reads back
  // as written.
  const std::string open = "<script id=\"clothlab-data\" type=\"application/json\">";
  const size_t begin = page.find(open);
  REQUIRE(begin != std::string::npos);
  const size_t from = begin + open.size();
  const auto data = nlohmann::json::parse(page.substr(from, page.find("</script>", from) - from));
  CHECK(data["title"] ==
        "a </script> or <!--<script> in a title must not end the page's script & data");
  CHECK(data["particles"] == 1);
  CHECK(data["frames"].size() == data["times"].size());
}

TEST_CASE(
    "run: velocities.csv and springs.csv when asked for - a hanging mass's spring pulls m g") {
  // A 0.5 kg mass on a spring (ks = 100 N/m, l0 = 1 m) from a pin, at rest where the spring
  // holds its weight: stretched by m g / ks = 0.049 m, a strain of 0.049 and a tension of
  // m g = 4.9 N, frame after frame.
  clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0, 0, 0]
mass = 1
pinned = true
[[particle]]
position = [0, -1.049, 0]
mass = 0.5
[[spring]]
i = 0
j = 1
ks = 100
kd = 0.5
l0 = 1
[gravity]
g = [0, -9.8, 0]
[integrator]
dt = 0.001
duration = 0.5
[output]
fps = 10
velocities = true
springs = true
)",
                                                "hanging.toml");
  const fs::path dir = test::scratch_path("physicist");
  const clothlab::RunReport report = clothlab::run_scene(scene, dir);
  REQUIRE(report.frames == 6);
  CHECK(std::count(report.files.begin(), report.files.end(), dir / "springs.csv") == 1);
  const auto positions = read_lines(dir / "positions.csv");
  const auto velocities = read_lines(dir / "velocities.csv");
  const auto springs = read_lines(dir / "springs.csv");
  // The same rows as positions.csv: frame, t and particle, then the velocity.
  REQUIRE(velocities.size() == positions.size());
  CHECK(velocities[0] == "frame,t,particle,vx,vy,vz");
  for (size_t k = 1; k < velocities.size(); ++k) {
    const std::vector<double> v = numbers(velocities[k]), x = numbers(positions[k]);
    REQUIRE(v.size() == 6);
    CHECK(v[0] == x[0]);
    CHECK(v[1] == x[1]);
    CHECK(v[2] == x[2]);
    CHECK(std::abs(v[4]) < 1e-9);  // at rest
  }
  // The last velocity row is the world's last velocity, to the bit ({:.17g}).
  CHECK(numbers(velocities.back())[4] == scene.world.particles.v(1, 1));
  // One row per spring per frame: frame, t, effect, spring, i, j, strain, tension.
  REQUIRE(springs.size() == 1 + 6);
  CHECK(springs[0] == "frame,t,effect,spring,i,j,strain,tension");
  for (size_t k = 1; k < springs.size(); ++k) {
    CAPTURE(springs[k]);
    CHECK(springs[k].rfind(std::to_string(k - 1) + ",", 0) == 0);
    const std::string ends = ",springs,0,0,1,";  // effect, spring 0, from particle 0 to 1
    const size_t at = springs[k].find(ends);
    REQUIRE(at != std::string::npos);
    const std::string numeric = springs[k].substr(at + ends.size());
    const std::vector<double> row = numbers(numeric);  // strain, tension
    REQUIRE(row.size() == 2);
    CHECK(row[0] == doctest::Approx(0.049).epsilon(1e-9));
    CHECK(row[1] == doctest::Approx(0.5 * 9.8).epsilon(1e-9));
  }
  // Without [output] velocities or springs, neither file.
  clothlab::Scene plain = clothlab::parse_scene(R"(
[[particle]]
position = [0, 0, 0]
mass = 1
[integrator]
dt = 0.1
duration = 0.2
)",
                                                "plain.toml");
  const fs::path plain_dir = test::scratch_path("plain");
  clothlab::run_scene(plain, plain_dir);
  CHECK(!fs::exists(plain_dir / "velocities.csv"));
  CHECK(!fs::exists(plain_dir / "springs.csv"));
}

namespace {

// A post-step effect whose exercise answer is out of range at step 3.
class BadAnswerAtStep3 final : public clothlab::PostStepEffect {
 public:
  std::string_view name() const override { return "bad answer"; }
  void apply(clothlab::World& world, const clothlab::StepTime& /*time*/) override {
    if (world.steps + 1 == 3) clothlab::check_tears({5}, 2);
  }
};

}  // namespace

TEST_CASE("run: a run stops at the step of a bad answer, with the frames before it") {
  // An exercise's answer the engine cannot use (clothlab/core/kernel_answer.hpp), at step 3.
  clothlab::Scene scene = falls_out();
  scene.world.post_step_effects.push_back(std::make_unique<BadAnswerAtStep3>());
  const fs::path dir = test::scratch_path("kernel-answer");
  const clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
  long step = -1;
  std::string message;
  try {
    clothlab::run_scene(scene, outputs);
  } catch (const clothlab::SimulationError& e) {
    step = e.step();
    message = e.what();
  }
  CHECK(step == 3);
  CHECK(message.find("the run stopped in step 3 (from t = 0.02 s): select_tears returned the "
                     "position 5, but there are 2 springs") != std::string::npos);
  CHECK(message.find("(exercise ex06.2)") != std::string::npos);
  // A header and frames 0, 1 and 2 (the start and the two steps before); the page says why it
  // ends.
  CHECK(read_lines(dir / "energy.csv").size() == 1 + 3);
  std::ifstream page(dir / "view.html");
  const std::string html{std::istreambuf_iterator<char>(page), {}};
  CHECK(html.find("select_tears returned the position 5") != std::string::npos);
  fs::remove_all(dir);
}
