// Outputs that lose nothing: whole frames whatever stops a run, a folder that is the run's own,
// and no inf or NaN in any file.
#include <doctest/doctest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "clothlab/core/effect.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/core/stop.hpp"
#include "io/files.hpp"
#include "io/npy.hpp"
#include "io/output.hpp"
#include "io/run.hpp"
#include "io/run_folder.hpp"
#include "scene/scene.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using clothlab::OutputError;

namespace {

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
  const fs::path dir = test::scratch_path("append");
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
  const fs::path dir = test::scratch_path("replace");
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
  const fs::path dir = test::scratch_path("foreign");
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
  const fs::path dir = test::scratch_path("lock");
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
  const fs::path dir = test::scratch_path("page");
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
    const fs::path dir = test::scratch_path("slash");
    clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
    const clothlab::RunReport report = clothlab::run_scene(scene, dir.string() + spelling);
    CHECK(report.frames == 21);
    CHECK(fs::exists(dir / "view.html"));
  }
}

TEST_CASE("outputs: a second run clears the first run's frames and leaves the user's files") {
  const fs::path dir = test::scratch_path("rerun");
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
  const fs::path dir = test::scratch_path("signal");
  // Frames every 100 steps; the run takes its steps kRunStepsAtOnce at a time between frames
  // (World::advance) and looks at the stop signals after each such run of steps.
  std::string text = kCloth;
  text.replace(text.find("fps = 100"), 9, "fps = 10");
  clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
  // A TERM arrives with the first progress report at or after step 37: the run stops at the end
  // of the steps it took at once, between frames.
  constexpr long kAt = 37;
  const long stop_step =
      (kAt + clothlab::kRunStepsAtOnce - 1) / clothlab::kRunStepsAtOnce * clothlab::kRunStepsAtOnce;
  REQUIRE(stop_step % 100 != 0);
  bool raised = false;
  const auto progress = [&raised](long done, long) {
    if (done >= kAt && !raised) {
      raised = true;
      std::raise(SIGTERM);
    }
  };
  long stopped_at = -1, frames = -1;
  try {
    clothlab::run_scene(scene, dir, progress);
  } catch (const clothlab::RunStopped& stop) {
    CHECK(stop.signal() == SIGTERM);
    CHECK(std::string(stop.what()) == "stopped by SIGTERM after step " + std::to_string(stop_step));
    stopped_at = stop.step();
    frames = stop.frames();
  }
  CHECK(stopped_at == stop_step);
  CHECK(frames == 2);  // steps 0 and stop_step
  CHECK(scene.world.t == doctest::Approx(0.001 * static_cast<double>(stop_step)));

  std::ifstream energy(dir / "energy.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(energy, line);)
    rows.push_back(line);
  REQUIRE(rows.size() == 3);
  CHECK(rows.back().rfind(fmt::format("1,{:g}", 0.001 * static_cast<double>(stop_step)), 0) == 0);
  const std::string positions = read_all(dir / "positions.csv");
  CHECK(positions.back() == '\n');
  CHECK(std::count(positions.begin(), positions.end(), '\n') == 1 + 2 * 400);
  const std::string page = read_all(dir / "view.html");
  CHECK(page.find("\"times\":[0.0,0.0") != std::string::npos);
  // The handlers are gone with the run: the signal's usual meaning is back.
  CHECK(clothlab::StopSignals::received() == 0);
}

TEST_CASE("outputs: a frame with a value too large for a double is refused, not written") {
  const fs::path dir = test::scratch_path("overflow");
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
  // The page's data holds no such number (its scripts, and the message of why the run stopped,
  // which the page shows, may well say "inf" or "nan" in words).
  const std::string page = read_all(dir / "view.html");
  const size_t data = page.find("id=\"clothlab-data\"");
  REQUIRE(data != std::string::npos);
  const std::string frames = page.substr(data, page.find("</script>", data) - data);
  const std::regex number_not_finite(R"([\[,:]\s*-?(inf|nan|Infinity|NaN))");
  CHECK_FALSE(std::regex_search(frames, number_not_finite));
  CHECK(frames.find("\"stopped\":{\"message\":\"frame 0 (after step 0") != std::string::npos);
}

TEST_CASE("outputs: format npy writes positions.npy in place of positions.csv, frame for frame") {
  const fs::path dir = test::scratch_path("npy");
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

// The symbolic link attack: a link planted where a run writes (in a shared folder such as /tmp,
// say) must never make the run write, truncate or delete the file or folder it points to.
namespace {

// A folder of files a run must never touch, each holding "victim NAME\n".
fs::path make_victims(const std::string& test, const std::vector<std::string>& names) {
  const fs::path victims = test::scratch_path(test + "-victims");
  fs::create_directories(victims);
  for (const std::string& name : names)
    write_text(victims / name, "victim " + name + "\n");
  return victims;
}

void check_victims(const fs::path& victims, const std::vector<std::string>& names) {
  CHECK(names_in(victims) == names);
  for (const std::string& name : names)
    CHECK_MESSAGE(read_all(victims / name) == "victim " + name + "\n", name);
}

}  // namespace

TEST_CASE("outputs: every writer replaces a symbolic link in its place and not the file it names") {
  const fs::path dir = test::scratch_path("writer-links");
  fs::create_directories(dir);
  const std::vector<std::string> names = {"append", "npy", "partial", "replace"};
  const fs::path victims = make_victims("writer-links", names);
  fs::create_symlink(victims / "append", dir / "rows.csv");
  fs::create_symlink(victims / "npy", dir / "x.npy");
  fs::create_symlink(victims / "replace", dir / "page.html");
  // The temporary file's name is predictable (the process id): a link planted there.
  fs::create_symlink(victims / "partial", dir / (".page.html.partial-" + std::to_string(getpid())));

  clothlab::AppendFile rows(dir / "rows.csv");
  rows.append("mine\n");
  clothlab::NpyFrameWriter npy(dir / "x.npy", 1);
  npy.append(clothlab::Matrix3X::Zero(3, 1));
  clothlab::write_whole_file(dir / "page.html", "my page\n");

  check_victims(victims, names);
  for (const std::string name : {"rows.csv", "x.npy", "page.html"})
    CHECK_MESSAGE(fs::is_regular_file(fs::symlink_status(dir / name)), name);
  CHECK(read_all(dir / "rows.csv") == "mine\n");
  CHECK(read_all(dir / "page.html") == "my page\n");
  CHECK(names_in(dir) == std::vector<std::string>{"page.html", "rows.csv", "x.npy"});
}

TEST_CASE("outputs: a marker that is a link or has a second name is refused and its file kept") {
  const std::vector<std::string> names = {"marker"};
  const fs::path victims = make_victims("marker-link", names);
  const fs::path dir = test::scratch_path("marker-link");
  fs::create_directories(dir);
  fs::create_symlink(victims / "marker", dir / ".clothlab-run");
  for (const bool force : {false, true}) {
    CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir, force),
                         ((dir / ".clothlab-run").string() +
                          " is a symbolic link, not clothlab's marker, and a run writes into "
                          "that file; remove it, or choose another --out")
                             .c_str(),
                         OutputError);
  }
  // A link to no file at all (which O_CREAT would make): refused too, and nothing made.
  fs::remove(dir / ".clothlab-run");
  fs::create_symlink(victims / "new", dir / ".clothlab-run");
  CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir, true), doctest::Contains("is a symbolic link"),
                       OutputError);
  // A hard link: the same file under a second name.
  fs::remove(dir / ".clothlab-run");
  fs::create_hard_link(victims / "marker", dir / ".clothlab-run");
  CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir, true),
                       doctest::Contains("is a file with other names (hard links), not "
                                         "clothlab's marker"),
                       OutputError);
  fs::remove(dir / ".clothlab-run");
  check_victims(victims, names);

  // A run folder that is itself a link is not followed.
  fs::create_directories(victims / "folder");
  fs::create_symlink(victims / "folder", dir / "out");
  CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir / "out", true),
                       ("cannot write into " + (dir / "out").string() +
                        ": it is a symbolic link, which a run does not follow; give the folder "
                        "it points to as --out")
                           .c_str(),
                       OutputError);
  CHECK(fs::is_empty(victims / "folder"));
}

TEST_CASE("outputs: links in a run folder are removed as names and what they point to is kept") {
  const fs::path dir = test::scratch_path("folder-links");
  const auto run = [&](bool npy) {
    std::string text = kCloth;
    text += npy ? "velocities = true\nformat = \"npy\"\n" : "velocities = true\nsprings = true\n";
    clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
    clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
    outputs.obj = outputs.vtk = true;
    return clothlab::run_scene(scene, outputs);
  };
  run(false);  // the folder is clothlab's now: a marker, outputs and frames
  const std::vector<std::string> outputs = {"energy.csv",  "positions.csv",       "velocities.csv",
                                            "springs.csv", "positions.npy",       "velocities.npy",
                                            "view.html",   ".view.html.partial-1"};
  std::vector<std::string> names = outputs;
  names.push_back("frames");
  std::sort(names.begin(), names.end());
  const fs::path victims = make_victims("folder-links", names);
  fs::remove(victims / "frames");
  fs::create_directories(victims / "frames");
  const std::vector<std::string> frames = {"frame_0001.obj", "frame_0002.vtk", "frames.vtk.series"};
  for (const std::string& frame : frames)
    write_text(victims / "frames" / frame, "victim frame\n");

  for (const bool npy : {false, true}) {
    CAPTURE(npy);
    for (const std::string& name : outputs) {
      fs::remove(dir / name);
      fs::create_symlink(victims / name, dir / name);
    }
    fs::remove_all(dir / "frames");
    fs::create_directory_symlink(victims / "frames", dir / "frames");
    CHECK(run(npy).frames == 21);
    for (const std::string& name : outputs) {
      CHECK_MESSAGE(read_all(victims / name) == "victim " + name + "\n", name);
      CHECK_FALSE(fs::is_symlink(dir / name));
    }
    CHECK(names_in(victims / "frames") == frames);
    CHECK_FALSE(fs::is_symlink(dir / "frames"));
    CHECK(fs::is_regular_file(dir / "frames" / "frame_0021.obj"));
  }
}

TEST_CASE(
    "outputs: --html is no link nor a note that mentions the viewer nor another run's folder") {
  const fs::path dir = test::scratch_path("html-place");
  fs::create_directories(dir);
  const std::vector<std::string> names = {"page"};
  const fs::path victims = make_victims("html-place", names);
  // A temporary file's name planted as a link beside the page.
  fs::create_symlink(victims / "page", dir / (".view.html.partial-" + std::to_string(getpid())));
  clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
  clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir / "run");
  outputs.html = dir / "view.html";
  CHECK(clothlab::run_scene(scene, outputs).frames == 21);
  check_victims(victims, names);
  CHECK(fs::is_regular_file(fs::symlink_status(dir / "view.html")));

  // A link as the page itself: refused unless forced; forced, the link goes, not its file.
  fs::create_symlink(victims / "page", dir / "link.html");
  CHECK_THROWS_WITH_AS(clothlab::check_page_target(dir / "link.html", false),
                       ((dir / "link.html").string() +
                        " is a symbolic link; choose another --html, or add --force to replace "
                        "the link (the file it points to is left alone)")
                           .c_str(),
                       OutputError);

  // A user's note that names the viewer is not a page.
  write_text(dir / "notes.html", "<!-- my notes on the clothlab viewer: it is good -->\n");
  CHECK_THROWS_WITH_AS(clothlab::check_page_target(dir / "notes.html", false),
                       doctest::Contains("notes.html exists and is not a clothlab viewer page"),
                       OutputError);
  CHECK_NOTHROW(clothlab::check_page_target(dir / "view.html", false));  // a page: replaced

  // Into another run's folder while that run writes there: refused.
  {
    const clothlab::RunFolder other(dir / "other", false);
    const std::string busy = "is writing into " + (dir / "other").string() +
                             " now; wait for it to end, or choose another --html";
    CHECK_THROWS_WITH_AS(clothlab::check_page_target(dir / "other" / "view.html", false),
                         doctest::Contains(busy.c_str()), OutputError);
  }
  // And while the page may be written there, no run starts in that folder.
  {
    const clothlab::PageFolderLock lock =
        clothlab::check_page_target(dir / "other" / "view.html", false);
    CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir / "other", false),
                         doctest::Contains("is writing into"), OutputError);
  }
  CHECK_NOTHROW(clothlab::RunFolder(dir / "other", false));
  check_victims(victims, names);
}

TEST_CASE("outputs: an fps so small that 1 / (fps dt) overflows writes the first and last frame") {
  std::string text = kCloth;
  text.replace(text.find("fps = 100"), 9, "fps = 1e-300");
  clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
  const clothlab::RunReport report = clothlab::run_scene(scene, test::scratch_path("tiny-fps"));
  CHECK(report.steps == 200);
  CHECK(report.frames == 2);
}

TEST_CASE(
    "outputs: a value past 3.4e38 stops the run before a 32-bit float file or page gets inf") {
  // The guard's bounds, widened, let a particle fly at 1e40 m/s: x = 1e38 k m after step k, a
  // double all along, but past the largest float (3.4e38) from step 4 on.
  const std::string text = R"(
[guard]
max_speed = 1e300
max_position = 1e300
[[particle]]
position = [0, 0, 0]
velocity = [1e40, 0, 0]
mass = 1
[integrator]
dt = 0.01
duration = 0.1
[output]
fps = 100
)";
  const fs::path dir = test::scratch_path("float-range");
  clothlab::Scene scene = clothlab::parse_scene(text, "<fast>");
  CHECK_THROWS_WITH_AS(clothlab::run_scene(scene, dir),
                       "frame 4 (after step 4, t = 0.04 s) would write a position [m] of 4e+38: "
                       "more than a 32-bit float holds (3.4e+38), which the page keeps; stopped "
                       "before writing it (the files hold the frames before it)",
                       clothlab::SimulationError);
  std::string energy = read_all(dir / "energy.csv");
  CHECK(std::count(energy.begin(), energy.end(), '\n') == 1 + 4);
  CHECK(read_all(dir / "view.html").find("\"times\":[0.0,0.01,0.02,0.03]") != std::string::npos);

  // velocities.npy would hold the starting velocity of 1e40 as a float: the run refuses it at
  // its place in the scene, before it writes anything (the files of the run above are kept).
  scene = clothlab::parse_scene(text + "format = \"npy\"\nvelocities = true\n", "<fast>");
  REQUIRE(scene.velocity_beyond_float);
  CHECK_FALSE(scene.position_beyond_float);
  clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
  outputs.html.clear();
  CHECK_THROWS_WITH_AS(clothlab::run_scene(scene, outputs),
                       "<fast>:7:12: [[particle]] #1 starts at velocity (1e+40, 0, 0) m/s, beyond "
                       "what a 32-bit float holds (3.40282e+38), which velocities.npy keeps; "
                       "expected each component within 3.40282e+38 m/s, or velocities in "
                       "velocities.csv (format = \"csv\")",
                       clothlab::SceneError);
  CHECK(read_all(dir / "energy.csv") == energy);

  // The CSV files alone keep doubles: the run goes to its end.
  scene = clothlab::parse_scene(text, "<fast>");
  CHECK(clothlab::run_scene(scene, outputs).frames == 11);
  energy = read_all(dir / "energy.csv");
  CHECK(std::count(energy.begin(), energy.end(), '\n') == 1 + 11);

  // A start past 3.4e38 m: the page, or positions.npy, would hold it as inf. Refused at the
  // key that put it there, the folder untouched; the CSV files alone take it.
  const std::string far = R"(
[guard]
max_position = 1e300
[[particle]]
position = [0, 1e39, 0]
mass = 1
[cloth]
rows = 2
cols = 2
spacing = 1e30
origin = [0, 0, 0]
mass = 1
[integrator]
dt = 0.01
duration = 0.1
[output]
fps = 100
)";
  scene = clothlab::parse_scene(far, "<far>");
  REQUIRE(scene.position_beyond_float);
  CHECK_FALSE(scene.velocity_beyond_float);
  const std::string position_error =
      "<far>:5:12: [[particle]] #1 starts at (0, 1e+39, 0) m, beyond what a 32-bit float holds "
      "(3.40282e+38), which the page and positions.npy keep; expected |x|, |y|, |z| <= "
      "3.40282e+38 m, or a run that writes the CSV files alone (--no-html, format = \"csv\")";
  CHECK(scene.position_beyond_float->text() == position_error);
  CHECK_THROWS_WITH_AS(clothlab::run_scene(scene, dir), position_error.c_str(),
                       clothlab::SceneError);
  CHECK(read_all(dir / "energy.csv") == energy);
  outputs.npy = true;
  CHECK_THROWS_WITH_AS(clothlab::run_scene(scene, outputs), position_error.c_str(),
                       clothlab::SceneError);
  outputs.npy = false;
  CHECK(clothlab::run_scene(scene, outputs).frames == 11);
  // A body's start: its velocity, at the key that set it.
  const clothlab::Scene moving = clothlab::parse_scene(
      "[guard]\nmax_speed = 1e300\n[cloth]\nrows = 2\ncols = 2\nspacing = 1\nmass = 1\n"
      "velocity = [0, 0, -1e39]\n[integrator]\ndt = 0.01\nduration = 0.1\n",
      "<moving>");
  REQUIRE(moving.velocity_beyond_float);
  CHECK(moving.velocity_beyond_float->text().starts_with(
      "<moving>:8:12: the cloth's particle 0 starts at velocity (0, 0, -1e+39) m/s, beyond what "
      "a 32-bit float holds (3.40282e+38), which velocities.npy keeps"));
  // Within a float's range (the cloth's far corner, 1e30 m): no note.
  CHECK_FALSE(
      clothlab::parse_scene(
          far.substr(0, far.find("[[particle]]")) + far.substr(far.find("[cloth]")), "<near>")
          .position_beyond_float);
}

namespace {

// A force of nothing that, at its `at`-th evaluation, asks the run to stop as a TERM would: a
// signal that arrives in the middle of a step, at a known moment.
class StopAtEvaluation : public clothlab::ForceEffect {
 public:
  explicit StopAtEvaluation(long at) : at_(at) {}
  std::string_view name() const override { return "stop-at-evaluation"; }
  void add_forces(const clothlab::Particles&, const clothlab::Matrix3X&, const clothlab::Matrix3X&,
                  clothlab::Matrix3X&) const override {
    if (++evaluations_ == at_) std::raise(SIGTERM);
  }
  mutable long evaluations_ = 0;

 private:
  long at_;
};

}  // namespace

TEST_CASE("outputs: a TERM during a step of many substeps gives it up at once") {
  // XPBD with 2000 substeps a step, one sum of the external forces each: the TERM comes in the
  // 5th substep of step 3 (evaluation 2 * 2000 + 5), and the run ends in that substep.
  std::string text = kCloth;
  text.replace(text.find("[integrator]"), 12,
               "[integrator]\nmethod = \"xpbd\"\nsubsteps = 2000\niterations = 1");
  clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
  auto stopper = std::make_unique<StopAtEvaluation>(2 * 2000 + 5);
  const StopAtEvaluation& counter = *stopper;
  scene.world.force_effects.push_back(std::move(stopper));
  const fs::path dir = test::scratch_path("term-substeps");
  try {
    clothlab::run_scene(scene, dir);
    FAIL("the run was not stopped");
  } catch (const clothlab::RunStopped& stop) {
    CHECK(std::string(stop.what()) == "stopped by SIGTERM during step 3, given up part way");
    CHECK(stop.abandoned() == 3);
    CHECK(stop.step() == 0);  // the last frame written: frame 0 (frames are every 10 steps)
    CHECK(stop.frames() == 1);
  }
  CHECK(counter.evaluations_ == 2 * 2000 + 5);  // not one substep more
  const std::string energy = read_all(dir / "energy.csv");
  CHECK(std::count(energy.begin(), energy.end(), '\n') == 1 + 1);
  CHECK(fs::exists(dir / "view.html"));
  CHECK(clothlab::StopSignals::received() == 0);
}

TEST_CASE("outputs: the long loops give up their work on a stop only where a run asked them to") {
  // [gravitation]'s energy, n^2 / 2 pairs, and local/global and strain limiting's iterations.
  std::string text = kCloth;
  text += "[gravitation]\n[strain_limit]\nmax_strain = 0.1\n";
  clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
  const double energy = scene.world.potential_energy();
  clothlab::ask_to_stop(SIGTERM);
  CHECK(scene.world.potential_energy() == energy);  // no StopPoints: a test, the game loop
  {
    const clothlab::StopPoints points;
    CHECK_THROWS_AS(scene.world.potential_energy(), clothlab::StepAbandoned);
    CHECK_THROWS_AS(scene.world.step(0.001), clothlab::StepAbandoned);
  }
  clothlab::ask_to_stop(0);
  const clothlab::StopPoints points;
  CHECK(scene.world.potential_energy() == energy);
}

TEST_CASE("outputs: after a SIGKILL every file is cut back to the frames all of them hold") {
  const fs::path dir = test::scratch_path("killed");
  for (const bool npy : {false, true}) {
    CAPTURE(npy);
    std::string text = kCloth;
    text += npy ? "velocities = true\nformat = \"npy\"\n" : "velocities = true\nsprings = true\n";
    clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
    clothlab::run_scene(scene, dir);
    const std::vector<std::string> names =
        npy ? std::vector<std::string>{"energy.csv", "positions.npy", "velocities.npy"}
            : std::vector<std::string>{"energy.csv", "positions.csv", "velocities.csv",
                                       "springs.csv"};
    std::vector<std::string> whole;
    for (const std::string& name : names)
      whole.push_back(read_all(dir / name));
    // A kill in the middle of frame 21: positions took it whole, velocities a part of it, and
    // energy.csv a cut line (or, for .npy, the frame's bytes and the count that takes it in).
    const auto append = [&](const std::string& name, const std::string& more) {
      std::ofstream(dir / name, std::ios::app | std::ios::binary) << more;
    };
    if (npy) {
      std::string bytes = read_all(dir / "positions.npy");
      const std::string shape = "'shape': (21, 400, 3)";
      bytes.replace(bytes.find(shape), shape.size(), "'shape': (22, 400, 3)");
      write_text(dir / "positions.npy", bytes + std::string(400 * 12, 'x'));
      append("velocities.npy", std::string(100, 'x'));
    } else {
      std::string frame;
      for (int i = 0; i < 400; ++i)
        frame += "21,0.21," + std::to_string(i) + ",1,2,3\n";
      append("positions.csv", frame);
      append("velocities.csv", frame.substr(0, 1000));
      append("springs.csv", "21,0.21,springs,0,0,1,0.0");
    }
    append("energy.csv", "21,0.2");
    CHECK(clothlab::cut_to_common_frames(dir) == 21);
    for (size_t k = 0; k < names.size(); ++k)
      CHECK_MESSAGE(read_all(dir / names[k]) == whole[k], names[k]);
    CHECK(clothlab::cut_to_common_frames(dir) == 21);  // a second time: nothing to do
  }
}

TEST_CASE("outputs: --html onto the run's own data, its marker or its folder is refused first") {
  const fs::path dir = test::scratch_path("html-own");
  // Refused before the first step, with a message that holds `why`.
  const auto refused = [&](const fs::path& out, const fs::path& html, const std::string& why) {
    clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
    clothlab::RunOutputs outputs = clothlab::RunOutputs::in(out);
    outputs.html = html;
    CHECK_THROWS_WITH_AS(clothlab::run_scene(scene, outputs), doctest::Contains(why.c_str()),
                         OutputError);
    CHECK(scene.world.t == 0.0);
  };
  // A new folder: the page would replace positions.csv at the end of the run; the folder itself,
  // or one that holds it, could not be the page.
  const fs::path fresh = dir / "fresh";
  refused(fresh, fresh / "positions.csv",
          "--html " + (fresh / "positions.csv").string() + " is the run's own positions.csv in " +
              "--out " + fresh.string() + ", and the page would replace it; choose another " +
              "--html, such as " + (fresh / "view.html").string());
  refused(fresh, fresh,
          "--html " + fresh.string() + " is the --out folder " + fresh.string() +
              ", and the page is a file beside the run's data; choose another --html, such as " +
              (fresh / "view.html").string());
  refused(fresh, fresh.string() + "/", "is the --out folder");
  refused(fresh / "deeper", fresh, "is a folder that holds the --out folder");
  CHECK_FALSE(fs::exists(fresh));

  // A run's folder: its data, marker and page are as they were.
  {
    clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
    clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir / "run");
    outputs.velocities = true;
    clothlab::run_scene(scene, outputs);
  }
  const std::vector<std::string> names = {".clothlab-run", "energy.csv", "positions.csv",
                                          "velocities.csv", "view.html"};
  std::vector<std::string> before;
  for (const std::string& name : names)
    before.push_back(read_all(dir / "run" / name));
  for (const std::string name : {"energy.csv", "velocities.csv", "springs.csv", ".clothlab-run"}) {
    CAPTURE(name);
    // Spelt another way than --out, the same folder.
    refused(dir / "run", dir / "run" / "." / name, "is the run's own " + name + " in --out");
  }
  CHECK(names_in(dir / "run") == names);
  for (size_t k = 0; k < names.size(); ++k)
    CHECK_MESSAGE(read_all(dir / "run" / names[k]) == before[k], names[k]);
}

TEST_CASE("outputs: a run refused for its page or a file named frames changes nothing there") {
  const fs::path dir = test::scratch_path("refused-unchanged");
  const auto run = [&](const fs::path& html, bool obj = false) {
    clothlab::Scene scene = clothlab::parse_scene(kCloth, "<cloth>");
    clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
    if (!html.empty()) outputs.html = html;
    outputs.obj = obj;
    return clothlab::run_scene(scene, outputs);
  };
  run({});
  write_text(dir / "notes.txt", "mine\n");
  const std::vector<std::string> names = {".clothlab-run", "energy.csv", "notes.txt",
                                          "positions.csv", "view.html"};
  std::vector<std::string> before;
  for (const std::string& name : names)
    before.push_back(read_all(dir / name));
  const auto unchanged = [&] {
    CHECK(names_in(dir) == names);
    for (size_t k = 0; k < names.size(); ++k)
      CHECK_MESSAGE(read_all(dir / names[k]) == before[k], names[k]);
  };
  // --html onto the user's note in the folder: refused before the last run's files are cleared.
  CHECK_THROWS_WITH_AS(run(dir / "notes.txt"),
                       ((dir / "notes.txt").string() +
                        " exists and is not a clothlab viewer page; choose another --html, or add "
                        "--force to replace it")
                           .c_str(),
                       OutputError);
  unchanged();

  // A file of the user's named frames: refused, with or without meshes, and kept; the folder of
  // mesh frames a run makes is no such file.
  write_text(dir / "frames", "my notes on these frames\n");
  const std::string why = (dir / "frames").string() +
                          " is a file, not the folder of mesh frames (frames/frame_NNNN.obj) "
                          "that a run keeps there, and a run into " +
                          dir.string() +
                          " would remove it; move or rename it, or choose another "
                          "--out";
  for (const bool obj : {false, true}) {
    CHECK_THROWS_WITH_AS(run({}, obj), why.c_str(), OutputError);
  }
  CHECK_THROWS_WITH_AS(clothlab::RunFolder(dir, true), why.c_str(), OutputError);
  CHECK(read_all(dir / "frames") == "my notes on these frames\n");
  fs::remove(dir / "frames");
  unchanged();
  CHECK(run({}, true).frames == 21);
  CHECK(fs::is_regular_file(dir / "frames" / "frame_0021.obj"));
  CHECK(run({}).frames == 21);  // the frames of the last run cleared
  CHECK_FALSE(fs::exists(dir / "frames"));

  // --force into a folder of the user's with such a file: refused too, and no marker made.
  const fs::path mine = test::scratch_path("refused-unchanged-mine");
  fs::create_directories(mine);
  write_text(mine / "frames", "mine\n");
  CHECK_THROWS_WITH_AS(clothlab::RunFolder(mine, true), doctest::Contains("is a file, not the"),
                       OutputError);
  CHECK(names_in(mine) == std::vector<std::string>{"frames"});
  CHECK(read_all(mine / "frames") == "mine\n");
}

namespace {

// The run of kCloth (with velocities and springs, or as .npy) in `dir`, whose files repair is
// then asked to mend.
void run_for_repair(const fs::path& dir, bool npy) {
  std::string text = kCloth;
  text += npy ? "velocities = true\nformat = \"npy\"\n" : "velocities = true\nsprings = true\n";
  clothlab::Scene scene = clothlab::parse_scene(text, "<cloth>");
  clothlab::RunOutputs outputs = clothlab::RunOutputs::in(dir);
  outputs.html.clear();
  clothlab::run_scene(scene, outputs);
}

// The first `frames` frames of the CSV text `csv`: its header and their rows.
std::string first_frames(const std::string& csv, long frames) {
  size_t at = csv.find('\n') + 1;
  while (at < csv.size() && std::stol(csv.substr(at, csv.find(',', at) - at)) < frames)
    at = csv.find('\n', at) + 1;
  return csv.substr(0, at);
}

}  // namespace

TEST_CASE("outputs: repair cuts every file to the frames all of them hold whole, and says so") {
  const fs::path dir = test::scratch_path("repair-short");
  run_for_repair(dir, false);
  const std::vector<std::string> names = {"energy.csv", "positions.csv", "springs.csv",
                                          "velocities.csv"};
  std::vector<std::string> whole;
  for (const std::string& name : names)
    whole.push_back(read_all(dir / name));
  // A power cut lost the end of velocities.csv: frame 11 holds particles 0 to 4, the 6th row cut
  // in the middle; then springs.csv, cut at the end of a line: frame 9 holds one spring.
  std::string velocities = first_frames(whole[3], 11);
  const std::string frame_11 = whole[3].substr(velocities.size());
  size_t rows = 0;
  for (int k = 0; k < 5; ++k)
    rows = frame_11.find('\n', rows) + 1;
  write_text(dir / "velocities.csv", velocities + frame_11.substr(0, rows + 10));
  CHECK(clothlab::cut_to_common_frames(dir) == 11);
  for (size_t k = 0; k < names.size(); ++k)
    CHECK_MESSAGE(read_all(dir / names[k]) == first_frames(whole[k], 11), names[k]);

  const size_t first_row = first_frames(whole[2], 9).size();
  write_text(dir / "springs.csv", whole[2].substr(0, whole[2].find('\n', first_row) + 1));
  CHECK(clothlab::cut_to_common_frames(dir) == 9);
  for (size_t k = 0; k < names.size(); ++k)
    CHECK_MESSAGE(read_all(dir / names[k]) == first_frames(whole[k], 9), names[k]);
  CHECK(clothlab::cut_to_common_frames(dir) == 9);  // a second time: nothing to do

  // positions.npy cut short, its header still counting every frame: the header is put right.
  run_for_repair(dir, true);
  const std::string positions = read_all(dir / "positions.npy");
  const long frame_bytes = 400 * 3 * 4;
  write_text(dir / "positions.npy", positions.substr(0, 128 + 15 * frame_bytes + 100));
  CHECK(clothlab::cut_to_common_frames(dir) == 15);
  for (const std::string name : {"positions.npy", "velocities.npy"}) {
    const std::string npy = read_all(dir / name);
    CHECK_MESSAGE(npy.size() == 128 + 15 * frame_bytes, name);
    CHECK_MESSAGE(npy.find("'shape': (15, 400, 3)") != std::string::npos, name);
  }
  const std::string energy = read_all(dir / "energy.csv");
  CHECK(std::count(energy.begin(), energy.end(), '\n') == 1 + 15);
}

TEST_CASE(
    "outputs: repair refuses a folder of the user's and a file it cannot read, cutting none") {
  const fs::path dir = test::scratch_path("repair-refused");
  // The user's own data: no marker.
  fs::create_directories(dir / "mine");
  write_text(dir / "mine" / "energy.csv", "frame,t\n0,0\n1,0.1\n");
  write_text(dir / "mine" / "positions.csv",
             "frame,t,particle,x,y,z\n0,0,0,1,2,3\n1,0.1,0,1,2,3\n"
             "2,0.2,0,1,2,3\n");
  CHECK_THROWS_WITH_AS(clothlab::cut_to_common_frames(dir / "mine"),
                       ((dir / "mine").string() +
                        " is not a clothlab output folder: it holds no .clothlab-run marker, and "
                        "repair cuts the files there; nothing was cut")
                           .c_str(),
                       OutputError);
  CHECK(read_all(dir / "mine" / "positions.csv") ==
        "frame,t,particle,x,y,z\n0,0,0,1,2,3\n1,0.1,0,1,2,3\n2,0.2,0,1,2,3\n");

  // A run's folder in which a file is not one clothlab wrote: every file as it was.
  const fs::path run = dir / "run";
  const std::vector<std::string> names = {"energy.csv", "positions.csv", "springs.csv",
                                          "velocities.csv"};
  const auto check_refused = [&](const std::string& name, const std::string& text,
                                 const std::string& why) {
    CAPTURE(name);
    run_for_repair(run, false);
    write_text(run / name, text);
    std::vector<std::string> before;
    for (const std::string& file : names)
      before.push_back(read_all(run / file));
    CHECK_THROWS_WITH_AS(
        clothlab::cut_to_common_frames(run),
        ((run / name).string() + " is not a file of frames as clothlab writes it: " + why +
         "; repair cut nothing")
            .c_str(),
        OutputError);
    for (size_t k = 0; k < names.size(); ++k)
      CHECK_MESSAGE(read_all(run / names[k]) == before[k], names[k]);
  };
  check_refused("energy.csv", "garbage\n",
                "its first line is not the header \"frame,t,kinetic,potential,total,px,py,pz\"");
  check_refused("energy.csv", "frame,t,kinetic,potential,total,px,py,pz\n0,0,0,0,0,0,0,0\n2,0\n",
                "line 3 is a row of frame 2 after frame 0");
  check_refused("positions.csv", "frame,t,particle,x,y,z\n0,0,0,1,2,3\nx,0,1,1,2,3\n",
                "line 3 is not a row of a frame");
  check_refused("velocities.csv", "", "it holds no whole header line");

  // .npy files of different particles, or a header that is not clothlab's.
  run_for_repair(run, true);
  std::string npy = read_all(run / "velocities.npy");
  const std::string shape = "'shape': (21, 400, 3)";
  npy.replace(npy.find(shape), shape.size(), "'shape': (21, 300, 3)");
  write_text(run / "velocities.npy", npy);
  const std::string positions = read_all(run / "positions.npy");
  CHECK_THROWS_WITH_AS(clothlab::cut_to_common_frames(run),
                       ((run / "positions.npy").string() + " holds frames of 400 particles and " +
                        (run / "velocities.npy").string() +
                        " of 300: they are not one run's files; repair cut nothing")
                           .c_str(),
                       OutputError);
  CHECK(read_all(run / "positions.npy") == positions);
  CHECK(read_all(run / "velocities.npy") == npy);
  write_text(run / "velocities.npy", "not numpy\n");
  CHECK_THROWS_WITH_AS(clothlab::cut_to_common_frames(run),
                       doctest::Contains("velocities.npy is not a file of frames as clothlab "
                                         "writes it: it is shorter than its header"),
                       OutputError);

  // Nor while a run writes there.
  const clothlab::RunFolder busy(run, false);
  CHECK_THROWS_WITH_AS(clothlab::cut_to_common_frames(run),
                       doctest::Contains(("is writing into " + run.string() + " now").c_str()),
                       OutputError);
}
