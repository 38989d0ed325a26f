// bench_methods.cpp: `clothlab bench methods`, lesson 12's bake-off of the methods on cloth.
//
// Each scene runs under every method over a ladder of settings: symplectic Euler and RK4 from
// the largest step the stability advisor allows (lesson 08) down, implicit Euler from one step a
// frame down, XPBD at one step a frame with more and more substeps or iterations, the
// local/global solver, and Vertex Block Descent (lesson 14) at one sweep a step and ten. Every run
// is compared, frame by frame, with a reference of the same spring model: RK4 at a step far below
// its stability limit. The reference is run twice, at dt_ref and dt_ref / 2, and the difference
// between the two is printed beside the methods' errors: the reference has converged where that
// difference is far below them.
//
// For each run: the error (the particles' root-mean-square distance from the reference over
// all frames, relative to the cloth's size), the worst strain |l - l0| / l0 of a structural or
// shear spring at any frame, the energy lost against the reference by the end (relative to the
// largest kinetic energy the reference reached: 1 is all the motion the cloth ever had), and the
// wall time per simulated second (fastest repeat). A
// CSV, and a plot per scene drawn by a small matplotlib script written next to it.
//
// `--speed`: on cloths of 64 x 64, 128 x 128 and 256 x 256 particles, on 1 and 2 threads, what
// a symplectic Euler step, an XPBD iteration and a local/global iteration cost per spring, each
// on the readable path (no backend) and in the engine room (engine/fast/), measured in the same
// run, and the targets beside the ratios. Beside each target, what bounds it, measured in
// the same run: for an XPBD iteration, the engine room's same passes with no square root or
// division (FastEngine::xpbd_access_passes: the gathers and scatters alone); for local/global,
// its solve alone; for two threads, the wakes of the threads (barriers) a step or an iteration
// makes, counted, at the cost of a wake with nothing to do, and a stream's own speed-up.
//
// Implicit Euler's rows: ns per spring per conjugate-gradient iteration, readable and engine
// room, with the iterations per step, and a streaming pass over as many bytes as the bound.
//
// Vertex Block Descent's rows (lesson 14), readable and engine room: a step of one iteration and
// an iteration, ns per spring and per vertex, against the engine room's symplectic Euler step of
// the same run, and against an XPBD iteration.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>
#include <Eigen/CholmodSupport>

#include "analysis/stability.hpp"
#include "app/bench.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "fast/engine.hpp"
#include "io/files.hpp"
#include "scene/scene.hpp"

namespace clothlab::app {

extern const std::string_view kPlotScript;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFrame = 1.0 / 60.0;  // [s]: errors are sampled once a frame of a 60 Hz game
constexpr int kLargeBelow = 8;  // the large cloths' reference: 8 times below its advised limit

struct MethodsOptions {
  std::vector<std::string> scenes;  // empty: lesson 12's three bake-off scenes (or large ones)
  bool large = false;               // the cloths of real size: 48 x 48, woven stiffness
  std::string reference;            // empty: rk4 (see reference_config)
  int reference_below = 0;          // 0: the default factor below the advised limit
  std::string out = "clothlab-out/methods";
  std::string plot;  // empty: OUT/methods.svg
  bool no_plot = false;
  bool force = false;  // replace files of the bench's names that it did not write
  bool quick = false;
  double min_seconds = 0.05;  // wall time each run is repeated for
  bool speed = false;
  std::vector<int> grids = {64, 128, 256};  // the speed measurement's cloths: N x N particles
};

// One setting of one method: its step is one frame over per_frame; substeps and iterations
// are written to [integrator] when they are not 0.
struct Config {
  std::string method;
  int per_frame = 1;
  int substeps = 0;
  int iterations = 0;
  double dt() const { return kFrame / per_frame; }
};

// A method's ladder, as data. Steps per frame are `base * factor`, where base is 1 or, for
// `from_limit`, the fewest steps a frame that the stability advisor calls stable; each rung runs
// with every (substeps, iterations) pair of `inner` ({0, 0}: the method has neither).
struct Ladder {
  std::string_view method;
  bool from_limit;
  std::vector<double> factors;
  std::vector<std::pair<int, int>> inner = {{0, 0}};
};

std::vector<Ladder> ladders(bool quick, bool large) {
  if (large && quick) {  // the wiring, in seconds: one rung of each method but RK4
    return {{"symplectic-euler", true, {1}},
            {"implicit-euler", false, {1}},
            {"xpbd", false, {1}, {{4, 1}}},
            {"local-global", false, {1}, {{0, 10}}},
            {"vbd", false, {1}, {{0, 1}}}};
  }
  if (large) {
    // A cloth of real size at a game's frame: the explicit methods need hundreds of steps a
    // frame, so their ladders are short (symplectic Euler's first rung, at twice the advised
    // step, shows the limit is real); the large-step methods get the longer ladders.
    return {{"symplectic-euler", true, {0.5, 1, 2}},
            {"rk4", true, {1, 2}},
            {"implicit-euler", false, {1, 4, 16}},
            {"xpbd", false, {1}, {{1, 1}, {4, 1}, {16, 1}, {64, 1}, {1, 16}}},
            {"xpbd", false, {8}, {{8, 1}}},
            {"local-global", false, {1, 4, 16}, {{0, 10}}},
            {"vbd", false, {1, 4, 16}, {{0, 1}, {0, 10}}}};
  }
  if (quick) {
    return {{"symplectic-euler", true, {1, 2, 4}},
            {"rk4", true, {1, 2}},
            {"implicit-euler", false, {1, 4, 16}},
            {"xpbd", false, {1}, {{1, 1}, {8, 1}, {64, 1}, {1, 8}}},
            {"xpbd", false, {8}, {{8, 1}}},
            {"local-global", false, {1, 4}, {{0, 10}}},
            {"vbd", false, {1, 4}, {{0, 10}}}};
  }
  // Symplectic Euler's first rung takes twice the advised step, to show where it fails.
  return {
      {"symplectic-euler", true, {0.5, 1, 2, 4, 8}},
      {"rk4", true, {1, 2, 4}},
      {"implicit-euler", false, {1, 2, 4, 8, 16, 32}},
      {"xpbd", false, {1}, {{1, 1}, {4, 1}, {16, 1}, {64, 1}, {256, 1}, {1, 4}, {1, 16}, {1, 64}}},
      // 64 substeps a frame again, in 8 steps of 8: colliders act after every substep either
      // way (world.hpp's substep contract); the effects that act once a step see 8 steps.
      {"xpbd", false, {8}, {{8, 1}}},
      {"local-global", false, {1, 2, 4, 8, 16}, {{0, 10}}},
      // Vertex Block Descent (lesson 14): one sweep a step, and ten.
      {"vbd", false, {1, 2, 4, 8, 16}, {{0, 1}, {0, 10}}}};
}

bool engine_has(std::string_view method) {
  const auto names = method_names();
  return std::find(names.begin(), names.end(), method) != names.end();
}

// A scene file and what every run of it shares.
struct BakeoffScene {
  std::string path;
  toml::table table;  // the file, whose [integrator] each run replaces
  int frames = 0;     // the run's length in frames
  double size = 1.0;  // the diagonal of the particles' bounding box at the start [m]
};

BakeoffScene read_bakeoff_scene(const std::string& path, int max_frames) {
  BakeoffScene scene;
  scene.path = path;
  const Scene loaded = load_scene_file(path);  // the scene's own errors, with lines and columns
  scene.table = toml::parse_file(path);
  scene.frames = std::clamp(static_cast<int>(std::lround(loaded.duration / kFrame)), 1, max_frames);
  const Matrix3X& x0 = loaded.world.particles.x;
  const double diagonal = (x0.rowwise().maxCoeff() - x0.rowwise().minCoeff()).norm();
  scene.size = diagonal > 0.0 ? diagonal : 1.0;
  return scene;
}

// The scene's world, stepped by `config`: its file with [integrator] written anew. (Through the
// scene reader, so a method's own keys, such as `iterations`, mean what they mean in a scene.)
World make_world(const BakeoffScene& scene, const Config& config) {
  toml::table table = scene.table;
  toml::table integrator{
      {"method", config.method}, {"dt", config.dt()}, {"duration", scene.frames * kFrame}};
  if (config.substeps > 0) integrator.insert("substeps", config.substeps);
  if (config.iterations > 0) integrator.insert("iterations", config.iterations);
  table.insert_or_assign("integrator", std::move(integrator));
  std::ostringstream text;
  text << table;
  return std::move(parse_scene(text.str(), scene.path).world);
}

// The fewest steps a frame at which the advisor calls `method` stable on the scene at rest.
int advised_per_frame(const BakeoffScene& scene, std::string_view method) {
  const World world = make_world(scene, Config{std::string(method)});
  const double limit = advise_time_step(world, kFrame, scene.frames).dt_limit;
  if (!(limit > 0.0) || !std::isfinite(limit)) return 1;
  return std::max(1, static_cast<int>(std::ceil(kFrame / limit)));
}

// The largest |l - l0| / l0 of the structural and shear springs.
double worst_strain(const World& world) {
  double worst = 0.0;
  for (const auto& effect : world.force_effects) {
    if (effect->name() != "springs") continue;
    const SpringSet& s = dynamic_cast<const SpringDampers&>(*effect).springs();
    for (size_t k = 0; k < s.size(); ++k) {
      const double l = (world.particles.x.col(s.i(k)) - world.particles.x.col(s.j(k))).norm();
      if (s.l0(k) > 0.0) worst = std::max(worst, std::abs(l - s.l0(k)) / s.l0(k));
    }
  }
  return worst;
}

// What a run leaves at each frame (frame 0 is the start).
struct Trajectory {
  std::vector<Matrix3X> x;
  std::vector<double> energy;   // kinetic + potential [J]
  std::vector<double> kinetic;  // [J]
  double worst_strain = 0.0;
  double seconds = 0.0;  // wall time of the steps alone
  std::string stopped;   // the guard's message when it stopped the run
};

Trajectory simulate(const BakeoffScene& scene, const Config& config, bool record) {
  Trajectory run;
  World world = make_world(scene, config);
  const double dt = config.dt();
  const auto sample = [&] {
    if (!record) return;
    run.x.push_back(world.particles.x);
    run.kinetic.push_back(world.kinetic_energy());
    run.energy.push_back(run.kinetic.back() + world.potential_energy());
    run.worst_strain = std::max(run.worst_strain, worst_strain(world));
  };
  sample();
  try {
    for (int f = 0; f < scene.frames; ++f) {
      const Clock::time_point start = Clock::now();
      for (int s = 0; s < config.per_frame; ++s)
        world.step(dt);
      run.seconds += std::chrono::duration<double>(Clock::now() - start).count();
      sample();
    }
  } catch (const SimulationError& e) {
    run.stopped = e.what();
  }
  return run;
}

// The particles' RMS distance between two runs over every frame after the start, relative to
// the scene's size; NaN when a run stopped early.
double difference(const Trajectory& run, const Trajectory& reference, double size) {
  if (run.x.size() != reference.x.size() || run.x.size() < 2) return kNaN;
  double sum = 0.0;
  Index count = 0;
  for (size_t f = 1; f < run.x.size(); ++f) {
    sum += (run.x[f] - reference.x[f]).colwise().squaredNorm().sum();
    count += run.x[f].cols();
  }
  return std::sqrt(sum / static_cast<double>(count)) / size;
}

struct MethodRun {
  std::string scene;
  Config config;
  double error = kNaN, worst_strain = kNaN, energy_lost = kNaN;
  double wall_per_sim = kNaN;  // [s per simulated s], fastest repeat
  long steps = 0;              // steps over the run
  bool stable = false;
  bool reference = false;  // the reference's row: its error is its own difference at dt / 2
};

// "1.23e-04" or "-" for a number that is not one.
std::string sci(double value) {
  return std::isfinite(value) ? fmt::format("{:.2e}", value) : "-";
}

std::string setting(const Config& c) {
  std::string text;
  if (c.substeps > 0) text += fmt::format("{} substeps", c.substeps);
  if (c.iterations > 0) text += fmt::format("{}{} it", text.empty() ? "" : " x ", c.iterations);
  return text.empty() ? "-" : text;
}

void print_row(const MethodRun& r) {
  fmt::print("  {:<17} {:>9.3g} {:>19} {:>9} {:>9} {:>9} {:>12}  {}\n",
             r.reference ? fmt::format("reference ({})", r.config.method) : r.config.method,
             r.config.dt(), setting(r.config), sci(r.error), sci(r.worst_strain),
             sci(r.energy_lost), sci(r.wall_per_sim),
             r.reference ? "its own difference at dt/2" : (r.stable ? "yes" : "no"));
}

// The reference's method and step: `--reference` (default RK4) at a step `--reference-below`
// times below its advised limit. On the small cloths that is 128 (--quick: 16): 16 (4) times
// below the finest rung of the ladders, that far because a scene's wind and colliders make
// every method first order (see the lesson). On the large cloths a step costs 20 times more (8930
// springs against 440) and the advised step is 9 times smaller, so 128 would cost 180 times the
// small sheet's reference a simulated second: kLargeBelow is 8, still 4 times below the finest
// rung of RK4 and symplectic Euler. --quick --large, one frame to check the
// wiring, takes 2. Either way the bench runs the reference again at half its step and prints
// the difference: the reference has converged where that is far below every method's error.
Config reference_setting(const BakeoffScene& scene, const MethodsOptions& opt) {
  int below = opt.reference_below;
  if (below == 0) below = opt.large ? (opt.quick ? 2 : kLargeBelow) : (opt.quick ? 16 : 128);
  const std::string method = opt.reference.empty() ? "rk4" : opt.reference;
  return Config{method, below * advised_per_frame(scene, method)};
}

// Every run of one scene, the reference first.
std::vector<MethodRun> bake_off(const std::string& path, const MethodsOptions& opt) {
  // --quick: half a second at most; with --large, one frame.
  const BakeoffScene scene = read_bakeoff_scene(path, opt.quick ? (opt.large ? 1 : 30) : 1'000'000);
  const double sim_seconds = scene.frames * kFrame;
  fmt::print("\nscene {}: {} frames of 1/60 s ({:.3g} s), size {:.3g} m\n", path, scene.frames,
             sim_seconds, scene.size);

  const Config reference_config = reference_setting(scene, opt);
  const Trajectory reference = simulate(scene, reference_config, true);
  const Trajectory finer =
      simulate(scene, Config{reference_config.method, 2 * reference_config.per_frame}, true);
  if (!reference.stopped.empty()) {
    throw std::runtime_error(fmt::format("the {} reference of {} at dt = {:.3g} s stopped: {}",
                                         reference_config.method, path, reference_config.dt(),
                                         reference.stopped));
  }
  // The scale of the energy lost: the most kinetic energy the reference had at a frame [J].
  double motion = *std::max_element(reference.kinetic.begin(), reference.kinetic.end());
  if (!(motion > 0.0)) motion = 1.0;

  fmt::print("  energy lost is relative to {:.3g} J, the reference's largest kinetic energy\n",
             motion);
  std::vector<MethodRun> runs;
  MethodRun ref_row{path, reference_config};
  ref_row.reference = true;
  ref_row.steps = static_cast<long>(scene.frames) * reference_config.per_frame;
  ref_row.error = difference(finer, reference, scene.size);
  ref_row.worst_strain = reference.worst_strain;
  ref_row.energy_lost = 0.0;
  ref_row.wall_per_sim = reference.seconds / sim_seconds;
  ref_row.stable = true;
  fmt::print("  {:<17} {:>9} {:>19} {:>9} {:>9} {:>9} {:>12}  {}\n", "method", "dt [s]", "setting",
             "error", "strain", "E lost", "wall s/sim s", "stable");
  print_row(ref_row);
  runs.push_back(ref_row);

  for (const Ladder& ladder : ladders(opt.quick, opt.large)) {
    if (!engine_has(ladder.method)) continue;  // the local/global solver, before lesson 13
    const int base = ladder.from_limit ? advised_per_frame(scene, ladder.method) : 1;
    for (double factor : ladder.factors) {
      const int per_frame = static_cast<int>(std::lround(base * factor));
      if (per_frame < 1) continue;
      for (const auto& [substeps, iterations] : ladder.inner) {
        MethodRun row{path, Config{std::string(ladder.method), per_frame, substeps, iterations}};
        row.steps = static_cast<long>(scene.frames) * per_frame;
        const Trajectory run = simulate(scene, row.config, true);
        row.error = difference(run, reference, scene.size);
        row.stable = run.stopped.empty() && std::isfinite(row.error) && row.error < 1.0;
        if (run.stopped.empty()) {
          row.worst_strain = run.worst_strain;
          row.energy_lost = (reference.energy.back() - run.energy.back()) / motion;
          // The fastest of the repeats that fit in min_seconds (at most 100).
          double best = run.seconds, total = run.seconds;
          for (int r = 0; r < 100 && total < opt.min_seconds; ++r) {
            const double seconds = simulate(scene, row.config, false).seconds;
            best = std::min(best, seconds);
            total += seconds;
          }
          row.wall_per_sim = best / sim_seconds;
        }
        print_row(row);
        runs.push_back(row);
      }
    }
  }
  return runs;
}

// --- --speed: ns per spring ---------------------------------------------------------------

// A grid x grid cloth of structural and shear springs, hanging from its top corners.
std::string speed_scene(int grid, std::string_view method, int substeps, int iterations) {
  std::string text = fmt::format(
      "[cloth]\nrows = {0}\ncols = {0}\nspacing = 0.01\nplane = \"vertical\"\ndensity = 0.15\n"
      "pins = \"top-corners\"\n[springs]\nks = 500.0\nkd = 0.001\nshear_ks = 100.0\n"
      "[gravity]\ng = [0.0, -9.8, 0.0]\n[integrator]\nmethod = \"{1}\"\ndt = 1e-4\n"
      "duration = 1.0\n",
      grid, method);
  if (substeps > 0) text += fmt::format("substeps = {}\n", substeps);
  if (iterations > 0) text += fmt::format("iterations = {}\n", iterations);
  return text;
}

// The fastest of `repeats` wall times [s] of `steps` steps of the scene on `threads` threads,
// in the engine room (`fast`) or on the readable path alone, after `untimed` steps (a
// factorisation on the first step, say).
double time_steps(const std::string& text, int steps, int repeats, int threads, bool fast,
                  int untimed = 0) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    World world = std::move(parse_scene(text, "<speed>").world);
    if (!fast) world.backend.reset();
    world.threads = threads;
    for (int s = 0; s < untimed; ++s)
      world.step(1e-4);
    const Clock::time_point start = Clock::now();
    for (int s = 0; s < steps; ++s)
      world.step(1e-4);
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
  }
  return best;
}

// Implicit Euler's conjugate gradients: the fastest of `repeats` runs of `steps` steps of dt [s]
// (a large step, so that each solve takes enough iterations to time), as [s] in the solves per
// iteration, and the iterations per step.
struct CgTiming {
  double seconds_per_iteration = std::numeric_limits<double>::infinity();
  double iterations_per_step = 0.0;
};

CgTiming time_cg(const std::string& text, int steps, int repeats, int threads, bool fast,
                 double dt) {
  CgTiming best;
  for (int r = 0; r < repeats; ++r) {
    World world = std::move(parse_scene(text, "<speed>").world);
    if (!fast) world.backend.reset();
    world.threads = threads;
    for (int s = 0; s < steps; ++s)
      world.step(dt);
    const auto& implicit = dynamic_cast<const ImplicitEuler&>(*world.integrator);
    const LinearSolveStats& stats = implicit.stats();
    if (stats.iterations == 0) continue;
    best.seconds_per_iteration = std::min(
        best.seconds_per_iteration, stats.solve_seconds / static_cast<double>(stats.iterations));
    best.iterations_per_step = static_cast<double>(stats.iterations) / steps;
  }
  return best;
}

// The bound on a memory-bound pass: ns per spring of a streaming pass (y = y + s x, over
// arrays as large as the bytes a conjugate-gradient iteration of the engine room moves, about
// 240 per spring: engine/fast/implicit.cpp's four passes) on `threads` threads, fastest of 5.
double streaming_ns_per_spring(size_t springs, int threads) {
  const size_t n = springs * 240 / 24;  // y read and written, x read: 24 bytes an element
  std::vector<double> x(n, 1.0), y(n, 0.0);
  std::unique_ptr<ThreadTeam> team;
  if (threads > 1) team = std::make_unique<ThreadTeam>(threads);
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < 5; ++r) {
    const Clock::time_point start = Clock::now();
    for_ranges(team.get(), static_cast<Index>(n), [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
        y[static_cast<size_t>(i)] += 1e-3 * x[static_cast<size_t>(i)];
    });
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
  }
  return 1e9 * best / static_cast<double>(springs) + 0.0 * y[n / 2];
}

// The bound on an XPBD iteration in the engine room [ns per spring per pass]: the fastest of
// `repeats` runs of `steps` calls of FastEngine::xpbd_access_passes (the iteration's passes with
// no square root or division) with 1 + `more` passes, less the fastest with 1, over `more`: as
// the iteration itself is measured, on the constraints a step of the same scene built.
double xpbd_access_ns(const std::string& text, size_t springs, int steps, int repeats, int threads,
                      int more) {
  World world = std::move(parse_scene(text, "<speed>").world);
  world.threads = threads;
  world.step(1e-4);  // builds the constraints, as the timed XPBD steps do
  auto* engine = dynamic_cast<fast::FastEngine*>(world.backend.get());
  const auto* xpbd = dynamic_cast<const Xpbd*>(world.integrator.get());
  if (!engine || !xpbd) return kNaN;
  const XpbdConstraints& constraints = xpbd->constraints();
  const Matrix3X x_old = world.particles.x;
  std::vector<double> lambda(constraints.size(), 0.0);
  const auto best = [&](int passes) {
    double fastest = std::numeric_limits<double>::infinity();
    for (int r = 0; r < repeats; ++r) {
      const Clock::time_point start = Clock::now();
      for (int s = 0; s < steps; ++s)
        engine->xpbd_access_passes(world, constraints, x_old, 1e-4, passes, lambda);
      fastest = std::min(fastest, std::chrono::duration<double>(Clock::now() - start).count());
    }
    return fastest;
  };
  const double one = best(1), many = best(1 + more);
  return 1e9 * (many - one) / (static_cast<double>(springs) * steps * more);
}

// The times a step wakes the threads, on `threads` threads in the engine room (ThreadTeam::run:
// each hands every thread a job and waits for all of them, a barrier), per step after a first.
double wakes_per_step(const std::string& text, int threads, int steps) {
  World world = std::move(parse_scene(text, "<speed>").world);
  world.threads = threads;
  world.step(1e-4);
  const long before = world.thread_wakes();
  for (int s = 0; s < steps; ++s)
    world.step(1e-4);
  return static_cast<double>(world.thread_wakes() - before) / steps;
}

// One pass of a loop of square roots and divisions alone over `n` values (kept out of line, so
// that the passes are not turned inside out into one chain per value).
[[gnu::noinline]] void sqrt_div_pass(double* v, int n) {
  for (int i = 0; i < n; ++i)
    v[i] = 1.7 / std::sqrt(v[i]);
}

// What `threads` threads gain over one on square roots and divisions alone, the step's slowest
// instructions: each thread runs the same passes over its own values in the first-level cache;
// the work done per second by all at once against one alone, fastest of 5. A virtual machine's
// cores may share a physical core, and then this is below `threads`.
double arithmetic_gain(int threads) {
  constexpr int kValues = 512, kPasses = 10000;
  ThreadTeam team(threads);
  std::vector<std::vector<double>> values(static_cast<size_t>(threads),
                                          std::vector<double>(kValues, 1.3));
  const auto seconds = [&](int running) {
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < 5; ++r) {
      const Clock::time_point start = Clock::now();
      team.run([&](int t) {
        if (t >= running) return;
        for (int p = 0; p < kPasses; ++p)
          sqrt_div_pass(values[static_cast<size_t>(t)].data(), kValues);
      });
      best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
    }
    return best;
  };
  const double one = seconds(1);
  return threads * one / seconds(threads);
}

// The extra iterations whose cost is the cost of an iteration (XPBD's, VBD's, the bound's).
constexpr int kSpeedMore = 8;

// One grid's figures on one number of threads [ns per spring].
struct SpeedRow {
  int grid = 0, threads = 0;
  size_t springs = 0;
  double euler[2] = {}, xpbd_one[2] = {}, xpbd_iteration[2] = {};  // [readable, engine room]
  // The XPBD iteration's passes with no square root or division (xpbd_access_ns): its bound.
  double xpbd_access = 0.0;
  // On more than one thread: the wakes of the threads a symplectic Euler step and an XPBD
  // iteration make (wakes_per_step), and what one wake costs [ns] (wake_ns).
  double euler_wakes = 0.0, xpbd_wakes = 0.0, wake = 0.0;
  // Vertex Block Descent (lesson 14): a step of one iteration and an iteration.
  double vbd_one[2] = {}, vbd_iteration[2] = {};  // [readable, engine room]

  // Implicit Euler: ns per spring per conjugate-gradient iteration, and iterations per step.
  double cg_iteration[2] = {}, cg_iterations[2] = {};
  // A local/global iteration [readable, engine room], and its solve alone in the engine room
  // (CHOLMOD's, three right-hand sides): the part the threads do not share.
  double lg_iteration[2] = {}, lg_solve = 0.0;
};

// A local/global iteration's cost: steps of 1 + kLgMore iterations against steps of 1, after a
// first step that factors the matrix (untimed), on few steps, since a 256 x 256 cloth's
// readable iteration takes a tenth of a second; and the engine room's solve alone, timed on the
// matrix the integrator built.
void measure_local_global(SpeedRow& row, int grid, int threads, bool quick) {
  const int steps = quick ? 2 : 5, repeats = quick ? 1 : 3;
  constexpr int kLgMore = 4;
  const double per = 1e9 / (static_cast<double>(row.springs) * steps);
  const auto text = [&](int iterations) {
    return speed_scene(grid, "local-global", 0, iterations);
  };
  for (int fast = 0; fast < 2; ++fast) {
    const double one = per * time_steps(text(1), steps, repeats, threads, fast == 1, 1);
    const double many = per * time_steps(text(1 + kLgMore), steps, repeats, threads, fast == 1, 1);
    row.lg_iteration[fast] = (many - one) / kLgMore;
  }
  World world = std::move(parse_scene(text(1), "<speed>").world);
  world.step(1e-4);
  const auto* lg = dynamic_cast<const LocalGlobal*>(world.integrator.get());
  if (!lg) return;
  Eigen::CholmodSimplicialLLT<Eigen::SparseMatrix<double>> llt;
  llt.cholmod().nmethods = 1;
  llt.cholmod().method[0].ordering = CHOLMOD_AMD;
  llt.compute(lg->system().a);
  const Eigen::Matrix<double, Eigen::Dynamic, 3> b =
      Eigen::Matrix<double, Eigen::Dynamic, 3>::Ones(lg->system().a.rows(), 3);
  Eigen::Matrix<double, Eigen::Dynamic, 3> x;
  const int solves = quick ? 3 : 10;
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < solves; ++r) {
    const Clock::time_point start = Clock::now();
    x = llt.solve(b);
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
  }
  row.lg_solve = 1e9 * best / static_cast<double>(row.springs);
}

SpeedRow measure_speed(int grid, int threads, bool quick) {
  const int steps = quick ? 5 : 40, repeats = quick ? 2 : 5;
  SpeedRow row;
  row.grid = grid;
  row.threads = threads;
  const Scene scene = parse_scene(speed_scene(grid, "symplectic-euler", 0, 0), "<speed>");
  for (const auto& effect : scene.world.force_effects) {
    if (const auto* s = dynamic_cast<const SpringDampers*>(effect.get()))
      row.springs += s->springs().size();
  }
  const double per = 1e9 / (static_cast<double>(row.springs) * steps);  // s per run -> ns
  for (int fast = 0; fast < 2; ++fast) {
    const auto time = [&](const std::string& text) {
      return per * time_steps(text, steps, repeats, threads, fast == 1);
    };
    row.euler[fast] = time(speed_scene(grid, "symplectic-euler", 0, 0));
    row.xpbd_one[fast] = time(speed_scene(grid, "xpbd", 1, 1));
    const double many = time(speed_scene(grid, "xpbd", 1, 1 + kSpeedMore));
    row.xpbd_iteration[fast] = (many - row.xpbd_one[fast]) / kSpeedMore;
    if (fast == 1) {
      row.xpbd_access = xpbd_access_ns(speed_scene(grid, "xpbd", 1, 1), row.springs, steps, repeats,
                                       threads, kSpeedMore);
      if (threads > 1) {
        row.euler_wakes = wakes_per_step(speed_scene(grid, "symplectic-euler", 0, 0), threads, 4);
        row.xpbd_wakes = (wakes_per_step(speed_scene(grid, "xpbd", 1, 1 + kSpeedMore), threads, 4) -
                          wakes_per_step(speed_scene(grid, "xpbd", 1, 1), threads, 4)) /
                         kSpeedMore;
        row.wake = wake_ns(threads);
      }
    }
    row.vbd_one[fast] = time(speed_scene(grid, "vbd", 0, 1));
    row.vbd_iteration[fast] =
        (time(speed_scene(grid, "vbd", 0, 1 + kSpeedMore)) - row.vbd_one[fast]) / kSpeedMore;

    // Implicit Euler at 1/600 s, a tenth of a frame: the solves time its iterations.
    const CgTiming cg = time_cg(speed_scene(grid, "implicit-euler", 0, 0), quick ? 2 : 6,
                                quick ? 1 : 3, threads, fast == 1, 1.0 / 600);
    row.cg_iteration[fast] = 1e9 * cg.seconds_per_iteration / static_cast<double>(row.springs);
    row.cg_iterations[fast] = cg.iterations_per_step;
  }
  measure_local_global(row, grid, threads, quick);
  return row;
}

void speed(const MethodsOptions& opt, const fs::path& out_dir) {
  std::vector<SpeedRow> rows;
  fmt::print(
      "\nspeed: ns per spring, fastest of {} runs of {} steps; readable = the lecture's "
      "code alone, engine room = engine/fast/\n",
      opt.quick ? 2 : 5, opt.quick ? 5 : 40);
  fmt::print("  {:>9} {:>7} {:>7} | {:>21} | {:>21} | {:>21} | {:>14}\n", "grid", "springs",
             "threads", "symplectic Euler step", "XPBD substep, 1 it.", "XPBD iteration",
             "XPBD it./step");
  fmt::print("  {:>9} {:>7} {:>7} | {:>10} {:>10} | {:>10} {:>10} | {:>10} {:>10} | {:>14}\n", "",
             "", "", "readable", "engine", "readable", "engine", "readable", "engine",
             "engine (<=1.5)");
  for (int grid : opt.grids) {
    for (int threads : {1, 2}) {
      const SpeedRow r = measure_speed(grid, threads, opt.quick);
      fmt::print(
          "  {:>9} {:>7} {:>7} | {:10.2f} {:10.2f} | {:10.2f} {:10.2f} | {:10.2f} {:10.2f} | "
          "{:14.2f}\n",
          fmt::format("{0} x {0}", grid), r.springs, threads, r.euler[0], r.euler[1], r.xpbd_one[0],
          r.xpbd_one[1], r.xpbd_iteration[0], r.xpbd_iteration[1],
          r.xpbd_iteration[1] / r.euler[1]);
      rows.push_back(r);
    }
  }
  fmt::print("  {:>9} {:>7} | {:>21} | {:>14} | {:>14}\n", "grid", "threads",
             "local/global iteration", "LG it./step", "solve alone");
  fmt::print("  {:>9} {:>7} | {:>10} {:>10} | {:>14} | {:>14}\n", "", "", "readable", "engine",
             "engine (<=4)", "engine");
  for (const SpeedRow& r : rows) {
    fmt::print("  {:>9} {:>7} | {:10.2f} {:10.2f} | {:14.2f} | {:14.2f}\n",
               fmt::format("{0} x {0}", r.grid), r.threads, r.lg_iteration[0], r.lg_iteration[1],
               r.lg_iteration[1] / r.euler[1], r.lg_solve);
  }
  // The targets, as ratios measured in this run.
  fmt::print(
      "  targets (one thread, engine room): an XPBD iteration <= 1.5 symplectic Euler "
      "steps; 2 threads >= 1.7 times 1 thread at 128 x 128\n");
  for (const SpeedRow& one : rows) {
    if (one.threads != 1) continue;
    const double ratio = one.xpbd_iteration[1] / one.euler[1];
    fmt::print("  {0} x {0}: XPBD iteration / Euler step = {1:.2f} ({2})", one.grid, ratio,
               ratio <= 1.5 ? "met" : "missed");
    for (const SpeedRow& two : rows) {
      if (two.grid != one.grid || two.threads != 2) continue;
      const double euler = one.euler[1] / two.euler[1],
                   xpbd = one.xpbd_iteration[1] / two.xpbd_iteration[1];
      fmt::print("; 2 threads over 1: Euler {:.2f}, XPBD {:.2f}{}", euler, xpbd,
                 one.grid == 128 ? (euler >= 1.7 && xpbd >= 1.7 ? " (met)" : " (missed)") : "");
      // What bounds two threads: the wakes (each a barrier) a step or an iteration makes, at
      // their measured cost with nothing to do, and the memory's own speed-up (a stream). The
      // gains keep three significant digits: on a small grid of a busy machine the stream's
      // second thread may wait for a core a thousand times longer than the stream takes, and
      // two decimals would print that as a gain of 0.00.
      const double springs = static_cast<double>(one.springs);
      const auto most = [&](double ns_per_spring, double wakes) {
        const double t1 = ns_per_spring * springs;
        return t1 / (t1 / 2 + wakes * two.wake);
      };
      fmt::print(
          "\n    bound on 2 threads: an Euler step wakes the threads {:.1f} times, an XPBD "
          "iteration {:.1f}, at {:.0f} ns a wake with nothing to do: with the rest split evenly, "
          "at most {:.2f} and {:.2f} times 1 thread; on this machine a stream gains {:#.3g} and "
          "square roots and divisions alone {:#.3g}",
          two.euler_wakes, two.xpbd_wakes, two.wake, most(one.euler[1], two.euler_wakes),
          most(one.xpbd_iteration[1], two.xpbd_wakes),
          streaming_ns_per_spring(one.springs, 1) / streaming_ns_per_spring(one.springs, 2),
          arithmetic_gain(2));
    }
    fmt::print("\n");
    // What bounds it: the same passes, gathers and scatters with no square root or division.
    fmt::print(
        "    bound: the iteration's passes with no square root or division (the gathers and "
        "scatters alone) take {:.2f} ns per spring on 1 thread, {:.2f} Euler steps",
        one.xpbd_access, one.xpbd_access / one.euler[1]);
    for (const SpeedRow& two : rows) {
      if (two.grid == one.grid && two.threads == 2)
        fmt::print("; {:.2f} on 2 threads", two.xpbd_access);
    }
    fmt::print("; the XPBD iteration is {:.2f} times them\n",
               one.xpbd_iteration[1] / one.xpbd_access);
  }
  for (const SpeedRow& one : rows) {
    if (one.threads != 1) continue;
    const double ratio = one.lg_iteration[1] / one.euler[1];
    // The bound: the solve alone, on one thread whatever the threads (CHOLMOD's triangular
    // solves), against the Euler step.
    fmt::print(
        "  {0} x {0}: local/global iteration / Euler step = {1:.2f} ({2}; the solve alone "
        "{3:.2f})",
        one.grid, ratio, ratio <= 4.0 ? "met" : "missed", one.lg_solve / one.euler[1]);
    for (const SpeedRow& two : rows) {
      if (two.grid != one.grid || two.threads != 2) continue;
      const double lg = one.lg_iteration[1] / two.lg_iteration[1];
      // Amdahl: with the solve on one thread, 2 threads gain at most it / (solve + rest / 2).
      const double most = one.lg_iteration[1] /
                          (one.lg_solve + std::max(0.0, one.lg_iteration[1] - one.lg_solve) / 2);
      fmt::print("; 2 threads over 1: {:.2f}{} (at most {:.2f} with the solve on one thread)", lg,
                 one.grid == 128 ? (lg >= 1.7 ? " (met)" : " (missed)") : "", most);
    }
    fmt::print("\n");
  }

  // Implicit Euler's conjugate-gradient iterations, and the targets for them.
  fmt::print(
      "\n  implicit Euler at dt = 1/600 s: ns per spring per conjugate-gradient iteration "
      "(the time in the solves over their iterations), iterations per step\n");
  fmt::print("  {:>9} {:>7} | {:>21} | {:>21} | {:>16}\n", "grid", "threads", "CG iteration",
             "CG iterations/step", "CG it./Euler step");
  fmt::print("  {:>9} {:>7} | {:>10} {:>10} | {:>10} {:>10} | {:>16}\n", "", "", "readable",
             "engine", "readable", "engine", "engine (<=2)");
  for (const SpeedRow& r : rows) {
    fmt::print("  {:>9} {:>7} | {:10.2f} {:10.2f} | {:10.1f} {:10.1f} | {:16.2f}\n",
               fmt::format("{0} x {0}", r.grid), r.threads, r.cg_iteration[0], r.cg_iteration[1],
               r.cg_iterations[0], r.cg_iterations[1], r.cg_iteration[1] / r.euler[1]);
  }
  for (const SpeedRow& one : rows) {
    if (one.threads != 1) continue;
    const double ratio = one.cg_iteration[1] / one.euler[1];
    fmt::print("  {0} x {0}: CG iteration / Euler step = {1:.2f} ({2})", one.grid, ratio,
               ratio <= 2.0 ? "met" : "missed");
    for (const SpeedRow& two : rows) {
      if (two.grid != one.grid || two.threads != 2) continue;
      const double cg = one.cg_iteration[1] / two.cg_iteration[1];
      fmt::print("; 2 threads over 1: CG {:.2f}{}", cg,
                 one.grid == 128 ? (cg >= 1.7 ? " (met)" : " (missed)") : "");
    }
    fmt::print("\n");
    // What bounds it: the same bytes streamed once, on 1 and 2 threads.
    const double stream1 = streaming_ns_per_spring(one.springs, 1),
                 stream2 = streaming_ns_per_spring(one.springs, 2);
    fmt::print(
        "    bound: streaming the ~240 bytes per spring a CG iteration moves takes {:.2f} ns per "
        "spring on 1 thread, {:.2f} on 2 ({:.2f} times faster); the CG iteration is {:.1f} "
        "times the 1-thread stream\n",
        stream1, stream2, stream1 / stream2, one.cg_iteration[1] / stream1);
  }

  // Vertex Block Descent.
  fmt::print(
      "\n  VBD (lesson 14): ns per spring, an iteration = (a step of {} iterations - a step of "
      "1) / {}; per vertex = per spring x springs / vertices\n",
      1 + kSpeedMore, kSpeedMore);
  fmt::print("  {:>9} {:>7} | {:>21} | {:>21} | {:>10} | {:>10} | {:>10}\n", "grid", "threads",
             "step, 1 iteration", "VBD iteration", "engine,", "VBD it./", "VBD it./");
  fmt::print("  {:>9} {:>7} | {:>10} {:>10} | {:>10} {:>10} | {:>10} | {:>10} | {:>10}\n", "", "",
             "readable", "engine", "readable", "engine", "per vertex", "Euler step", "XPBD it.");
  for (const SpeedRow& r : rows) {
    const double vertices = static_cast<double>(r.grid) * r.grid;
    const double per_vertex = static_cast<double>(r.springs) / vertices;  // ns/spring -> ns/vertex
    fmt::print(
        "  {:>9} {:>7} | {:10.2f} {:10.2f} | {:10.2f} {:10.2f} | {:10.2f} | {:10.2f} | "
        "{:10.2f}\n",
        fmt::format("{0} x {0}", r.grid), r.threads, r.vbd_one[0], r.vbd_one[1], r.vbd_iteration[0],
        r.vbd_iteration[1], r.vbd_iteration[1] * per_vertex, r.vbd_iteration[1] / r.euler[1],
        r.vbd_iteration[1] / r.xpbd_iteration[1]);
  }

  std::string table = "grid,springs,measure,ns_per_spring,threads\n";
  for (const SpeedRow& r : rows) {
    for (int fast = 0; fast < 2; ++fast) {
      const char* way = fast ? "" : "-readable";
      const auto add = [&](const char* measure, double ns) {
        fmt::format_to(std::back_inserter(table), "{},{},{}{},{:.6g},{}\n", r.grid, r.springs,
                       measure, way, ns, r.threads);
      };
      add("symplectic-euler-step", r.euler[fast]);
      add("xpbd-substep-1-iteration", r.xpbd_one[fast]);
      add("xpbd-iteration", r.xpbd_iteration[fast]);

      add("implicit-euler-cg-iteration", r.cg_iteration[fast]);
      add("local-global-iteration", r.lg_iteration[fast]);
      add("vbd-step-1-iteration", r.vbd_one[fast]);
      add("vbd-iteration", r.vbd_iteration[fast]);
    }
  }
  write_whole_file(out_dir / "speed.csv", table);
  fmt::print("  wrote {}\n", (out_dir / "speed.csv").string());
}

constexpr std::string_view kMethodsCsv = "methods.csv";
constexpr std::string_view kMethodsHeader =
    "scene,method,dt,substeps,iterations,steps,error,worst_strain,energy_lost,wall_s_per_sim_s,"
    "stable";

int bench_methods(const MethodsOptions& opt) {
  // Where the results go, before the bake-off's minutes are spent.
  const fs::path out_dir = opt.out;
  const fs::path plot = opt.plot.empty() ? out_dir / "methods.svg" : fs::path(opt.plot);
  check_bench_folder(out_dir, std::string(kMethodsCsv), kMethodsHeader, opt.force);
  if (!opt.no_plot) check_bench_plot(plot, std::string(kMethodsCsv), kMethodsHeader, opt.force);

  std::vector<std::string> scenes = opt.scenes;
  if (scenes.empty()) {
    const fs::path lesson = fs::path(CLOTHLAB_SOURCE_DIR) / "lessons" / "12-xpbd";
    const auto names =
        opt.large ? std::vector<std::string>{"bakeoff-large-sheet.toml", "bakeoff-large-flag.toml",
                                             "bakeoff-large-drape.toml"}
                  : std::vector<std::string>{"bakeoff-hanging-sheet.toml",
                                             "bakeoff-gusty-flag.toml", "bakeoff-drape.toml"};
    for (const std::string& name : names)
      scenes.push_back((lesson / name).string());
  }
  fmt::print(
      "bench methods: {} scene(s); error = the particles' RMS distance from the reference "
      "over every 1/60 s frame, relative to the cloth's size; strain = the worst |l - l0| "
      "/ l0; E lost = energy lost against the reference by the end, relative to the "
      "reference's largest kinetic energy; wall time per simulated second, fastest "
      "repeat\n",
      scenes.size());
  if (!engine_has("local-global"))
    fmt::print("  (this engine has no local/global solver: its rows are left out)\n");

  std::vector<MethodRun> runs;
  for (const std::string& path : scenes) {
    std::vector<MethodRun> more = bake_off(path, opt);
    runs.insert(runs.end(), more.begin(), more.end());
  }

  fs::create_directories(out_dir);
  const fs::path csv = out_dir / kMethodsCsv;
  std::string table = std::string(kMethodsHeader) + "\n";
  for (const MethodRun& r : runs) {
    fmt::format_to(std::back_inserter(table),
                   "{},{},{:.17g},{},{},{},{:.17g},{:.17g},{:.17g},"
                   "{:.17g},{}\n",
                   fs::path(r.scene).stem().string(), r.reference ? "reference" : r.config.method,
                   r.config.dt(), r.config.substeps, r.config.iterations, r.steps, r.error,
                   r.worst_strain, r.energy_lost, r.wall_per_sim, r.stable ? "true" : "false");
  }
  write_whole_file(csv, table);
  const fs::path script = out_dir / "plot_methods.py";
  write_whole_file(script, kPlotScript);
  fmt::print("\n  wrote {} and {}\n", csv.string(), script.string());
  if (opt.speed) speed(opt, out_dir);
  if (opt.no_plot) return 0;
  draw_plot(script, csv, plot);
  return 0;
}

}  // namespace

void add_bench_methods_command(CLI::App& bench) {
  static MethodsOptions options;
  CLI::App* methods = bench.add_subcommand(
      "methods",
      "Lesson 12's bake-off: each method over a ladder of steps on cloth scenes, against a "
      "converged RK4 reference (table, CSV and a plot per scene)");
  methods
      ->add_option("scenes", options.scenes,
                   "Scenes to run (default: lesson 12's hanging sheet, gusty flag and drape)")
      ->check(CLI::ExistingFile);
  methods->add_option("--out", options.out, "Directory for methods.csv, the plot and its script")
      ->capture_default_str();
  methods->add_option("--plot", options.plot,
                      "Plot file (.svg, .png or .pdf; default OUT/methods.svg)");
  methods->add_flag("--no-plot", options.no_plot, "Write the CSV and the script, draw nothing");
  add_bench_force_option(*methods, options.force);
  methods->add_flag("--quick", options.quick, "Shorter ladders and a cheaper reference (tests)");
  methods->add_flag("--large", options.large,
                    "Lesson 12's cloths of real size (48 x 48 particles, a woven fabric's "
                    "stiffness) instead of its three small ones; the reference takes minutes");
  methods
      ->add_option("--reference", options.reference,
                   "The reference's method (default rk4): any method with a stability limit")
      ->check(CLI::IsMember({"symplectic-euler", "rk4", "velocity-verlet", "midpoint"}));
  methods
      ->add_option("--reference-below", options.reference_below,
                   "The reference's step: this many times below its advised limit (default "
                   "128; 8 with --large; --quick 16, or 2 with --large)")
      ->check(CLI::PositiveNumber);
  methods
      ->add_option("--min-seconds", options.min_seconds,
                   "Wall time [s] each run is repeated for; the fastest repeat is kept")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  methods->add_flag("--speed", options.speed,
                    "Also time a symplectic Euler step, an XPBD iteration, a CG iteration of "
                    "implicit Euler and a local/global iteration per spring, readable and engine "
                    "room, and a VBD iteration (readable), on 1 and 2 threads");
  methods
      ->add_option("--grid", options.grids,
                   "The speed measurement's cloths: N x N particles (one or more N)")
      ->check(CLI::Range(4, 1024))
      ->capture_default_str();
  methods->callback([] { run_bench_command("methods", [] { return bench_methods(options); }); });
}

}  // namespace clothlab::app
