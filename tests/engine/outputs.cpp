// Outputs that lose nothing: whole frames whatever stops a run, a folder that is the run's own,
// and no inf or NaN in any file.
#include <doctest/doctest.h>
#include <sys/resource.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "clothlab/core/guard.hpp"
#include "io/files.hpp"
#include "io/run.hpp"
#include "io/run_folder.hpp"
#include "scene/scene.hpp"

namespace fs = std::filesystem;
using clothlab::OutputError;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("clothlab-outputs-" + name);
  fs::remove_all(dir);
  return dir;
}

std::string read_all(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
}

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A cloth of 20 x 20 falling for 0.2 s, 21 frames.
constexpr const char* kCloth = R"(
title = "outputs test"
[cloth]
rows = 20
cols = 20
spacing = 0.05
mass = 0.4
pins = "top-corners"
[springs]
ks = 100
kd = 0.01
[gravity]
[integrator]
dt = 0.001
duration = 0.2
[output]
fps = 100
)";

// Sets the file size limit (ulimit -f) for as long as it lives, with SIGXFSZ ignored so that a
// write past it fails with EFBIG instead of ending the test program.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
};

}  // namespace

TEST_CASE("outputs: a piece a full disk takes only part of is cut off again") {
  const fs::path dir = fresh_dir("append");
  fs::create_directories(dir);
  clothlab::AppendFile file(dir / "rows.csv");
  file.append("header\n");
  file.append(std::string(1000, 'a') + "\n");
  CHECK(file.size() == 1008);
  {
    // The next piece would end at 1008 + 5001 bytes; the limit lets 3000 of them in.
    FileSizeLimit limit(4000);
    CHECK_THROWS_WITH_AS(
        file.append(std::string(5000, 'b') + "\n"),
        doctest::Contains(
            ("writing " + (dir / "rows.csv").string() + " failed: File too large").c_str()),
        OutputError);
  }
  CHECK(file.size() == 1008);
  CHECK(fs::file_size(dir / "rows.csv") == 1008);
  // The file goes on after the last whole piece.
  file.append("c\n");
  CHECK(read_all(dir / "rows.csv") == "header\n" + std::string(1000, 'a') + "\nc\n");
}

TEST_CASE("outputs: a full device is an error that names the file and says why") {
  if (!fs::exists("/dev/full")) return;
  clothlab::AppendFile file("/dev/full");
  CHECK_THROWS_WITH_AS(file.append("frame\n"), "writing /dev/full failed: No space left on device",
                       OutputError);
}

TEST_CASE("outputs: a replaced file is the old one or the new one, never a part") {
  const fs::path dir = fresh_dir("replace");
  fs::create_directories(dir);
  write_text(dir / "page.html", "old page");
  {
    clothlab::ReplaceFile file(dir / "page.html");
    file.write("new pa");
    CHECK(read_all(dir / "page.html") == "old page");  // not yet
    // Destroyed without commit(): a write that stopped.
  }
  CHECK(read_all(dir / "page.html") == "old page");
  CHECK(names_in(dir) == std::vector<std::string>{"page.html"});  // no temporary file left
  clothlab::write_whole_file(dir / "page.html", "new page");
  CHECK(read_all(dir / "page.html") == "new page");
  CHECK(names_in(dir) == std::vector<std::string>{"page.html"});
  {
    FileSizeLimit limit(4);
    CHECK_THROWS_WITH_AS(clothlab::write_whole_file(dir / "page.html", "a longer new page"),
                         doctest::Contains("File too large; the file there is as it was"),
                         OutputError);
  }
  CHECK(read_all(dir / "page.html") == "new page");
  CHECK(names_in(dir) == std::vector<std::string>{"page.html"});
}

TEST_CASE("outputs: a run folder is refused if it is the user's, unless forced") {
  const fs::path dir = fresh_dir("foreign");
  fs::create_directories(dir / "data");
  write_text(dir / "positions.csv", "my own measurements\n");
  write_text(dir / "notes.txt", "keep me\n");
  CHECK_THROWS_WITH_AS(
      clothlab::RunFolder(dir, false),
      (dir.string() +
       " is not a clothlab output folder: it holds data/, notes.txt and positions.csv "
       "and no .clothlab-run marker, and a run would replace files there; choose "
       "another --out (a new or empty folder), or add --force to write into it "
       "anyway (files named as clothlab's outputs are replaced, others are left "
       "alone)")
          .c_str(),
      OutputError);
  CHECK(read_all(dir / "positions.csv") == "my own measurements\n");
  CHECK_FALSE(fs::exists(dir / ".clothlab-run"));
  {
    clothlab::RunFolder forced(dir, true);
    CHECK(fs::exists(dir / ".clothlab-run"));
    CHECK_FALSE(fs::exists(dir / "positions.csv"));  // an output name: replaced
  }
  CHECK(read_all(dir / "notes.txt") == "keep me\n");
  CHECK(fs::is_directory(dir / "data"));
  // Now it is clothlab's: the next run needs no --force.
  CHECK_NOTHROW(clothlab::RunFolder(dir, false));

  const fs::path file = dir / "notes.txt";
  CHECK_THROWS_WITH_AS(
      clothlab::RunFolder(file, true),
      ("cannot write into " + file.string() + ": it is a file, not a folder; choose another --out")
          .c_str(),
      OutputError);
}

TEST_CASE("outputs: two runs into one folder at once: the second is refused") {
  const fs::path dir = fresh_dir("lock");
  {
    clothlab::RunFolder first(dir, false);
    CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir, false),
                         doctest::Contains(("is writing into " + dir.string() +
                                            " now; wait for it to end, or choose another --out")
                                               .c_str()),
                         OutputError);
    CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir, true), doctest::Contains("is writing into"),
                         OutputError);
  }
  CHECK_NOTHROW(clothlab::RunFolder(dir, false));  // the lock went with the first run
}

TEST_CASE("outputs: --html over a file that is not a viewer page is refused unless forced") {
  const fs::path dir = fresh_dir("page");
  fs::create_directories(dir);
  write_text(dir / "report.html", "<html>my report</html>");
  CHECK_THROWS_WITH_AS(
      clothlab::check_page_target(dir / "report.html", false),
      ((dir / "report.html").string() +
       " exists and is not a clothlab viewer page; choose another --html, or add --force to "
       "replace it")
          .c_str(),
      OutputError);
  CHECK_NOTHROW(clothlab::check_page_target(dir / "report.html", true));
  CHECK_THROWS_WITH_AS(clothlab::check_page_target(dir / "missing" / "view.html", false),
                       doctest::Contains("No such file or directory"), OutputError);
  CHECK_THROWS_WITH_AS(clothlab::check_page_target(dir, false), doctest::Contains("a folder"),
                       OutputError);
  CHECK(names_in(dir) == std::vector<std::string>{"report.html"});

  // A bad --html is found before anything is written or run.
  clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
  clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir / "run");
  outputs.html = dir / "report.html";
  CHECK_THROWS_AS(clothlab::run_scene(scene, outputs), OutputError);
  CHECK(scene.world.t == 0.0);
  CHECK_FALSE(fs::exists(dir / "run"));
  CHECK(read_all(dir / "report.html") == "<html>my report</html>");
}

TEST_CASE("outputs: --out with a trailing slash or a ./ is the same folder as without") {
  for (const std::string spelling : {"/", "/./", "/.//"}) {
    const fs::path dir = fresh_dir("slash");
    clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
    const clothlab::RunReport report = clothlab::run_scene(scene, dir.string() + spelling);
    CHECK(report.frames == 21);
    CHECK(fs::exists(dir / "view.html"));
  }
}

TEST_CASE("outputs: a second run clears the first run's frames and leaves the user's files") {
  const fs::path dir = fresh_dir("rerun");
  {
    clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
    clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
    outputs.obj = outputs.vtk = outputs.velocities = true;
    clothlab::run_scene(scene, outputs);
  }
  CHECK(fs::exists(dir / "frames" / "frame_0021.obj"));
  CHECK(fs::exists(dir / "velocities.csv"));
  write_text(dir / "notes.txt", "mine\n");
  write_text(dir / "frames" / "README", "mine too\n");

  std::string shorter = kCloth;
  shorter.replace(shorter.find("duration = 0.2"), 14, "duration = 0.05");
  clothlab::Scene scene = clothlab::parse_scene(shorter, "<cloth>");
  clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
  outputs.obj = true;
  const clothlab::RunReport report = clothlab::run_scene(scene, outputs);
  CHECK(report.frames == 6);
  CHECK(names_in(dir) == std::vector<std::string>{".clothlab-run", "energy.csv", "frames",
                                                  "notes.txt", "positions.csv", "view.html"});
  std::vector<std::string> frames = names_in(dir / "frames");
  CHECK(frames.size() == 7);  // frame_0001..6.obj and the README
  CHECK(frames.front() == "README");
  CHECK(frames.back() == "frame_0006.obj");
}

TEST_CASE("outputs: a run stopped by a signal ends with a whole last frame and its page") {
  const fs::path dir = fresh_dir("signal");
  clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
  // A TERM arrives after step 37, between frames (frames are every 10 steps).
  const auto progress = [](long done, long) {
    if (done == 37) std::raise(SIGTERM);
  };
  long stopped_at = -1, frames = -1;
  try {
    clothlab::run_scene(scene, dir, progress);
  } catch (const clothlab::RunStopped& stop) {
    CHECK(stop.signal() == SIGTERM);
    CHECK(std::string(stop.what()) == "stopped by SIGTERM after step 37");
    stopped_at = stop.step();
    frames = stop.frames();
  }
  CHECK(stopped_at == 37);
  CHECK(frames == 5);  // steps 0, 10, 20, 30 and 37
  CHECK(scene.world.t == doctest::Approx(0.037));

  std::ifstream energy(dir / "energy.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(energy, line);)
    rows.push_back(line);
  REQUIRE(rows.size() == 6);
  CHECK(rows.back().rfind("4,0.037", 0) == 0);
  const std::string positions = read_all(dir / "positions.csv");
  CHECK(positions.back() == '\n');
  CHECK(std::count(positions.begin(), positions.end(), '\n') == 1 + 5 * 400);
  const std::string page = read_all(dir / "view.html");
  CHECK(page.find("\"times\":[0.0,0.01") != std::string::npos);
  // The handlers are gone with the run: the signal's usual meaning is back.
  CHECK(clothlab::StopSignals::received() == 0);
}

TEST_CASE("outputs: a frame with a value too large for a double is refused, not written") {
  const fs::path dir = fresh_dir("overflow");
  // The guard's bounds, widened, let a speed through whose kinetic energy 1/2 m v^2 is inf
  // (v > 1.9e154 m/s): after step 1 of a fall in a gravity of 1e300 m/s^2.
  std::string text = R"(
[guard]
max_speed = 1e300
max_position = 1e300
[[particle]]
position = [0, 0, 0]
mass = 1
[gravity]
g = [0, -1e300, 0]
[integrator]
dt = 0.01
duration = 1
[output]
fps = 100
)";
  clothlab::Scene scene = clothlab::parse_scene(text, "<overflow>");
  CHECK_THROWS_WITH_AS(clothlab::run_scene(scene, dir),
                       "frame 1 (after step 1, t = 0.01 s) would write a kinetic energy [J] of "
                       "inf: a number too large for a double, or not a number; stopped before "
                       "writing it (the files hold the frames before it)",
                       clothlab::SimulationError);
  CHECK(read_all(dir / "energy.csv") ==
        "frame,t,kinetic,potential,total,px,py,pz\n0,0,0,0,0,0,0,0\n");
  CHECK(read_all(dir / "positions.csv") == "frame,t,particle,x,y,z\n0,0,0,0,0,0\n");

  // Already at the start: no frame at all. (A scene file that starts so is refused by the reader,
  // scene_errors.cpp; a world set so by code reaches the run.)
  scene = clothlab::parse_scene(text, "<overflow>");
  scene.world.particles.v.col(0) = clothlab::Vec3(1e160, 0, 0);
  CHECK_THROWS_WITH_AS(clothlab::run_scene(scene, dir),
                       doctest::Contains("frame 0 (after step 0, t = 0 s) would write a kinetic "
                                         "energy [J] of inf"),
                       clothlab::SimulationError);
  CHECK(read_all(dir / "energy.csv") == "frame,t,kinetic,potential,total,px,py,pz\n");
  CHECK(read_all(dir / "positions.csv") == "frame,t,particle,x,y,z\n");
  // The page's data (its scripts may well say "inf" or "nan" in their own words).
  const std::string page = read_all(dir / "view.html");
  const size_t data = page.find("id=\"clothlab-data\"");
  REQUIRE(data != std::string::npos);
  const std::string frames = page.substr(data, page.find("</script>", data) - data);
  CHECK(frames.find("inf") == std::string::npos);
  CHECK(frames.find("nan") == std::string::npos);
}

TEST_CASE("outputs: format npy writes positions.npy in place of positions.csv, frame for frame") {
  const fs::path dir = fresh_dir("npy");
  std::string text = kCloth;
  text += "velocities = true\nformat = \"npy\"\n";  // in [output], the last table
  clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
  const clothlab::RunReport report = clothlab::run_scene(scene, dir);
  CHECK(report.frames == 21);
  CHECK(names_in(dir) == std::vector<std::string>{".clothlab-run", "energy.csv", "positions.npy",
                                                  "velocities.npy", "view.html"});
  const std::string npy = read_all(dir / "positions.npy");
  CHECK(npy.find("'shape': (21, 400, 3)") != std::string::npos);
  CHECK(npy.size() == 128 + 21 * 400 * 3 * 4);
  // The last frame's first particle, as the float the double was rounded to.
  float x0 = 0;
  std::memcpy(&x0, npy.data() + 128 + 20 * 400 * 3 * 4, sizeof x0);
  CHECK(x0 == static_cast<float>(scene.world.particles.x(0, 0)));
  CHECK(read_all(dir / "velocities.npy").size() == npy.size());
}
