#include "io/run.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "clothlab/core/guard.hpp"
#include "clothlab/core/kernel_answer.hpp"
#include "clothlab/core/stop.hpp"
#include "io/mesh_export.hpp"
#include "io/output.hpp"
#include "io/run_folder.hpp"
#include "io/viewer.hpp"

namespace clothlab {

namespace {

// Says at once that the run heard the signal, with write(2), which a handler may call.
extern "C" void on_stop_signal(int signal) {
  ask_to_stop(signal);
  static constexpr char kSaid[] =
      "\nstopping after this step (a long step is given up part way); a second signal ends the "
      "run at once\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, kSaid, sizeof kSaid - 1);
}

struct sigaction g_old_int {};
struct sigaction g_old_term {};
struct sigaction g_old_xfsz {};
int g_stop_signals_alive = 0;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string signal_name(int signal) {
  const char* abbreviation = sigabbrev_np(signal);
  return abbreviation ? fmt::format("SIG{}", abbreviation) : fmt::format("signal {}", signal);
}

// Where `path` is, so that two spellings of one place compare equal: absolute, the links of the
// part that exists followed, without "." or ".." or a trailing slash ("out/", "./out" and
// "$PWD/out" are one folder).
std::filesystem::path place_of(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path.empty() ? "." : path, ec);
  std::filesystem::path place = ec ? path : std::filesystem::weakly_canonical(absolute, ec);
  if (ec) place = absolute.lexically_normal();
  return !place.has_filename() && place.has_parent_path() ? place.parent_path() : place;
}

bool same_place(const std::filesystem::path& a, const std::filesystem::path& b) {
  return place_of(a) == place_of(b);
}

// Throws OutputError if the page `html` would take the place of the run's own files in `dir`:
// the folder itself or a folder that holds it (the page is a file: the run's folder could not
// be made, or the page not written once the frames are), or, inside the folder (`inside`), a
// name the run writes its data under, or its marker. The page would replace the data at the end
// of the run, or be cleared as the last run's output by the next one.
void check_page_place(const std::filesystem::path& html, const std::filesystem::path& dir,
                      bool inside) {
  const std::filesystem::path page = place_of(html), folder = place_of(dir);
  const auto [p, f] = std::mismatch(page.begin(), page.end(), folder.begin(), folder.end());
  if (p == page.end()) {
    throw OutputError(fmt::format(
        "--html {} is {} --out folder {}, and the page is a file beside the run's data; choose "
        "another --html, such as {}",
        html.string(), f == folder.end() ? "the" : "a folder that holds the", dir.string(),
        (dir / "view.html").string()));
  }
  const std::string name = html.filename().string();
  const bool own = name == kRunFolderMarker ||
                   (name != "view.html" && std::find(kRunOutputNames.begin(), kRunOutputNames.end(),
                                                     name) != kRunOutputNames.end());
  if (inside && own) {
    throw OutputError(fmt::format(
        "--html {} is the run's own {} in --out {}, and the page would replace it; choose "
        "another --html, such as {}",
        html.string(), name, dir.string(), (dir / "view.html").string()));
  }
}

}  // namespace

StopSignals::StopSignals() {
  if (g_stop_signals_alive++ > 0) return;
  ask_to_stop(0);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  // SA_RESETHAND: a second Ctrl-C ends the process, for a user who does not want to wait.
  sa.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &sa, &g_old_int);
  sigaction(SIGTERM, &sa, &g_old_term);
  // A file grown past the size limit (ulimit -f) is an error the writers report with the file's
  // name (EFBIG), not a signal that ends the process between two frames.
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, &g_old_xfsz);
}

StopSignals::~StopSignals() {
  if (--g_stop_signals_alive > 0) return;
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
  sigaction(SIGXFSZ, &g_old_xfsz, nullptr);
  ask_to_stop(0);
}

int StopSignals::received() {
  return stop_asked();
}

RunStopped::RunStopped(int signal, long step, long frames, long abandoned)
    : std::runtime_error(
          abandoned > 0 ? fmt::format("stopped by {} during step {}, given up part way",
                                      signal_name(signal), abandoned)
          : abandoned == 0
              ? fmt::format("stopped by {} before the first frame", signal_name(signal))
              : fmt::format("stopped by {} after step {}", signal_name(signal), step)),
      signal_(signal),
      step_(step),
      frames_(frames),
      abandoned_(abandoned) {}

RunReport run_scene(Scene& scene, const RunOutputs& outputs, const ProgressFn& progress) {
  StopSignals stop_signals;
  // Everything that can be found wrong with the outputs is found before the first step.
  const bool page = !outputs.html.empty();
  // A start past a float's range, in a file of floats: refused at its place in the scene.
  const bool npy = outputs.npy || scene.output.npy;
  const bool velocities = outputs.velocities || scene.output.velocities;
  for (const auto& [note, refused] : {std::pair{&scene.position_beyond_float, page || npy},
                                      std::pair{&scene.velocity_beyond_float, npy && velocities}}) {
    if (*note && refused)
      throw SceneError((*note)->source, (*note)->line, (*note)->column, (*note)->message);
  }
  // A page outside the folder is checked first, so that a bad --html creates no folder; a page
  // inside it is checked by RunFolder, before it clears anything there.
  const bool page_inside = page && same_place(outputs.html.parent_path(), outputs.dir);
  if (page) check_page_place(outputs.html, outputs.dir, page_inside);
  const PageFolderLock page_lock =
      page && !page_inside ? check_page_target(outputs.html, outputs.force) : PageFolderLock();
  RunFolder folder(outputs.dir, outputs.force,
                   page_inside ? outputs.html : std::filesystem::path());
  FrameWriter writer(folder.folder(), velocities, outputs.springs || scene.output.springs, npy,
                     scene.world.particles.size(), page);
  MeshExporter meshes(folder.folder(), "frames", outputs.obj, outputs.vtk);
  RunReport report;
  report.files = writer.files();

  const long total = scene.step_count();
  // A frame every 1/fps seconds: that many steps, rounded, at least one and at most the run's
  // steps (then the first and the last frame only). Clamped as a double: for a tiny fps,
  // 1 / (fps dt) is past what a long holds, or inf.
  const double frame_steps = std::round(1.0 / (scene.output.fps * scene.dt));
  const long steps_per_frame = !(frame_steps < static_cast<double>(std::max(total, 1L)))
                                   ? std::max(total, 1L)
                                   : std::max(1L, static_cast<long>(frame_steps));
  // The first frame, one every steps_per_frame steps, and the last if it falls between.
  const long frames = 1 + total / steps_per_frame + (total % steps_per_frame != 0 ? 1 : 0);
  ViewerRecorder viewer(scene.title, scene.source, frames);

  World& world = scene.world;
  long step = 0;
  long frame_step = 0;  // the step of the last frame written
  const auto write_frame = [&] {
    writer.write(world, report.frames, step);
    meshes.write(world, report.frames + 1);  // mesh files count from 1: frame_0001
    if (page) viewer.offer(world);
    ++report.frames;
    frame_step = step;
  };
  // The page is rewritten now and then during a long run, so that it is there whatever stops
  // the run; at most every half minute, and at most a twentieth of the time the run takes.
  Clock::time_point last_page = Clock::now();
  double page_seconds = 0.0;  // how long the last page took to write [s]
  const auto write_page = [&] {
    const Clock::time_point start = Clock::now();
    if (page_inside) {
      viewer.write(world, folder.folder(), outputs.html.filename().string());
    } else {
      viewer.write(world, outputs.html);
    }
    page_seconds = seconds_since(start);
    last_page = Clock::now();
  };
  // However the run ends, the page shows the frames written.
  const auto finish_after_error = [&] {
    if (!page) return;
    try {
      write_page();
    } catch (const std::exception&) {
      // The error that ended the run is the one to report; the old page is removed so that no
      // page of an earlier run stands beside these files.
      std::error_code ignored;
      std::filesystem::remove(outputs.html, ignored);
    }
  };

  const auto start = Clock::now();
  try {
    // A stop asked for during a long step (or the first frame's energy) gives it up part way
    // (clothlab/core/stop.hpp): the files keep the frames before it.
    try {
      const StopPoints points;
      write_frame();
    } catch (const StepAbandoned&) {
      throw RunStopped(StopSignals::received(), 0, 0, 0);
    }
    for (step = 1; step <= total; ++step) {
      // The steps up to the next frame (or to the end) at once, at most kRunStepsAtOnce: the engine
      // room may keep the state in its own layout between them (World::advance, the same bits).
      // A stop signal is looked at after them, a short while (a frame's steps) later at most.
      const long due =
          std::min({total, (step + steps_per_frame - 1) / steps_per_frame * steps_per_frame,
                    step + kRunStepsAtOnce - 1});
      const long steps_before = world.steps;
      try {
        const StopPoints points;
        world.advance(scene.dt, due - step + 1);
      } catch (const StepAbandoned&) {
        throw RunStopped(StopSignals::received(), frame_step, report.frames,
                         step + (world.steps - steps_before));
      } catch (const KernelAnswerError& error) {
        // An exercise's answer the engine could not use: the run stops as after a blow-up, at
        // the step that asked for it, with the frames before it.
        const long failed = step + (world.steps - steps_before);
        throw SimulationError(fmt::format("the run stopped in step {} (from t = {:.6g} s): {}",
                                          failed, world.t, error.what()),
                              failed, -1);
      }
      step = due;
      const bool frame_due = step % steps_per_frame == 0 || step == total;
      if (frame_due) write_frame();
      if (progress) progress(step, total);
      if (const int signal = StopSignals::received(); signal != 0) {
        if (!frame_due) write_frame();  // the state the user stopped at
        throw RunStopped(signal, step, report.frames);
      }
      if (page && frame_due && seconds_since(last_page) > std::max(30.0, 20.0 * page_seconds)) {
        write_page();
      }
    }
  } catch (const SimulationError& error) {
    // The page says why it ends where it does.
    viewer.stopped(error.what(), error.step(), error.particle());
    finish_after_error();
    throw;
  } catch (...) {
    finish_after_error();
    throw;
  }
  report.wall_seconds = seconds_since(start);
  report.steps = total;
  if (page) {
    write_page();
    report.files.push_back(outputs.html);
    report.page_note = viewer.sampling_note();
  }
  if (outputs.obj || outputs.vtk) report.files.push_back(outputs.dir / "frames");
  return report;
}

}  // namespace clothlab
