// clothlab: the command line.
//
//   clothlab                          run the built-in demo scene
//   clothlab run SCENE.toml [--out D] simulate a scene and write its frames (--threads N)
//   clothlab validate SCENE.toml      check a scene without running it
//   clothlab repair DIR               cut a killed run's files back to their common frames
//   clothlab grade [...]              build and grade the exercises (see app/grade/)
//   clothlab watch [exNN[.k]]         grade again on every save of an exercise file
//   clothlab bench boundary           measure what the exercise boundary costs
//   clothlab bench speed              the engine's speed on cloths of 32^2 to 256^2 particles
//   clothlab bench accuracy [SCENE]   every integrator's error against its cost (lesson 07)
//   clothlab bench methods [SCENES]   lesson 12's bake-off of the methods on cloth
//
// The same code builds `clothlab` (reference solutions) and `clothlab-student` (your
// exercises); app::kKernels says which.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "analysis/run_cost.hpp"
#include "analysis/stability.hpp"
#include "app/bench.hpp"
#include "app/build_info.hpp"
#include "app/course.hpp"
#include "app/demo_scene.hpp"
#include "app/exit_codes.hpp"
#include "app/grade.hpp"
#include "app/grade/text.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/core/stop.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "fast/float_room.hpp"
#include "io/files.hpp"
#include "io/output.hpp"
#include "io/run.hpp"
#include "io/run_folder.hpp"
#include "scene/scene.hpp"

namespace fs = std::filesystem;
using namespace clothlab;

namespace {

// A progress bar on stderr, only when stderr is a terminal and the run lasts a moment: half a
// second, or the seconds in the environment variable CLOTHLAB_PROGRESS_AFTER (the tests set 0,
// so that a short run shows it too).
class ProgressBar {
 public:
  ProgressBar() : enabled_(isatty(STDERR_FILENO) != 0) {
    if (const char* after = std::getenv("CLOTHLAB_PROGRESS_AFTER")) after_ = std::atof(after);
  }
  void operator()(long done, long total) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    // Nothing for a run that ends within half a second; then at most ten updates a second.
    if (elapsed < after_) return;
    if (done != total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    shown_ = true;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * done / total);
    fmt::print(stderr, "\r[{:=<{}}{:<{}}] {:3}%  {:.0f} steps/s", "", filled, "", kWidth - filled,
               100 * done / total, done / std::max(elapsed, 1e-9));
    if (done == total) fmt::print(stderr, "\n");
  }
  bool shown() const { return shown_; }

 private:
  bool enabled_;
  double after_ = 0.5;  // [s] of wall time before the bar shows
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_ = start_;
};

// Text from a scene or the command line (a title, a key, a path) as a message shows it, on one
// line, as the grader shows a name: control characters in caret notation ("^[" for an escape),
// a line break or tab as \n or \t, so that nothing a scene says can move the cursor or start a
// line.
std::string shown(const std::string& text) {
  return app::grading::one_line(text);
}

std::string particle_count(const Scene& scene) {
  const Index n = scene.world.particles.size();
  return fmt::format("{} particle{}", n, n == 1 ? "" : "s");
}

// The --stats table: where the time of the run went, effect by effect (only those in play).
void print_stats(const World& world, const StepTimes& times) {
  double total = times.integrator + times.guard + times.backend_forces + times.backend_steps;
  for (double s : times.force_effects)
    total += s;
  for (double s : times.post_step_effects)
    total += s;
  const auto row = [&](std::string_view name, double seconds) {
    fmt::print("    {:<24} {:9.4f} s {:5.1f} %\n", name, seconds,
               total > 0 ? 100.0 * seconds / total : 0.0);
  };
  fmt::print("  time per part of the step (--stats):\n");
  // An effect the fast path took whole has no time of its own: it is not listed.
  const bool fast = times.backend_steps > 0 || times.backend_forces > 0;
  for (size_t k = 0; k < times.force_effects.size(); ++k) {
    if (!fast || times.force_effects[k] > 0)
      row(world.force_effects[k]->name(), times.force_effects[k]);
  }
  for (size_t k = 0; k < times.post_step_effects.size(); ++k) {
    if (!fast || times.post_step_effects[k] > 0)
      row(world.post_step_effects[k]->name(), times.post_step_effects[k]);
  }
  // What the fast engine (World::backend) took: its passes sum every effect at once, so they
  // are timed as a whole. `--readable` times each effect on its own instead.
  if (times.backend_steps > 0) row("fast path: whole steps", times.backend_steps);
  if (times.backend_forces > 0) row("fast path: force sums", times.backend_forces);
  if (fast) fmt::print("    (the fast path sums every effect at once; --readable times each)\n");
  row(fmt::format("{} (own)", world.integrator->name()), times.integrator);
  row("guard", times.guard);
  fmt::print("  force evaluations: {} ({} per step)\n", world.force_evaluations,
             world.integrator->force_evaluations_per_step());
  if (const auto* implicit = dynamic_cast<const ImplicitEuler*>(world.integrator.get())) {
    const LinearSolveStats& s = implicit->stats();
    fmt::print(
        "  linear solves: {}, conjugate-gradient iterations {:.1f} per solve (most {}), "
        "largest relative residual {:.2g}\n",
        s.solves, s.solves > 0 ? static_cast<double>(s.iterations) / s.solves : 0.0,
        s.max_iterations, s.worst_error);
  }
}

// After a run with the implicit integrator: say so if some linear solves stopped early.
void warn_unconverged(const World& world) {
  const auto* implicit = dynamic_cast<const ImplicitEuler*>(world.integrator.get());
  if (!implicit || implicit->stats().unconverged == 0) return;
  const LinearSolveStats& s = implicit->stats();
  fmt::print(stderr,
             "warning: {} of {} linear solves stopped at max_iterations = {} with a relative "
             "residual up to {:.2g} (tolerance {:.2g}); raise max_iterations in [integrator] or "
             "take a smaller dt\n",
             s.unconverged, s.solves, implicit->max_iterations, s.worst_error, implicit->tolerance);
}

// The scene reader's warnings: inputs that run but are likely mistakes, each with FILE:LINE:COL;
// then what the run will cost, where a part of it will take long or its files be big.
void print_scene_warnings(const Scene& scene, bool velocities, bool springs, bool npy) {
  std::fflush(stdout);  // after what was printed before them
  for (const SceneWarning& warning : scene.warnings)
    fmt::print(stderr, "warning: {}\n", shown(warning.text()));
  for (const std::string& cost : run_cost_warnings(scene, velocities, springs, npy))
    fmt::print(stderr, "warning: {}\n", shown(cost));
}

int run(Scene& scene, const RunOutputs& outputs, bool stats) {
  // The folder as a user reads it: "out/" and "./out" are "out".
  fs::path out_dir = outputs.dir.lexically_normal();
  if (!out_dir.has_filename() && out_dir.has_parent_path()) out_dir = out_dir.parent_path();
  StepTimer timer;
  if (stats) timer.attach(scene.world);
  fmt::print("clothlab ({} build): {}{}\n", app::kKernels, shown(scene.source),
             scene.title.empty() ? "" : " - " + shown(scene.title));
  fmt::print("  {}; {}; dt = {} s for {} s ({} steps)\n", particle_count(scene),
             scene.world.effects_in_play(), scene.dt, scene.duration, scene.step_count());
  print_scene_warnings(scene, outputs.velocities || scene.output.velocities,
                       outputs.springs || scene.output.springs, outputs.npy || scene.output.npy);
  // The start-up work can take long too ([gravitation]'s energy of a big cloth): a signal
  // during it stops the run before anything is written (clothlab/core/stop.hpp).
  double energy_start = 0.0;
  TimeStepAdvice advice;
  try {
    const StopPoints points;
    energy_start = scene.world.kinetic_energy() + scene.world.potential_energy();
    // The time-step advisor speaks before the run, so a user who sees it blow up knows why.
    advice = advise_time_step(scene.world, scene.dt, scene.step_count());
  } catch (const StepAbandoned&) {
    fmt::print(stderr, "stopped by SIG{} before the first step; nothing was written\n",
               sigabbrev_np(StopSignals::received()));
    return app::kExitInterrupted;
  }
  if (!advice.warning.empty()) {
    std::fflush(stdout);
    fmt::print(stderr, "warning: {}\n", advice.warning);
  }
  ProgressBar bar;
  const auto progress = [&](long done, long total) { bar(done, total); };
  // Where the frames are, for a run that ended early.
  const auto frames_are_in = [&] {
    std::error_code ec;
    const bool page = !outputs.html.empty() && fs::exists(outputs.html, ec);
    return fmt::format(
        "{}/{}", shown(out_dir.string()),
        page ? fmt::format(" and the page {} shows them", shown(outputs.html.string()))
             : std::string());
  };
  const auto end_bar = [&] {
    std::fflush(stdout);  // what was said before the error comes before it
    if (bar.shown()) fmt::print(stderr, "\n");
  };
  try {
    const RunReport report = run_scene(scene, outputs, progress);
    const double energy_end = scene.world.kinetic_energy() + scene.world.potential_energy();
    fmt::print("  done: {} steps in {:.3f} s; total energy {:.6g} J -> {:.6g} J\n", report.steps,
               report.wall_seconds, energy_start, energy_end);
    fmt::print("  wrote {} frames to {}/: ", report.frames, shown(out_dir.string()));
    for (const fs::path& file : report.files) {
      const bool inside = file.parent_path().lexically_normal() == out_dir;
      fmt::print("{} ", shown(inside ? file.filename().string() : file.string()));
    }
    fmt::print("\n");
    if (!outputs.html.empty()) {
      fmt::print("  watch it: open {} in a browser\n", shown(outputs.html.string()));
      if (!report.page_note.empty()) {
        fmt::print("  {}; the {} files have every frame\n", report.page_note,
                   outputs.npy || scene.output.npy ? "data" : "CSV");
      }
    }
    if (stats) print_stats(scene.world, timer.times);
    warn_unconverged(scene.world);
    return 0;
  } catch (const SimulationError& error) {
    end_bar();
    fmt::print(stderr, "error: {}\n", shown(error.what()));
    if (error.step() <= 0) {
      fmt::print(stderr, "  no frame was written\n");
    } else {
      fmt::print(stderr, "  frames up to step {} are in {}\n", error.step() - 1, frames_are_in());
    }
    return app::kExitBlewUp;
  } catch (const RunStopped& stop) {
    end_bar();
    if (stop.abandoned() < 0) {
      fmt::print(stderr, "{} (t = {:.6g} s): {} frames, the last at that step, are in {}\n",
                 stop.what(), scene.world.t, stop.frames(), frames_are_in());
    } else if (stop.frames() == 0) {
      fmt::print(stderr, "{}; no frame was written\n", stop.what());
    } else {
      fmt::print(stderr, "{}: {} frames, the last after step {}, are in {}\n", stop.what(),
                 stop.frames(), stop.step(), frames_are_in());
    }
    return app::kExitInterrupted;
  } catch (const OutputError& error) {
    end_bar();
    fmt::print(stderr, "error: {}\n", shown(error.what()));
    // The steps the world took: the frame of the last of them may be the one that failed.
    const long steps_done = scene.world.steps;
    if (steps_done == 0) {
      fmt::print(stderr, "  nothing was run\n");
      return app::kExitBadInput;
    }
    fmt::print(stderr, "  the run stopped after step {}; the frames before it are whole in {}\n",
               steps_done, frames_are_in());
    return app::kExitFailed;
  }
}

// <name> for the reference build, <name>-student for the student's, so that the two runs of one
// scene can be compared side by side.
std::string build_folder_name(const std::string& name) {
  return name + (std::string(app::kKernels) == "student" ? "-student" : "");
}

// clothlab-out/<scene's folder>/<scene>/ (with -student for the student build): the folder's
// name keeps apart two scenes of one file name, as lessons 12 and 13 both ship hanging-mass.toml,
// so that a run of one never replaces the other's (clothlab-out/12-xpbd/hanging-mass/).
fs::path default_out_dir(const std::string& scene_path) {
  const fs::path scene = fs::absolute(scene_path).lexically_normal();
  return fs::path("clothlab-out") / scene.parent_path().filename() /
         build_folder_name(scene.stem().string());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"clothlab: learn cloth simulation step by step, and run the engine on scenes"};
  app.require_subcommand(0, 1);

  std::string scene_path;
  std::string out_dir;
  CLI::App* run_cmd = app.add_subcommand("run", "Simulate a scene and write its frames");
  run_cmd->add_option("scene", scene_path, "Scene file (.toml)")->required();
  run_cmd->add_option("--out", out_dir,
                      "Output folder (default: clothlab-out/<scene's folder>/<scene name>, or "
                      "clothlab-out/<scene's folder>/<scene name>-student for clothlab-student)");
  std::string html;
  bool no_html = false, obj = false, vtk = false, stats = false;
  run_cmd->add_option("--html", html, "Viewer page to write (default: <output folder>/view.html)");
  run_cmd->add_flag("--no-html", no_html, "Write no viewer page");
  std::string format = "csv";
  run_cmd
      ->add_option("--format", format,
                   "csv: positions.csv (every bit of each double); npy: positions.npy, 32-bit "
                   "floats, a fifth of the size, for big runs (as [output] format)")
      ->check(CLI::IsMember({"csv", "npy"}));
  bool force = false;
  run_cmd->add_flag("--force", force,
                    "Write into an output folder that is not clothlab's (files named as its "
                    "outputs are replaced), or over a --html file that is not a viewer page");
  run_cmd->add_flag("--obj", obj, "Also write an OBJ sequence to <output folder>/frames/");
  run_cmd->add_flag("--vtk", vtk, "Also write a VTK series to <output folder>/frames/");
  bool velocities = false, springs = false;
  run_cmd->add_flag("--velocities", velocities,
                    "Also write velocities.csv (as [output] velocities = true)");
  run_cmd->add_flag("--springs", springs,
                    "Also write springs.csv, each spring's strain and tension (as [output] "
                    "springs = true)");
  run_cmd->add_flag("--stats", stats,
                    "Print the time spent in each part of the step, on the path that runs");
  bool readable = false;
  run_cmd->add_flag("--readable", readable,
                    "Take the lecture's path alone, without the fast path (as [engine] fast_path "
                    "= false): the same result, slower; --stats then times each effect");
  bool use_float = false;
  run_cmd->add_flag("--float", use_float,
                    "Step in single precision in the engine room (as [engine] precision = "
                    "\"float\"): the Euler methods with gravity, springs, bending, damping, "
                    "aerodynamics, contacts and moving pins; close to the double run, not its "
                    "bits");
  int threads = -1;
  run_cmd
      ->add_option("--threads", threads,
                   "Threads a step may use (default: [engine] threads in the scene, or 1; 0: "
                   "every core). The result does not depend on it")
      ->check(CLI::Range(0, 1024));

  std::string validate_path;
  CLI::App* validate_cmd = app.add_subcommand("validate", "Check a scene without running it");
  validate_cmd->add_option("scene", validate_path, "Scene file (.toml)")->required();

  std::string repair_dir;
  CLI::App* repair_cmd = app.add_subcommand(
      "repair", "Cut a killed run's files back to the frames all of them hold (README: a SIGKILL)");
  repair_cmd->add_option("folder", repair_dir, "The run's output folder")->required();

  app::add_grade_command(app);
  app::add_watch_command(app);
  app::add_bench_command(app);
  app::add_course_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (*run_cmd) {
      // Ctrl-C and TERM stop the run cleanly from here on, the start-up work included.
      const StopSignals stop_signals;
      Scene scene = load_scene_file(scene_path);
      RunOutputs outputs =
          RunOutputs::in(out_dir.empty() ? default_out_dir(scene_path) : fs::path(out_dir));
      if (!html.empty()) outputs.html = html;
      if (no_html) outputs.html.clear();
      outputs.obj = obj;
      outputs.vtk = vtk;
      outputs.velocities = velocities;
      outputs.springs = springs;
      // A default folder, clothlab-out/<folder>/<scene>, holding only what a run writes is taken as
      // clothlab's even without a marker: it is what a version before the marker left.
      outputs.npy = format == "npy";
      outputs.force = force || (out_dir.empty() && holds_only_run_outputs(outputs.dir));
      if (threads >= 0)
        scene.world.threads = threads > 0 ? threads : ThreadTeam::hardware_threads();
      if (readable) scene.world.backend.reset();
      if (use_float) {
        if (const std::string why = fast::use_float(scene.world); !why.empty()) {
          fmt::print(stderr, "error: --float: {}\n", why);
          return app::kExitBadInput;  // as a scene the run cannot take
        }
      }
      return run(scene, outputs, stats);
    }
    if (*validate_cmd) {
      const Scene scene = load_scene_file(validate_path);
      fmt::print("{}: ok: {}; {}; dt = {} s for {} s ({} steps)\n", shown(validate_path),
                 particle_count(scene), scene.world.effects_in_play(), scene.dt, scene.duration,
                 scene.step_count());
      print_scene_warnings(scene, scene.output.velocities, scene.output.springs, scene.output.npy);
      // A run refuses these where it would write them to a file of floats (run_scene).
      for (const auto& note : {scene.position_beyond_float, scene.velocity_beyond_float}) {
        if (note) fmt::print(stderr, "warning: {}\n", shown(note->text()));
      }
      const TimeStepAdvice advice = advise_time_step(scene.world, scene.dt, scene.step_count());
      if (advice.bounds.omega_max > 0.0) {
        fmt::print("  stiffest mode: w <= {:.4g} rad/s; stable time step for {}: {}\n",
                   advice.bounds.omega_max, scene.world.integrator->name(),
                   describe_dt_limit(advice.dt_limit));
      }
      if (!advice.warning.empty()) {
        std::fflush(stdout);
        fmt::print(stderr, "warning: {}\n", advice.warning);
      }
      return 0;
    }
    if (*repair_cmd) {
      long frames = 0;
      try {
        frames = cut_to_common_frames(repair_dir);
      } catch (const OutputError& error) {
        // A folder that is not a run's, or a file it cannot read: refused, as a run refuses a
        // folder of the user's, before anything is cut.
        fmt::print(stderr, "error: {}\n", shown(error.what()));
        return app::kExitBadInput;
      }
      if (frames == 0) {
        fmt::print("{}: every file holds no frame, only its header\n", shown(repair_dir));
      } else {
        fmt::print("{}: every file holds frames 0 to {} ({} frames)\n", shown(repair_dir),
                   frames - 1, frames);
      }
      return 0;
    }
    if (app.get_subcommands().empty()) {
      // No command: the demo, so that a first run shows something move.
      Scene scene = parse_scene(app::kDemoScene, app::kDemoSceneSource);
      RunOutputs outputs = RunOutputs::in(fs::path("clothlab-out") / build_folder_name("demo"));
      outputs.force = holds_only_run_outputs(outputs.dir);
      return run(scene, outputs, false);
    }
  } catch (const SceneError& error) {
    std::fflush(stdout);
    fmt::print(stderr, "error: {}\n", shown(error.what()));
    return app::kExitBadInput;
  } catch (const NotImplemented& error) {
    std::fflush(stdout);
    fmt::print(stderr, "error: {}\n", shown(error.what()));
    return app::kExitNotDone;
  } catch (const std::exception& error) {
    fmt::print(stderr, "error: {}\n", shown(error.what()));
    return app::kExitFailed;
  }
  return 0;
}
