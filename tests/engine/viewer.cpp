// The viewer page: within its byte budget, always with the run's last frame, and written whole
// or not at all.
#include <doctest/doctest.h>

#include <sys/resource.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "clothlab/core/world.hpp"
#include "io/viewer.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using clothlab::ViewerRecorder;
using clothlab::World;

namespace {

constexpr int kParticles = 10;
constexpr long kFrameBytes = 3 * kParticles * sizeof(float);  // 120 bytes a frame

// Ten particles, the whole world moving along x by 1 m per frame: frame k at x = k, t = k / 10.
World ten_particles() {
  World world;
  world.particles.grow(kParticles, 1.0);
  return world;
}

void offer_frames(ViewerRecorder& viewer, World& world, int count) {
  for (int k = 0; k < count; ++k) {
    world.t = 0.1 * k;
    world.particles.x.row(0).setConstant(k);
    viewer.offer(world);
  }
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = test::scratch_path(name);
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The page's data: the JSON in its data <script> element.
nlohmann::json page_data(const fs::path& page) {
  const std::string text = read_text(page);
  const std::string open = "<script id=\"clothlab-data\" type=\"application/json\">";
  const size_t begin = text.find(open);
  REQUIRE(begin != std::string::npos);
  const size_t from = begin + open.size();
  return nlohmann::json::parse(text.substr(from, text.find("</script>", from) - from));
}

std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  return names;
}

}  // namespace

TEST_CASE("viewer: a page within its budget keeps every k-th frame and the last") {
  // A budget of 5 frames for 21 offered: the first and every 6th on 4 places (0, 6, 12, 18),
  // ceil(21 / 4) = 6, and the last (20) on the fifth.
  World world = ten_particles();
  ViewerRecorder viewer("", "budget.toml", 21, 600, 5 * kFrameBytes);
  offer_frames(viewer, world, 21);
  CHECK(viewer.frames_offered() == 21);
  CHECK(viewer.frames_kept() == 5);
  CHECK(viewer.sampling_note() ==
        "the page keeps every 6th frame and the last (5 of 21): a page holds at most 600 bytes "
        "of frames, 120 bytes each");
  const fs::path dir = fresh_dir("budget");
  viewer.write(world, dir / "view.html");
  const nlohmann::json data = page_data(dir / "view.html");
  const std::vector<double> times = data["times"];
  REQUIRE(times.size() == 5);
  const double expected[] = {0.0, 0.6, 1.2, 1.8, 2.0};
  for (size_t f = 0; f < times.size(); ++f)
    CHECK(times[f] == doctest::Approx(expected[f]));
  REQUIRE(data["frames"].size() == 5);
  // 120 bytes in base64: 4 digits for every 3 bytes, 160.
  for (const auto& frame : data["frames"])
    CHECK(frame.get<std::string>().size() == 160);
  CHECK(data["sampling"] == viewer.sampling_note());
}

TEST_CASE("viewer: the max_frames cap samples too, and every frame kept needs no note") {
  World world = ten_particles();
  ViewerRecorder capped("", "capped.toml", 601, 600);
  offer_frames(capped, world, 601);
  // ceil(601 / 599) = 2: frames 0, 2, ..., 600, which is the last.
  CHECK(capped.frames_kept() == 301);
  CHECK(capped.sampling_note() ==
        "the page keeps every other frame and the last (301 of 601): a page holds at most 600 "
        "frames");
  World small = ten_particles();
  ViewerRecorder all("", "all.toml", 600, 600);
  offer_frames(all, small, 600);
  CHECK(all.frames_kept() == 600);
  CHECK(all.sampling_note().empty());
}

TEST_CASE("viewer: a run longer than expected is thinned out and never passes the budget") {
  // 5 frames expected, 50 offered, 4 frames' budget: the stride doubles as places run out.
  World world = ten_particles();
  ViewerRecorder viewer("", "long.toml", 5, 600, 4 * kFrameBytes);
  for (int k = 0; k < 50; ++k) {
    world.t = 0.1 * k;
    viewer.offer(world);
    CHECK(viewer.frames_kept() <= 4);
  }
  const fs::path dir = fresh_dir("long");
  viewer.write(world, dir / "view.html");
  const std::vector<double> times = page_data(dir / "view.html")["times"];
  REQUIRE(times.size() >= 2);
  CHECK(times.front() == 0.0);
  CHECK(times.back() == doctest::Approx(4.9));  // the last frame offered
  for (size_t f = 1; f < times.size(); ++f)
    CHECK(times[f] > times[f - 1]);
}

TEST_CASE("viewer: a frame over the budget leaves the first and the last frame") {
  World world = ten_particles();
  ViewerRecorder viewer("", "huge.toml", 41, 600, kFrameBytes / 2);
  offer_frames(viewer, world, 41);
  CHECK(viewer.frames_kept() == 2);
  CHECK(viewer.sampling_note() ==
        "the page keeps the first frame and the last (2 of 41): a page holds at most 60 bytes of "
        "frames, 120 bytes each");
  const fs::path dir = fresh_dir("huge");
  viewer.write(world, dir / "view.html");
  const std::vector<double> times = page_data(dir / "view.html")["times"];
  REQUIRE(times.size() == 2);
  CHECK(times[0] == 0.0);
  CHECK(times[1] == doctest::Approx(4.0));
}

TEST_CASE("viewer: a surface that changes between kept frames is shown from the next page frame") {
  // Kept: offered frames 0, 6, 12, 18 and the last, 20 (as in the budget test). The surface
  // grows from one triangle to two at frame 7 (shown from page frame 2, offered frame 12), and
  // to three at frame 20, the last (page frame 4).
  World world = ten_particles();
  ViewerRecorder viewer("", "torn.toml", 21, 600, 5 * kFrameBytes);
  world.triangles = {{0, 1, 2}};
  for (int k = 0; k < 21; ++k) {
    if (k == 7) world.triangles.push_back({3, 4, 5});
    if (k == 20) world.triangles.push_back({6, 7, 8});
    world.t = 0.1 * k;
    viewer.offer(world);
  }
  const fs::path dir = fresh_dir("torn");
  viewer.write(world, dir / "view.html");
  const nlohmann::json surfaces = page_data(dir / "view.html")["surfaces"];
  REQUIRE(surfaces.size() == 3);
  CHECK(surfaces[0]["from"] == 0);
  CHECK(surfaces[0]["triangles"] == std::vector<int>{0, 1, 2});
  CHECK(surfaces[1]["from"] == 2);
  CHECK(surfaces[1]["triangles"].size() == 6);
  CHECK(surfaces[2]["from"] == 4);
  CHECK(surfaces[2]["triangles"] == std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8});
}

TEST_CASE("viewer: the page replaces the old one whole, and a failed write leaves the old one") {
  World world = ten_particles();
  ViewerRecorder viewer("a title", "whole.toml", 3);
  offer_frames(viewer, world, 3);
  const fs::path dir = fresh_dir("whole");
  const fs::path page = dir / "view.html";
  {
    std::ofstream old(page);
    old << "the old page";
  }
  viewer.write(world, page);
  CHECK(files_in(dir) == std::vector<std::string>{"view.html"});  // no temporary file left
  CHECK(page_data(page)["title"] == "a title");
  const std::string whole = read_text(page);

  SUBCASE("a folder that does not exist") {
    const fs::path nowhere = dir / "missing" / "view.html";
    try {
      viewer.write(world, nowhere);
      FAIL("a page was written into a folder that does not exist");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()) ==
            "cannot write " + nowhere.string() + ": " + std::string(strerror(ENOENT)));
    }
  }
  SUBCASE("a file size limit that stops the page half-way") {
    // A page of three frames of ten particles and its template is several kilobytes; at most
    // 1000 bytes may be written. Every check waits until the limit is lifted again.
    rlimit before{};
    REQUIRE(getrlimit(RLIMIT_FSIZE, &before) == 0);
    rlimit limited = before;
    limited.rlim_cur = 1000;
    void (*const handler)(int) = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG, not a signal
    REQUIRE(setrlimit(RLIMIT_FSIZE, &limited) == 0);
    std::string error;
    try {
      world.t = 99.0;
      viewer.offer(world);
      viewer.write(world, page);
    } catch (const std::runtime_error& e) {
      error = e.what();
    }
    setrlimit(RLIMIT_FSIZE, &before);
    std::signal(SIGXFSZ, handler);
    CHECK(error == "writing " + page.string() + " failed: " + std::string(strerror(EFBIG)) +
                       "; the file there is as it was");
    CHECK(read_text(page) == whole);  // the old page, whole
    CHECK(files_in(dir) == std::vector<std::string>{"view.html"});
  }
}
