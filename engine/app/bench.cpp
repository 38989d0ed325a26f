// bench.cpp: `clothlab bench boundary` and `clothlab bench accuracy` (`bench speed` is in
// bench_speed.cpp).
//
// bench boundary:
// The engine's hot loops call the exercise kernels (gravity_force, symplectic_euler_step), which
// live in another file, exercises/ or solutions/. Without help from the compiler every particle
// would pay for two out-of-line calls and could not be vectorised. Link-time optimisation
// inlines the kernels across that boundary. This benchmark measures the engine's step against
// the same passes with the kernels' arithmetic written inline here, in one run, and prints the
// ratio: close to 1 means the boundary costs nothing.
//
// bench accuracy: the work-precision study of lesson 07 (analysis/accuracy.hpp): every
// integrator over a ladder of time steps, printed as a table, written as CSV and drawn as a
// log-log plot by a small matplotlib script written next to the CSV.
#include "app/bench.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "analysis/accuracy.hpp"
#include "app/build_info.hpp"
#include "app/grade/text.hpp"
#include "app/process.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/euler.hpp"
#include "clothlab/integrators/methods.hpp"
#include "io/files.hpp"
#include "scene/scene.hpp"

extern char** environ;

namespace clothlab::app {

extern const std::string_view kPlotScript;

namespace {

namespace fs = std::filesystem;

// bench boundary's most particles: as many as bench speed's largest cloth (--sizes 2048), about
// 1.2 GB for its three worlds. A count past what the machine holds would otherwise allocate
// until the system refuses, after a long while and with no figure to show for it.
constexpr Index kMaxBoundaryParticles = Index{2048} * 2048;

World make_world(Index n) {
  World world;
  for (Index i = 0; i < n; ++i) {
    world.particles.add(Vec3(0.001 * i, 1000.0, 0.0), Vec3(1.0, 0.0, 0.0), 0.5 + 1e-3 * i);
  }
  world.force_effects.push_back(std::make_unique<UniformGravity>(Vec3(0, -9.8, 0)));
  world.integrator = std::make_unique<SymplecticEuler>();
  world.guard.max_position = 1e12;
  return world;
}

// The engine's step, pass for pass, with the kernels' arithmetic written inline in this file:
// clear the forces, add gravity, move with symplectic Euler, run the guard's checks.
void inline_step(Particles& p, const Vec3& g, double dt, const Guard& guard) {
  p.f.setZero();
  for (Index i = 0; i < p.size(); ++i)
    p.f.col(i) += p.m[i] * g;
  for (Index i = 0; i < p.size(); ++i) {
    p.v.col(i) += p.f.col(i) * p.inv_m[i] * dt;
    p.x.col(i) += p.v.col(i) * dt;
  }
  if (!(p.x.array().abs() <= guard.max_position).all() ||
      !(p.v.array().abs() <= guard.max_speed).all()) {
    throw std::runtime_error("bench: the inline world blew up");
  }
}

// What the same physics costs in one fused loop: a hint of what a data-oriented fast path can
// gain over the step a lesson reads (see lesson 01 and, later, the performance work).
void fused_step(Particles& p, const Vec3& g, double dt) {
  for (Index i = 0; i < p.size(); ++i) {
    p.v.col(i) += g * dt;  // f / m = m g / m = g
    p.x.col(i) += p.v.col(i) * dt;
  }
}

// Median over `repeats` of the wall time of `steps` calls to step(), in ns per particle-step.
template <class Step>
double measure(Index n, long steps, int repeats, Step step) {
  std::vector<double> samples;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    for (long s = 0; s < steps; ++s)
      step();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    samples.push_back(1e9 * seconds / (static_cast<double>(n) * static_cast<double>(steps)));
  }
  std::nth_element(samples.begin(), samples.begin() + repeats / 2, samples.end());
  return samples[static_cast<size_t>(repeats / 2)];
}

void bench_boundary(Index n, long steps, int repeats) {
  const double dt = 1e-4;
  World engine = make_world(n);
  World inline_world = make_world(n);
  World fused_world = make_world(n);
  const Vec3 g(0, -9.8, 0);
  const double t_engine = measure(n, steps, repeats, [&] { engine.step(dt); });
  const double t_inline =
      measure(n, steps, repeats, [&] { inline_step(inline_world.particles, g, dt, engine.guard); });
  const double t_fused =
      measure(n, steps, repeats, [&] { fused_step(fused_world.particles, g, dt); });
  // The two worlds took the same steps: their states must agree, or the figures compare
  // different work. (Equal to rounding: the compiler may order the arithmetic differently.)
  const double gap = (engine.particles.x - inline_world.particles.x).cwiseAbs().maxCoeff();

  fmt::print("bench boundary: {} particles, gravity + symplectic Euler, {} steps, median of {}\n",
             n, steps, repeats);
  fmt::print(
      "  engine step (kernels from {}, {}):  {:7.3f} ns per particle-step\n", kKernels,
      kLinkTimeOptimised ? "inlined by link-time optimisation" : "link-time optimisation off",
      t_engine);
  fmt::print("  the same passes, kernels written inline here:      {:7.3f} ns per particle-step\n",
             t_inline);
  fmt::print(
      "  ratio engine / inline: {:.2f}   (1.00 = the boundary costs nothing; largest "
      "position gap {:.3g} m)\n",
      t_engine / t_inline, gap);
  fmt::print(
      "  for scale, one fused loop (no force array, no guard): {:7.3f} ns, engine / fused "
      "{:.2f}\n",
      t_fused, t_engine / t_fused);
}

// --- bench accuracy ------------------------------------------------------------------------

struct AccuracyOptions {
  std::string scene;  // empty: the damped oscillator
  std::string out = "clothlab-out/accuracy";
  std::string plot;  // empty: OUT/work-precision.svg
  bool no_plot = false;
  bool force = false;  // replace files of the bench's names that it did not write
  std::vector<std::string> integrators;
  double time = 0.0;  // [s]; 0: the problem's default
  double zeta = 0.05;
  double min_seconds = 0.02;  // wall time each run is repeated for
  bool quick = false;
};

// "1.23e-04" or "-" for a number that is not one.
std::string sci(double value) {
  return std::isfinite(value) ? fmt::format("{:.2e}", value) : "-";
}

// The cheapest stable run of each target accuracy: what the study is for.
void print_cheapest(const std::vector<AccuracyRun>& runs) {
  fmt::print("\n  cheapest stable run reaching each error (wall time per simulated second):\n");
  for (double target : {1e-2, 1e-4, 1e-6, 1e-8}) {
    const AccuracyRun* best = nullptr;
    for (const AccuracyRun& run : runs) {
      if (!run.stable || !(run.error <= target)) continue;
      if (!best || run.wall_per_sim < best->wall_per_sim) best = &run;
    }
    if (best) {
      fmt::print("    error <= {:.0e}: {:<17} dt = {:<9.3g} {} s ({} force evaluations)\n", target,
                 best->integrator, best->dt, sci(best->wall_per_sim), sci(best->evals_per_sim));
    } else {
      fmt::print("    error <= {:.0e}: no run of the ladder reached it\n", target);
    }
  }
}

constexpr std::string_view kAccuracyCsv = "accuracy.csv";
constexpr std::string_view kAccuracyHeader =
    "problem,integrator,dt,steps,error,wall_s_per_sim_s,force_evals_per_sim_s,stable";

int bench_accuracy(const AccuracyOptions& opt) {
  // Where the results go, before the study's minutes are spent.
  const fs::path out_dir = opt.out;
  const fs::path plot = opt.plot.empty() ? out_dir / "work-precision.svg" : fs::path(opt.plot);
  check_bench_folder(out_dir, std::string(kAccuracyCsv), kAccuracyHeader, opt.force);
  if (!opt.no_plot) check_bench_plot(plot, std::string(kAccuracyCsv), kAccuracyHeader, opt.force);

  std::vector<std::string> integrators = opt.integrators;
  if (integrators.empty()) integrators.assign(integrator_names().begin(), integrator_names().end());

  std::unique_ptr<AccuracyProblem> problem;
  std::vector<double> dts;
  if (opt.scene.empty()) {
    const double end = opt.time > 0.0 ? opt.time : 4.0;
    problem = std::make_unique<DampedOscillatorProblem>(1.0, 100.0, opt.zeta, end);
    // 0.2 s (y = dt w = 2: past most methods' limits) halving down to about 1e-4 s.
    const int rungs = opt.quick ? 6 : 12;
    for (int k = 0; k < rungs; ++k)
      dts.push_back(0.2 / std::pow(2.0, k));
  } else {
    const Scene scene = load_scene_file(opt.scene);
    // From 8 times the scene's dt down to a quarter of it; the reference at dt / 32.
    const int rungs = opt.quick ? 3 : 6;
    for (int k = 0; k < rungs; ++k)
      dts.push_back(scene.dt * 8.0 / std::pow(2.0, k));
    // Without --time: as many whole steps of the longest dt as fit in min(duration, 0.5 s), at
    // least one. min(duration, 0.5 s) itself is rarely a whole number of them (0.5 s is 62.5
    // steps of lesson 02's 8 x 0.001 s), and the check below would blame a --time the user
    // never gave.
    const double longest = dts.front();
    const double end =
        opt.time > 0.0
            ? opt.time
            : longest * std::max(1.0, std::floor(std::min(scene.duration, 0.5) / longest + 1e-9));
    fmt::print("bench accuracy: running the RK4 reference of {} ...\n", opt.scene);
    problem = std::make_unique<SceneProblem>(opt.scene, end, scene.dt / 32.0);
  }
  // Every dt must cover the end time in whole steps.
  for (double dt : dts) {
    const double steps = problem->end_time() / dt;
    if (std::abs(steps - std::round(steps)) > 1e-9 * steps) {
      throw std::invalid_argument(fmt::format("--time {} s is not a whole number of steps of {} s",
                                              problem->end_time(), dt));
    }
  }

  fmt::print("bench accuracy: {}\n", problem->description());
  fmt::print("  {} integrators x {} time steps, each run repeated for {} s (fastest kept)\n\n",
             integrators.size(), dts.size(), opt.min_seconds);
  fmt::print("  {:<17} {:>9} {:>8} {:>9} {:>6} {:>13} {:>13}  {}\n", "integrator", "dt [s]",
             "steps", "error", "order", "wall s/sim s", "evals/sim s", "stable");
  const AccuracyRun* previous = nullptr;
  std::vector<AccuracyRun> runs;
  runs.reserve(integrators.size() * dts.size());
  const auto report = [&](const AccuracyRun& run) {
    runs.push_back(run);
    const AccuracyRun& here = runs.back();
    std::string order = "";
    if (previous && previous->integrator == here.integrator && previous->stable && here.stable) {
      const double p = observed_order(*previous, here);
      if (std::isfinite(p)) order = fmt::format("{:.2f}", p);
    }
    fmt::print("  {:<17} {:>9.3g} {:>8} {:>9} {:>6} {:>13} {:>13}  {}\n", here.integrator, here.dt,
               here.steps, sci(here.error), order, sci(here.wall_per_sim), sci(here.evals_per_sim),
               here.stable ? "yes" : (here.stopped.empty() ? "no" : "no (guard stopped it)"));
    previous = &runs.back();
  };
  run_accuracy_study(*problem, integrators, dts, opt.min_seconds, report);
  print_cheapest(runs);

  // The CSV, then the plot drawn from it.
  fs::create_directories(out_dir);
  const fs::path csv = out_dir / kAccuracyCsv;
  std::string table = std::string(kAccuracyHeader) + "\n";
  for (const AccuracyRun& run : runs) {
    fmt::format_to(std::back_inserter(table), "{},{},{:.17g},{},{:.17g},{:.17g},{:.17g},{}\n",
                   problem->name(), run.integrator, run.dt, run.steps, run.error, run.wall_per_sim,
                   run.evals_per_sim, run.stable ? "true" : "false");
  }
  write_whole_file(csv, table);
  const fs::path script = out_dir / "plot_accuracy.py";
  write_whole_file(script, kPlotScript);
  fmt::print("\n  wrote {} and {}\n", csv.string(), script.string());
  if (opt.no_plot) return 0;
  draw_plot(script, csv, plot);
  return 0;
}

// Runs `python3 script csv out` and prints what it printed; returns its exit status (127 when
// python3 cannot start). Debian's own python3 comes first: that is where `apt-get install
// python3-matplotlib` puts matplotlib, whatever other python3 comes first on the PATH.
int run_python(const fs::path& script, const fs::path& csv, const fs::path& out) {
  const ProcessResult run =
      run_process({fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3", script.string(),
                   csv.string(), out.string()},
                  600);
  fmt::print("{}", run.output);
  return run.timed_out || run.signal != 0 ? 1 : run.exit_code;
}

// Whether `file` starts with the line `line`; read without following a symbolic link.
bool first_line_is(const fs::path& file, std::string_view line) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return false;
  std::string head(line.size() + 1, '\0');
  size_t got = 0;
  while (got < head.size()) {
    const ssize_t n = ::read(fd, head.data() + got, head.size() - got);
    if (n <= 0) break;
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  return got == head.size() && head.substr(0, line.size()) == line && head.back() == '\n';
}

// Throws unless `path`, found and not a symbolic link, is a regular file.
void require_regular(const fs::path& path, const fs::file_status& status) {
  if (!fs::is_regular_file(status)) {
    throw OutputError(fmt::format("cannot write {}: it is {}", path.string(),
                                  fs::is_directory(status) ? "a folder" : "not a regular file"));
  }
}

}  // namespace

void check_bench_file(const fs::path& file, std::string_view option, std::string_view header,
                      bool force) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(file, ec);
  if (!fs::exists(status)) return;
  if (fs::is_symlink(status)) {
    // The CSV is made new under the link's name (io/files.hpp): the link goes, its file stays.
    if (force) return;
    throw OutputError(fmt::format(
        "{} is a symbolic link; choose another {}, or add --force to replace the link (the file "
        "it points to is left alone)",
        file.string(), option));
  }
  require_regular(file, status);
  if (force || first_line_is(file, header)) return;
  throw OutputError(
      fmt::format("{} exists and is not a CSV file this bench wrote (its first line is not the "
                  "bench's header); choose another {}, or add --force to replace it",
                  file.string(), option));
}

void check_bench_folder(const fs::path& dir, const std::string& csv, std::string_view header,
                        bool force) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(dir, ec);
  if (!fs::exists(status)) return;
  if (fs::is_symlink(status) && !force) {
    throw OutputError(
        fmt::format("--out {} is a symbolic link; choose another --out, or add --force to write "
                    "into the folder it points to",
                    dir.string()));
  }
  if (!fs::is_directory(fs::status(dir, ec))) {
    throw OutputError(fmt::format("cannot write into --out {}: it is not a folder", dir.string()));
  }
  if (force || fs::is_empty(dir, ec)) return;
  // A folder an earlier bench wrote holds its CSV; the user's folder, with a CSV of that name or
  // not, is not taken for one.
  const fs::path own = dir / csv;
  if (fs::is_regular_file(fs::symlink_status(own, ec)) && first_line_is(own, header)) return;
  throw OutputError(fmt::format(
      "--out {} is a folder this bench did not write (it holds no {} of the bench's); choose "
      "another --out (a new or empty folder), or add --force to write the bench's files there, "
      "replacing those of the same names",
      dir.string(), csv));
}

void check_bench_plot(const fs::path& plot, const std::string& csv, std::string_view header,
                      bool force) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(plot, ec);
  if (!fs::exists(status)) return;
  if (fs::is_symlink(status)) {
    if (force) return;
    throw OutputError(fmt::format(
        "--plot {} is a symbolic link; choose another --plot, or add --force to draw the plot "
        "through it",
        plot.string()));
  }
  require_regular(plot, status);
  if (force) return;
  const fs::path own = holding_folder(plot) / csv;
  if (fs::is_regular_file(fs::symlink_status(own, ec)) && first_line_is(own, header)) return;
  throw OutputError(
      fmt::format("--plot {} exists and is not a plot this bench drew (one lies beside the "
                  "bench's {}); choose another --plot, or add --force to replace it",
                  plot.string(), csv));
}

void add_bench_force_option(CLI::App& command, bool& force) {
  command.add_flag("--force", force,
                   "Replace files of the names the bench writes though it did not write them, and "
                   "write into a folder it did not make");
}

double wake_ns(int threads, int meetings, int wakes) {
  using Clock = std::chrono::steady_clock;
  ThreadTeam team(threads);
  double best = HUGE_VAL;
  for (int r = 0; r < 5; ++r) {
    const Clock::time_point start = Clock::now();
    for (int w = 0; w < wakes; ++w) {
      team.run([&](int) {
        for (int m = 0; m < meetings; ++m)
          team.sync();
      });
    }
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
  }
  return 1e9 * best / wakes;
}

void draw_plot(const fs::path& script, const fs::path& csv, const fs::path& plot) {
  const int status = run_python(script, csv, plot);
  if (status != 0) {
    fmt::print(stderr,
               "warning: the plot was not drawn ({}); the CSV is written. To draw it: sudo "
               "apt-get install -y python3-matplotlib, then python3 {} {} {}\n",
               status == 127 ? "python3 did not start" : "the plot script failed", script.string(),
               csv.string(), plot.string());
  }
}

void run_bench_command(std::string_view name, const std::function<int()>& body) {
  int status = 0;
  try {
    status = body();
  } catch (const SceneError& e) {
    std::fflush(stdout);
    fmt::print(stderr, "error: {}\n", grading::one_line(e.what()));
    status = 2;  // a bad scene, as for `clothlab run`
  } catch (const std::bad_alloc&) {
    std::fflush(stdout);
    fmt::print(stderr,
               "error: bench {}: not enough memory for the sizes asked for; expected fewer "
               "particles or smaller cloths\n",
               name);
    status = 1;
  } catch (const std::exception& e) {
    std::fflush(stdout);
    fmt::print(stderr, "error: bench {}: {}\n", name, grading::one_line(e.what()));
    status = 1;
  }
  if (status != 0) throw CLI::RuntimeError(status);
}

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Measure the engine (figures and ratios)");
  bench->require_subcommand(1);
  CLI::App* boundary = bench->add_subcommand(
      "boundary", "Engine step with exercise kernels vs the same loop written inline");
  static Index n = 10000;
  static long steps = 2000;
  static int repeats = 5;
  boundary->add_option("--particles", n, "Particles")
      ->check(CLI::Range(Index{1}, kMaxBoundaryParticles))
      ->capture_default_str();
  boundary->add_option("--steps", steps, "Steps per repeat")
      ->check(CLI::Range(1L, std::numeric_limits<long>::max()));
  boundary->add_option("--repeats", repeats, "Repeats (median is shown)")
      ->check(CLI::Range(1, std::numeric_limits<int>::max()));
  boundary->callback([] {
    run_bench_command("boundary", [] {
      bench_boundary(n, steps, repeats);
      return 0;
    });
  });

  add_bench_speed_command(*bench);

  static AccuracyOptions accuracy_options;
  AccuracyOptions& a = accuracy_options;
  CLI::App* accuracy = bench->add_subcommand(
      "accuracy",
      "Work-precision study: every integrator over a ladder of time steps, error against wall "
      "time (table, CSV and plot)");
  accuracy
      ->add_option("scene", a.scene,
                   "A scene to study (default: a damped oscillator with its exact solution)")
      ->check(CLI::ExistingFile);
  accuracy->add_option("--out", a.out, "Directory for accuracy.csv, the plot and its script")
      ->capture_default_str();
  accuracy->add_option("--plot", a.plot,
                       "Plot file (.svg, .png or .pdf; default OUT/work-precision.svg)");
  accuracy->add_flag("--no-plot", a.no_plot, "Write the CSV and the script, draw nothing");
  add_bench_force_option(*accuracy, a.force);
  accuracy->add_option("--integrators", a.integrators, "Integrators to compare (default: all)")
      ->delimiter(',')
      ->check(CLI::IsMember(
          std::vector<std::string>(integrator_names().begin(), integrator_names().end())));
  accuracy
      ->add_option("--time", a.time,
                   "End time [s] (default 4 s for the oscillator; for a scene, min(duration, "
                   "0.5 s) cut to whole steps of the longest time step, 8 x dt)")
      ->check(CLI::PositiveNumber);
  accuracy->add_option("--zeta", a.zeta, "The oscillator's damping ratio (0 <= zeta < 1)")
      ->check(CLI::Range(0.0, 0.999))
      ->capture_default_str();
  accuracy
      ->add_option("--min-seconds", a.min_seconds,
                   "Wall time [s] each run is repeated for; the fastest repeat is kept")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  accuracy->add_flag("--quick", a.quick, "A shorter ladder of time steps (for tests)");
  accuracy->callback(
      [] { run_bench_command("accuracy", [] { return bench_accuracy(accuracy_options); }); });

  add_bench_methods_command(*bench);
  add_bench_roofline_command(*bench);
}

}  // namespace clothlab::app
