// Scenes that run but are likely mistakes: each gets a warning of the form
//   FILE:LINE:COL: what is odd; what to do
// in Scene::warnings, and still loads. A scene without such a mistake gets none.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "scene/scene_warnings.hpp"

namespace fs = std::filesystem;
using clothlab::Index;
using clothlab::Vec3;

namespace {

// 100 steps of 0.01 s: a frame rate of up to 100 frames/s fits.
const std::string kIntegrator = "[integrator]\ndt = 0.01\nduration = 1.0\n";

// One [[particle]] of 1 kg at `position`, three lines; its position's value is at column 12.
std::string particle_at(const std::string& position) {
  return "[[particle]]\nposition = " + position + "\nmass = 1\n";
}

// What the [gravitation] warning says a run costs, a step costing `per_step` [s].
std::string run_cost(double per_step, long steps) {
  return "about " + clothlab::human_duration(per_step) + " a step and " +
         clothlab::human_duration(per_step * static_cast<double>(steps)) + " for the run's " +
         std::to_string(steps) + " steps";
}

// The scene's one warning, as FILE:LINE:COL: message.
std::string only_warning(const clothlab::Scene& scene) {
  REQUIRE(scene.warnings.size() == 1);
  return scene.warnings[0].text();
}

}  // namespace

TEST_CASE("scene warning: none for a scene without mistakes") {
  // Everything the warnings look at, just inside the line: distinct pins, a rest length, fps equal
  // to 1/dt, [gravitation] on exactly kAllPairsWarnAbove particles, particles apart.
  const std::string text =
      particle_at("[-1, 0, 0]") + particle_at("[-2, 0, 0]") +
      "[[spring]]\ni = 0\nj = 1\nks = 10\nl0 = 0.5\n"
      "[cloth]\nrows = 2\ncols = 999\nspacing = 0.1\nmass = 1\npins = [0, 5, 48]\n"
      "[gravitation]\n" +
      kIntegrator + "[output]\nfps = 100\n";
  const clothlab::Scene scene = clothlab::parse_scene(text, "clean.toml");
  CHECK(scene.world.particles.size() == clothlab::kAllPairsWarnAbove);
  CHECK(scene.warnings.empty());

  // Nor does any scene a lesson ships, unless it says which warnings it means to raise (a scene
  // that shows a mistake's effect), each in a comment line "# warns on purpose: TEXT": then it
  // raises exactly that many warnings, and each TEXT is in one of them.
  const fs::path lessons = fs::path(CLOTHLAB_TEST_SCENES) / ".." / ".." / "lessons";
  int scenes = 0, on_purpose = 0;
  for (const auto& entry : fs::recursive_directory_iterator(lessons)) {
    if (entry.path().extension() != ".toml") continue;
    ++scenes;
    const clothlab::Scene lesson = clothlab::load_scene_file(entry.path());
    std::ifstream file(entry.path());
    std::string line;
    std::vector<std::string> meant;
    const std::string marker = "# warns on purpose: ";
    while (std::getline(file, line))
      if (line.rfind(marker, 0) == 0) meant.push_back(line.substr(marker.size()));
    if (meant.empty()) {
      for (const clothlab::SceneWarning& w : lesson.warnings)
        FAIL_CHECK("a lesson scene warns: " << w.text());
      continue;
    }
    ++on_purpose;
    INFO(entry.path().string() << " says it warns on purpose " << meant.size() << " times");
    REQUIRE(lesson.warnings.size() == meant.size());
    for (const std::string& one : meant) {
      INFO("the warning meant: " << one);
      CHECK(std::any_of(lesson.warnings.begin(), lesson.warnings.end(),
                        [&](const clothlab::SceneWarning& w) {
                          return w.text().find(one) != std::string::npos;
                        }));
    }
  }
  CHECK(scenes > 10);
  CHECK(on_purpose <= 5);  // a handful at most: a lesson's scenes are meant to be clean
}

TEST_CASE("scene warning: a particle pinned twice") {
  const std::string cloth =
      "[cloth]\nrows = 3\ncols = 3\nspacing = 0.1\nmass = 1\npins = [0, 5, 0, 5]\n" + kIntegrator;
  // The first repeat, pins[2] (line 6, column 15), and how many there are.
  CHECK(only_warning(clothlab::parse_scene(cloth, "pins.toml")) ==
        "pins.toml:6:15: 'pins[2]' in [cloth] pins particle 0 again, as 'pins[0]' does (2 repeats "
        "in all); a particle is pinned once, so a repeat does nothing: remove it, or write the "
        "index you meant");

  const std::string rope =
      "[rope]\nstart = [0, 0, 0]\nend = [1, 0, 0]\nparticles = 5\nmass = 1\npins = [4, 4]\n" +
      kIntegrator;
  CHECK(only_warning(clothlab::parse_scene(rope, "rope.toml")) ==
        "rope.toml:6:12: 'pins[1]' in [rope] pins particle 4 again, as 'pins[0]' does (1 repeat "
        "in all); a particle is pinned once, so a repeat does nothing: remove it, or write the "
        "index you meant");

  // A fixed pin that a moving path also holds: the path wins.
  const std::string path =
      "[solid]\nparticles = [2, 2, 2]\nsize = [1, 1, 1]\nmass = 1\npins = [1, 2]\n"
      "[[solid.pin_path]]\npins = [3, 2]\ntimes = [0, 1]\noffsets = [[0, 0, 0], [0, 1, 0]]\n" +
      kIntegrator;
  const std::string text = only_warning(clothlab::parse_scene(path, "path.toml"));
  CHECK(
      text.starts_with("path.toml:7:12: particle 2 is pinned by the body's 'pins' and moved by "
                       "[[solid.pin_path]] #1 (1 such particle in all)"));
  CHECK(text.find("remove it from one of the two") != std::string::npos);
}

TEST_CASE("scene warning: a spring of rest length zero") {
  const std::string particles = particle_at("[0, 0, 0]") + particle_at("[1, 0, 0]");
  // Given as l0 = 0 (line 11, column 6).
  const std::string given = particles + "[[spring]]\ni = 0\nj = 1\nks = 10\nl0 = 0\n" + kIntegrator;
  const std::string text = only_warning(clothlab::parse_scene(given, "l0.toml"));
  CHECK(
      text.starts_with("l0.toml:11:6: [[spring]] #1 has l0 = 0: with no rest length its strain "
                       "(l - l0) / l0 is undefined and it pulls its ends together"));
  CHECK(text.find("give l0 > 0 [m]") != std::string::npos);

  // By default, the distance at the start: 0 when the two particles coincide. The warning is at
  // the [[spring]] table (line 7), which has no l0; the particles are warned about too.
  const std::string coincident = particle_at("[0, 0, 0]") + particle_at("[0, 0, 0]") +
                                 "[[spring]]\ni = 1\nj = 0\nks = 10\n" + kIntegrator;
  const clothlab::Scene scene = clothlab::parse_scene(coincident, "same.toml");
  REQUIRE(scene.warnings.size() == 2);
  CHECK(scene.warnings[0].text().starts_with(
      "same.toml:7:1: [[spring]] #1 joins particles 1 and 0, which start at the same position, "
      "so its rest length (the distance at the start) is 0: with no rest length its strain "
      "(l - l0) / l0 is undefined and it pulls its ends together"));
  CHECK(scene.warnings[1].text().starts_with("same.toml:5:12: particle 1 ([[particle]] #2)"));
}

TEST_CASE("scene warning: a body's springs of rest length zero") {
  // A spacing of 1e-300 m at x = 1 m: 1 + 1e-300 is 1, so the 2 x 2 cloth's four particles start
  // at one point, and its 4 structural and 2 shear springs have rest length 0.
  const std::string text =
      "[cloth]\nrows = 2\ncols = 2\nspacing = 1e-300\norigin = [1, 1, 1]\n"
      "mass = 1\n[springs]\nks = 10\n" +
      kIntegrator;
  const clothlab::Scene scene = clothlab::parse_scene(text, "tiny.toml");
  REQUIRE(scene.warnings.size() == 2);
  CHECK(scene.warnings[0].text().starts_with(
      "tiny.toml:8:6: [springs] makes 6 springs of rest length 0, the first from particle 0 to 1: "
      "their ends start at the same position, so with no rest length their strain (l - l0) / l0 "
      "is undefined"));
  CHECK(scene.warnings[1].text().starts_with(
      "tiny.toml:5:10: particle 1 (the cloth's particle 1 (row 0, column 1)) starts at (1, 1, 1) "
      "m, exactly where particle 0 (the cloth's particle 0 (row 0, column 0)) does (3 particles"));
}

TEST_CASE("scene warning: particles that start at the same position") {
  // #3 and #5 start where #1 does, #4 where #2 does: three in all; the first pair is (0, 2), at
  // #3's position (line 8, column 12).
  std::string text;
  for (const char* x : {"[0, 0, 0]", "[1, 0, 0]", "[0, 0, 0]", "[1, 0, 0]", "[0, 0, 0]"})
    text += particle_at(x);
  text += kIntegrator;
  const std::string warning = only_warning(clothlab::parse_scene(text, "same.toml"));
  CHECK(
      warning.starts_with("same.toml:8:12: particle 2 ([[particle]] #3) starts at (0, 0, 0) m, "
                          "exactly where particle 0 ([[particle]] #1) does (3 particles in all "
                          "start where a lower-numbered one does)"));
  CHECK(warning.find("give each particle its own position") != std::string::npos);

  // A [[particle]] on a cloth's first corner: the warning names the cloth's key that places it.
  const std::string on_cloth = particle_at("[0, 0, 0]") +
                               "[cloth]\nrows = 400\ncols = 500\nspacing = 0.01\nmass = 1\n" +
                               kIntegrator;
  CHECK(only_warning(clothlab::parse_scene(on_cloth, "cloth.toml"))
            .starts_with("cloth.toml:7:11: particle 1 (the cloth's particle 0 (row 0, column 0)) "
                         "starts at (0, 0, 0) m, exactly where particle 0 ([[particle]] #1) does "
                         "(1 particle in all"));
}

TEST_CASE("scene warning: coincident particles are found by sorting, not by comparing all pairs") {
  // 200,000 particles: all pairs would be 2e10 comparisons, many seconds; sorting takes a blink.
  constexpr Index n = 200000;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  clothlab::Matrix3X x(3, n);
  for (Index i = 0; i < n; ++i)
    x.col(i) = Vec3(coordinate(random), coordinate(random), coordinate(random));
  const clothlab::CoincidentParticles none = clothlab::find_coincident_particles(x);
  CHECK(none.count == 0);
  CHECK(none.first == -1);
  // Two repeats: the pair reported is the one whose later particle comes first.
  x.col(190000) = x.col(150000);
  x.col(170000) = x.col(3);
  const clothlab::CoincidentParticles two = clothlab::find_coincident_particles(x);
  CHECK(two.count == 2);
  CHECK(two.first == 3);
  CHECK(two.second == 170000);
  // -0.0 is where 0.0 is.
  clothlab::Matrix3X signed_zero(3, 2);
  signed_zero.col(0) = Vec3(0.0, -0.0, 1.0);
  signed_zero.col(1) = Vec3(-0.0, 0.0, 1.0);
  CHECK(clothlab::find_coincident_particles(signed_zero).count == 1);
}

TEST_CASE("scene warning: fps above the step rate") {
  // dt = 0.01 s is 100 steps/s; fps = 1000 asks for ten frames a step and gets one.
  const std::string fps_1000 = particle_at("[0, 0, 0]") + kIntegrator + "[output]\nfps = 1000\n";
  CHECK(only_warning(clothlab::parse_scene(fps_1000, "fps.toml")) ==
        "fps.toml:8:7: fps = 1000 frames/s is more than the step rate 1/dt = 100 steps/s: a frame "
        "is written every step, so the run writes 100 frames per simulated second, not 1000; take "
        "fps <= 100 (or a smaller dt)");
  const std::string fps_huge =
      particle_at("[0, 0, 0]") + kIntegrator + "[output]\nvelocities = true\nfps = 1e300\n";
  CHECK(only_warning(clothlab::parse_scene(fps_huge, "huge.toml"))
            .starts_with("huge.toml:9:7: fps = 1e+300 frames/s is more than the step rate 1/dt = "
                         "100 steps/s: a frame is written every step"));
}

TEST_CASE("scene warning: gravitation on a 1000 x 1000 cloth says how long it would take") {
  // 10^6 particles are n(n-1)/2 = 4.999995e11 pairs, swept once a step for the forces, every 32
  // steps for the guard's energy and every 3 steps for energy.csv (30 fps at dt = 0.01 s): at
  // 4.3 ns a pair, about 49 min a step and 3.4 days for 100 steps.
  const std::string text =
      "[cloth]\nrows = 1000\ncols = 1000\nspacing = 0.001\nmass = 1\n[gravitation]\n" + kIntegrator;
  const std::string warning = only_warning(clothlab::parse_scene(text, "big.toml"));
  CHECK(
      warning.starts_with("big.toml:6:1: [gravitation] sums over all n(n-1)/2 = 5e+11 pairs of "
                          "the scene's 1000000 particles once a step with symplectic-euler"));
  const double per_step =
      499999500000.0 * (1.0 + 1.0 / 32.0 + 1.0 / 3.0) * clothlab::kGravitationSecondsPerPair;
  CHECK(per_step > 600.0);  // minutes a step on any machine of today
  CHECK(warning.find(run_cost(per_step, 100)) != std::string::npos);
  CHECK(warning.find("use it on at most 2000 particles, or leave [gravitation] out") !=
        std::string::npos);
  // One particle more than the line warns too.
  CHECK(clothlab::parse_scene("[rope]\nstart = [0, 0, 0]\nend = [1, 0, 0]\nparticles = 2001\n"
                              "mass = 1\n[gravitation]\nG = 1\n" +
                                  kIntegrator,
                              "rope.toml")
            .warnings.size() == 1);
}

TEST_CASE("scene warning: durations for people") {
  CHECK(clothlab::human_duration(0.25) == "0.25 s");
  CHECK(clothlab::human_duration(90.0) == "1.5 min");
  CHECK(clothlab::human_duration(5400.0) == "1.5 h");
  CHECK(clothlab::human_duration(3.0 * 86400.0) == "3 days");
  CHECK(clothlab::human_duration(2.0 * 365.25 * 86400.0) == "2 years");
}

TEST_CASE("scene warning: particles that start inside the ground, a plane or the sphere") {
  // Once moved out without a word at the first contact: a particle 9 m under the ground jumped
  // 9 m, and the scene's energy rose tenfold. Pinned particles are never pushed: no warning.
  const std::string pinned = "[[particle]]\nposition = [5, -3, 0]\nmass = 1\npinned = true\n";
  const std::string below = particle_at("[0, 1, 0]") + particle_at("[0, -9, 0]") +
                            particle_at("[1, -2, 0]") + pinned + kIntegrator;
  CHECK(only_warning(clothlab::parse_scene(below + "[ground]\n", "ground.toml")) ==
        "ground.toml:5:12: particle 1 ([[particle]] #2) starts at (0, -9, 0) m, 9 m inside the "
        "ground [ground] (y = 0 m) (2 free particles in all start inside it, the deepest 9 m); "
        "its first contact pushes them out to its surface at once, a jump that gives them "
        "energy no force put in: start them outside it, or pin them");
  CHECK(clothlab::parse_scene(below + "[ground]\ny = -20\n", "deep.toml").warnings.empty());

  const std::string plane = "[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 0, 2]\n";
  const std::string behind =
      particle_at("[0, 0, 1]") + particle_at("[3, 4, -0.5]") + kIntegrator + plane;
  CHECK(only_warning(clothlab::parse_scene(behind, "plane.toml"))
            .starts_with("plane.toml:5:12: particle 1 ([[particle]] #2) starts at (3, 4, -0.5) "
                         "m, 0.5 m inside the [[plane]] through (0, 0, 0) m facing (0, 0, 1) (1 "
                         "free particle in all start inside it, the deepest 0.5 m)"));

  const std::string ball = "[sphere]\ncentre = [1, 1, 1]\nradius = 2\n";
  CHECK(only_warning(clothlab::parse_scene(
                         particle_at("[1, 1, 4]") + particle_at("[1, 1, 1.5]") + kIntegrator + ball,
                         "ball.toml"))
            .starts_with("ball.toml:5:12: particle 1 ([[particle]] #2) starts at (1, 1, 1.5) m, "
                         "1.5 m inside the [sphere] of radius 2 m about (1, 1, 1) m (1 free "
                         "particle in all start inside it, the deepest 1.5 m)"));
  // On the surface is not inside.
  CHECK(clothlab::parse_scene(particle_at("[1, 1, 3]") + kIntegrator + ball, "on.toml")
            .warnings.empty());
}
