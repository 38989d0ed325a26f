// bench_speed.cpp: `clothlab bench speed`, what a step of cloth costs and where the time goes.
//
// The scene: an N x N cloth, 1 cm apart, hanging from its two top corners, with structural,
// shear and bending springs, gravity and symplectic Euler, for N in {32, 64, 128, 256}. Every
// figure is the median over repeats of the wall time of many steps, per spring and step, and
// every variant runs in the same process, the variants taking turns repeat by repeat, so that
// ratios compare like with like; a ratio the run prints is taken turn by turn (ratio_of_turns),
// the median of the repeats' ratios, with their range:
//
//   reference       the engine's own step (the fast path), on 1 thread and on every core, with
//                   the speed-up of every core over one
//   float           the same step in single precision ([engine] precision = "float", the float
//                   room), 1 thread and every core, with its time over reference's of the same
//                   run and its distance from reference after 20 steps
//   readable        the same step on the readable path ([engine] fast_path = false)
//   naive           a lecture-style engine kept here: an array of particle objects, spring
//                   objects holding pointers to their two particles, ComputeForce() per spring
//   bare            the engine's force effects and Euler kernel on a state that stays in the fast
//                   layout, with no copies and no guard: what the reference would cost if the
//                   engine kept its state that way (1 thread and every core)
//   plain           the anchor: the same step as a careful first engine writes it, one loop a
//                   stage over a list of springs and arrays of x, y and z, one thread, with the
//                   reference's time over its own: what the engine's engineering buys
//   kernel          the spring kernel alone (spring_forces_of_run, the fast path's inner loop)
//                   on 256 springs whose data stay in the first-level cache: the least any step
//                   built on the spring kernel can cost per spring on this machine
//   +aerodynamics   the reference with [aerodynamics] added, then [ground] as well
//   float+aerodynamics  the float step with [aerodynamics], with its time over +aerodynamics's
//   student         the same scene in clothlab-student (your exercises), run as a subprocess;
//                   skipped, saying which, while an exercise it needs is still a stub
//   implicit        implicit Euler on a stiff cloth: the whole step, then its assembly (forces,
//                   Jacobians, the matrix) and its linear solve
//
// All variants but `kernel` and `implicit` compute the same physics; the naive, bare, plain and
// float ones are checked against the engine after a few steps, and the readable and fast paths
// agree bit for bit (a test checks it).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "app/bench.hpp"
#include "app/build_info.hpp"
#include "app/process.hpp"
#include "app/submission.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/euler.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "fast/copies.hpp"
#include "fast/engine.hpp"
#include "fast/forces.hpp"
#include "fast/springs.hpp"
#include "io/files.hpp"
#include "io/run.hpp"
#include "scene/scene.hpp"

extern char** environ;

namespace clothlab::app {

namespace {

namespace fs = std::filesystem;

struct SpeedOptions {
  std::vector<int> sizes{32, 64, 128, 256};
  int repeats = 5;
  double min_seconds = 0.25;  // [s] wall time of one repeat
  int threads = 0;            // "all cores": 0 asks the machine
  std::string csv;
  bool force = false;                 // --csv may replace a file the bench did not write
  std::vector<std::string> variants;  // empty: every variant
  bool quick = false;
  bool no_student = false;
  bool single = false;  // --float: the float rows and the double rows they are compared with
};

struct Measurement {
  std::string variant;
  int n = 0;
  int threads = 1;
  long springs = 0;
  double ns_per_spring_step = 0.0;  // [ns]
  double steps_per_s = 0.0;         // [1/s]
  std::string note;
};

// The scene's constants. Per particle 1 g, springs of 50 N/m: the stiffest mode has
// w <= sqrt(4 * 2 * (2 * 50 + 10) / 0.001) ~ 940 rad/s, so dt = 0.5 ms (w dt < 0.5) is well
// inside symplectic Euler's limit of w dt < 2 at every size.
constexpr double kSpacing = 0.01;       // [m]
constexpr double kParticleMass = 1e-3;  // [kg]
constexpr double kKs = 50.0, kKd = 0.01;
constexpr double kBendKs = 10.0, kBendKd = 0.005;
constexpr double kDt = 5e-4;  // [s]

std::string cloth_scene(int n, int threads, bool fast, const std::string& extra,
                        const std::string& method = "symplectic-euler", double ks = kKs,
                        double dt = kDt, bool bending = true, bool single = false) {
  return fmt::format(
      "title = \"bench speed\"\n"
      "[cloth]\nrows = {0}\ncols = {0}\nspacing = {1}\norigin = [0.0, 1.0, 0.0]\nmass = {2}\n"
      "pins = \"top-corners\"\n"
      "[springs]\nks = {3}\nkd = {4}\n"
      "{5}"
      "[gravity]\n{6}\n"
      "[integrator]\nmethod = \"{7}\"\ndt = {8}\nduration = 1000.0\n"
      "[engine]\nthreads = {9}\nfast_path = {10}\nprecision = \"{11}\"\n",
      n, kSpacing, kParticleMass * n * n, ks, kKd,
      bending ? fmt::format("[bending]\nks = {}\nkd = {}\n", kBendKs, kBendKd) : "", extra, method,
      dt, threads, fast ? "true" : "false", single ? "float" : "double");
}

long spring_count(const World& world) {
  long count = 0;
  for (const auto& effect : world.force_effects) {
    if (const auto* s = dynamic_cast<const SpringDampers*>(effect.get())) {
      count += static_cast<long>(s->springs().size());
    }
  }
  return count;
}

// One thing to measure: a step function and what its row says.
struct Contender {
  std::string variant;
  int threads = 1;
  long springs = 0;
  std::function<void()> step;
  std::vector<double> samples;  // [s] per step, one per repeat
  long steps = 1;               // the steps a call of step takes
};

// A contender that steps `scene`'s world as `clothlab run` does, kRunStepsAtOnce steps at once
// (World::advance: the engine room keeps the state in its layout between them).
Contender stepping(const std::string& variant, int threads, Scene& scene) {
  return {variant,
          threads,
          spring_count(scene.world),
          [&scene] { scene.world.advance(scene.dt, kRunStepsAtOnce); },
          {},
          kRunStepsAtOnce};
}

// Median wall time [s] of one step of each contender, over `repeats` repeats of enough steps to
// last `min_seconds` each (at least 2). The contenders take turns, repeat by repeat, so that a
// machine busy with something else slows them all alike and the ratios stay fair.
void time_steps(std::vector<Contender>& contenders, const SpeedOptions& opt) {
  using Clock = std::chrono::steady_clock;
  std::vector<long> steps;
  for (Contender& c : contenders) {
    c.step();  // warm up: caches, the first step's guard setup, the threads
    c.step();
    // The time of a step, from batches of 1, 2, 4, ... steps until one lasts a twentieth of a
    // repeat (the first steps alone would overstate it: they set things up).
    double per_step = 0.0;
    for (long batch = 1;; batch *= 2) {
      const Clock::time_point start = Clock::now();
      for (long s = 0; s < batch; ++s)
        c.step();
      const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
      per_step = seconds / static_cast<double>(batch * c.steps);
      if (seconds >= opt.min_seconds / 20 || batch >= 1'000'000) break;
    }
    steps.push_back(std::clamp<long>(
        std::lround(opt.min_seconds / std::max(per_step * c.steps, 1e-9)), 2, 10'000'000));
  }
  for (int r = 0; r < opt.repeats; ++r) {
    for (size_t k = 0; k < contenders.size(); ++k) {
      const Clock::time_point start = Clock::now();
      for (long s = 0; s < steps[k]; ++s)
        contenders[k].step();
      contenders[k].samples.push_back(std::chrono::duration<double>(Clock::now() - start).count() /
                                      static_cast<double>(steps[k] * contenders[k].steps));
    }
  }
}

double median(std::vector<double> samples) {
  std::sort(samples.begin(), samples.end());
  const size_t mid = samples.size() / 2;
  return samples.size() % 2 == 1 ? samples[mid] : 0.5 * (samples[mid - 1] + samples[mid]);
}

// a's time over b's, turn by turn: each repeat times a and b one soon after the other (the
// contenders between them take a fraction of a second each), so the ratio of one repeat's pair
// leaves out whatever slowed the machine from one repeat to the next, which the ratio of the two
// medians keeps. Printed as the median of the repeats' ratios,
// and with several repeats, their range: how far one run's ratio can be trusted.
std::string ratio_of_turns(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> ratios;
  for (size_t r = 0; r < std::min(a.size(), b.size()); ++r)
    ratios.push_back(a[r] / b[r]);
  if (ratios.size() < 2) return fmt::format("{:.2f}", ratios.empty() ? 0.0 : ratios[0]);
  const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
  return fmt::format("{:.2f} ({:.2f} to {:.2f} in {} turns)", median(ratios), *lo, *hi,
                     ratios.size());
}

Measurement make_row(const std::string& variant, int n, int threads, long springs, double seconds,
                     std::string note = "") {
  return {variant,
          n,
          threads,
          springs,
          1e9 * seconds / static_cast<double>(springs),
          1.0 / seconds,
          std::move(note)};
}

// --- The naive baseline --------------------------------------------------------------------
//
// The lecture's first engine, as a student would write it: one object per particle, one per
// spring with pointers to its particles, and three loops a step (gravity, springs, Euler). It
// calls the same exercise kernels as the engine, inlined as they are there (`flatten`: GCC
// otherwise calls the spring kernel once per spring here): the difference measured is the layout.

struct NaiveParticle {
  Vec3 x, v, f;  // position [m], velocity [m/s], force [N]
  double m;      // mass [kg]
  double inv_m;  // 1/m [1/kg], 0 when pinned
};

struct NaiveSpring {
  NaiveParticle* p1;
  NaiveParticle* p2;
  double ks, kd, l0;  // [N/m], [N s/m], [m]

  void ComputeForce() {
    const Vec3 f1 = spring_damper_force(p1->x, p2->x, p1->v, p2->v, ks, kd, l0);
    p1->f += f1;
    p2->f -= f1;
  }
};

struct NaiveCloth {
  std::vector<NaiveParticle> particles;
  std::vector<NaiveSpring> springs;
  Vec3 g{0.0, -9.8, 0.0};  // [m/s^2]

  [[gnu::flatten]] void Step(double dt) {
    for (NaiveParticle& p : particles)
      p.f = gravity_force(p.m, g);
    for (NaiveSpring& s : springs)
      s.ComputeForce();
    for (NaiveParticle& p : particles) {
      const PointState next = symplectic_euler_step(p.x, p.v, p.f, p.inv_m, dt);
      p.x = next.r;
      p.v = next.v;
    }
  }
};

// The naive cloth of the same particles, springs in the order the builders list them.
NaiveCloth naive_cloth(const World& world, int n) {
  NaiveCloth cloth;
  const Particles& p = world.particles;
  for (Index i = 0; i < p.size(); ++i)
    cloth.particles.push_back({p.x.col(i), p.v.col(i), Vec3::Zero(), p.m[i], p.inv_m[i]});
  const auto add = [&](const std::vector<IndexPair>& pairs, double ks, double kd) {
    for (const auto& [a, b] : pairs) {
      NaiveParticle* p1 = &cloth.particles[static_cast<size_t>(a)];
      NaiveParticle* p2 = &cloth.particles[static_cast<size_t>(b)];
      cloth.springs.push_back({p1, p2, ks, kd, (p2->x - p1->x).norm()});
    }
  };
  add(structural_pairs(n, n), kKs, kKd);
  add(shear_pairs(n, n), kKs, kKd);
  add(bending_pairs(n, n), kBendKs, kBendKd);
  return cloth;
}

// --- The kernel alone ------------------------------------------------------------------------
//
// Springs t = 0 .. count - 1 joining particles t and t + 1 of a cloth, in the fast path's layout,
// evaluated by the fast path's own loop. 256 springs take 24 KiB (positions, velocities,
// constants, forces), so everything stays in the first-level cache: the time is the kernel's
// arithmetic alone.
//
// The arrays share one allocation, laid out so that the loop never loads from the same place
// within a 4 KiB page as one of its stores a few springs before: a processor takes such a load
// for one that may read what the store writes and holds it until the store's address is known
// in full ("4K aliasing"). With each array where the heap put it, the row measured 0.76 to 1.3
// ns per spring on one Zen 5 machine from one run to the next, as the heap's addresses fell.
struct KernelRun {
  static constexpr long kPasses = 16;  // evaluations of the run per timed "step"
  long count = 0;
  Index stride = 0;  // of the rows of x and v
  std::vector<double> memory;
  double* x = nullptr;  // 3 rows of `stride` particles each, and v the same
  double* v = nullptr;
  double* ks = nullptr;  // `count` values each
  double* kd = nullptr;
  double* l0 = nullptr;
  double* f1 = nullptr;  // 3 rows of `count`

  // The pointers point into `memory`, which a move takes along and a copy would not.
  KernelRun() = default;
  KernelRun(const KernelRun&) = delete;
  KernelRun& operator=(const KernelRun&) = delete;
  KernelRun(KernelRun&&) = default;
  KernelRun& operator=(KernelRun&&) = default;

  void evaluate() {
    for (long pass = 0; pass < kPasses; ++pass) {
      fast::spring_forces_of_run(count, stride, stride, x, x + 1, v, v + 1, ks, kd, l0, f1,
                                 f1 + count, f1 + 2 * count);
    }
  }
};

KernelRun kernel_run(const World& world) {
  const Particles& p = world.particles;
  KernelRun run;
  run.count = std::min<long>(256, static_cast<long>(p.size()) - 1);
  run.stride = run.count + 1;
  // In doubles: f1 starts a page, and every array the loop loads from starts half a row of
  // stores (1 KiB) past a multiple of 2 KiB from it, as far as it can be from f1's rows (2 KiB
  // apart when count is 256) within a page.
  constexpr long kPage = 512, kTwoKiB = 256, kApart = 128;
  long end = 3 * run.count;  // f1 at 0
  const auto place = [&end](long size) {
    const long at = (end + kTwoKiB - 1) / kTwoKiB * kTwoKiB + kApart;
    end = at + size;
    return at;
  };
  const long x = place(3 * run.stride), v = place(3 * run.stride), ks = place(run.count),
             kd = place(run.count), l0 = place(run.count);
  run.memory.assign(static_cast<size_t>(end + kPage), 0.0);
  // The page's first double; the allocation is aligned to 8 bytes, as any double.
  const auto address = reinterpret_cast<std::uintptr_t>(run.memory.data());
  double* const page = run.memory.data() + (kPage - static_cast<long>(address / 8 % kPage)) % kPage;
  run.f1 = page;
  run.x = page + x;
  run.v = page + v;
  run.ks = page + ks;
  run.kd = page + kd;
  run.l0 = page + l0;
  for (Index i = 0; i < run.stride; ++i) {
    for (Index c = 0; c < 3; ++c) {
      run.x[c * run.stride + i] = p.x(c, i);
      run.v[c * run.stride + i] = p.v(c, i);
    }
  }
  std::fill_n(run.ks, run.count, kKs);
  std::fill_n(run.kd, run.count, kKd);
  std::fill_n(run.l0, run.count, kSpacing);
  return run;
}

// --- The engine's step without its copies and checks ---------------------------------------
//
// The reference step copies x and v into the fast layout and f back out (fast/engine.hpp), and
// the guard checks the state before and after the step. `bare` keeps x, v and f in the fast
// layout from one step to the next and checks nothing: the world's force effects add their
// forces through their fast paths (the same code as the reference's), then symplectic Euler's
// kernel (the scene's integrator) moves each particle right there. What it saves against
// `reference` is what the copies and the guard cost: about what keeping the engine's state in
// that layout could gain, short of rewriting the kernels themselves.

struct BareCloth {
  const World* world = nullptr;
  // x, v and f, laid out as on the engine's fast path (a run of steps' two copies): `state`,
  // and `next`, x and v after the step: each block of particles moves there while later blocks
  // and other threads may still read its x and v in `state`.
  fast::ResidentOf<double> copies;
  fast::Copies* state_ = &copies.a;
  fast::Copies* next_ = &copies.b;
  std::vector<std::unique_ptr<fast::FastForce>> forces;  // the fast form of each force effect
  std::unique_ptr<ThreadTeam> team;                      // null on 1 thread

  // A copy of the world's state; every force effect must have a fast form.
  BareCloth(const World& w, int threads) : world(&w) {
    for (const auto& effect : w.force_effects) {
      forces.push_back(fast::fast_force(*effect));
      if (!forces.back() || !forces.back()->prepare(w.particles)) {
        throw std::logic_error("bench speed: bare: a force effect has no fast path");
      }
    }
    const Index n = w.particles.size();
    copies.resize(n);
    state_->x.leftCols(n) = w.particles.x;
    state_->v.leftCols(n) = w.particles.v;
    if (threads > 1) team = std::make_unique<ThreadTeam>(threads);
  }

  Matrix3X positions() const { return state_->x.leftCols(world->particles.size()); }
  Matrix3X velocities() const { return state_->v.leftCols(world->particles.size()); }

  // As on the engine's fast path, each thread owns a contiguous range of particles and takes it
  // a block at a time (fast::kPassBlock): it sums the block's forces, then moves it into `next`.
  void step(double dt) {
    const Index block = fast::kPassBlock;
    for_ranges(team.get(), world->particles.size(), [&](Index begin, Index end) {
      for (Index b0 = begin; b0 < end; b0 += block)
        step_range(b0, std::min(b0 + block, end), dt, next_->x.data(), next_->v.data());
    });
    std::swap(state_, next_);
  }

  // `flatten`: the exercise kernels inlined here, as in the engine's own loops.
  // x_out and v_out have the rows of state.x and state.v.
  [[gnu::flatten, gnu::noinline]] void step_range(Index begin, Index end, double dt, double* x_out,
                                                  double* v_out) {
    const Particles& p = world->particles;
    fast::Copies& state = *state_;
    state.f.middleCols(begin, end - begin).setZero();
    for (const auto& force : forces)
      force->add(p, state.x, state.v, state.f, begin, end);
    move_range(begin, end, dt, state.x.data(), state.x.cols(), state.v.data(), state.v.cols(),
               state.f.data(), state.f.cols(), p.inv_m.data(), x_out, v_out);
  }

  // Symplectic Euler on particles [begin, end), the fast layout in and out. A function of its
  // own so that the pointers can be declared not to overlap: GCC then vectorises the loop, as
  // in the engine's move (fast/engine.cpp).
  [[gnu::flatten, gnu::noinline]] static void move_range(
      Index begin, Index end, double dt, const double* __restrict x, Index nx,
      const double* __restrict v, Index nv, const double* __restrict f, Index nf,
      const double* __restrict inv_m, double* __restrict x_out, double* __restrict v_out) {
    for (Index i = begin; i < end; ++i) {
      // Not const, as in the engine's move: GCC 12 does not split a const aggregate.
      PointState moved = symplectic_euler_step(Vec3(x[i], x[nx + i], x[2 * nx + i]),
                                               Vec3(v[i], v[nv + i], v[2 * nv + i]),
                                               Vec3(f[i], f[nf + i], f[2 * nf + i]), inv_m[i], dt);
      x_out[i] = moved.r.x();
      x_out[nx + i] = moved.r.y();
      x_out[2 * nx + i] = moved.r.z();
      v_out[i] = moved.v.x();
      v_out[nv + i] = moved.v.y();
      v_out[2 * nv + i] = moved.v.z();
    }
  }
};

// --- A plain structure-of-arrays step: the anchor -------------------------------------------
//
// What a careful first engine looks like, the one a fast engine has to beat: every spring in one
// list held in arrays (the ends i and j, ks, kd, l0; the world's spring effects one after the
// other, each in its set's order), the particles' x, v and f an array per coordinate, and a step
// as the lecture writes it, a loop a stage: clear f; for each spring the exercise's force (one
// square root, one division), added to one end and taken from the other; gravity; symplectic
// Euler. One thread; no grid stencil, no blocks, no passes fused, no copies, no guard. The
// kernels are inlined (`flatten`), as in the engine's own loops. Its sums are the readable
// path's, in its order: the same bits as the reference, which the row's note shows.

struct PlainCloth {
  std::vector<double> x[3], v[3], f[3];  // x[c][i]: coordinate c of particle i
  std::vector<double> m, inv_m;
  std::vector<Index> i, j;  // spring k joins particles i[k] and j[k]
  std::vector<double> ks, kd, l0;
  Vec3 g = Vec3::Zero();
  std::vector<double> f1[3];  // each spring's force on its end i, a step's

  // The world's particles, its springs and its gravity; any other force effect is an error.
  explicit PlainCloth(const World& w) {
    const Particles& p = w.particles;
    for (int c = 0; c < 3; ++c) {
      x[c].assign(p.x.row(c).begin(), p.x.row(c).end());
      v[c].assign(p.v.row(c).begin(), p.v.row(c).end());
      f[c].assign(p.x.cols(), 0.0);
    }
    m.assign(p.m.begin(), p.m.end());
    inv_m.assign(p.inv_m.begin(), p.inv_m.end());
    int gravities = 0;
    for (const auto& effect : w.force_effects) {
      if (const auto* s = dynamic_cast<const SpringDampers*>(effect.get())) {
        if (gravities > 0) throw std::logic_error("bench speed: plain: springs after gravity");
        const SpringSet& set = s->springs();
        for (size_t k = 0; k < set.size(); ++k) {
          i.push_back(set.i(k));
          j.push_back(set.j(k));
          ks.push_back(set.ks(k));
          kd.push_back(set.kd(k));
          l0.push_back(set.l0(k));
        }
      } else if (const auto* gravity = dynamic_cast<const UniformGravity*>(effect.get())) {
        g = gravity->g();
        ++gravities;
      } else {
        throw std::logic_error("bench speed: plain: a force effect other than springs and gravity");
      }
    }
    if (gravities != 1) throw std::logic_error("bench speed: plain: expected one [gravity]");
  }

  Matrix3X positions() const { return rows(x); }
  Matrix3X velocities() const { return rows(v); }

  void step(double dt) {
    const size_t n = m.size(), springs = i.size();
    for (int c = 0; c < 3; ++c)
      std::fill(f[c].begin(), f[c].end(), 0.0);
    f1[0].resize(springs);
    f1[1].resize(springs);
    f1[2].resize(springs);
    spring_forces(springs, i.data(), j.data(), x[0].data(), x[1].data(), x[2].data(), v[0].data(),
                  v[1].data(), v[2].data(), ks.data(), kd.data(), l0.data(), f1[0].data(),
                  f1[1].data(), f1[2].data());
    for (size_t k = 0; k < springs; ++k) {
      const auto a = static_cast<size_t>(i[k]), b = static_cast<size_t>(j[k]);
      for (int c = 0; c < 3; ++c) {
        f[c][a] += f1[c][k];  // f2 = -f1
        f[c][b] -= f1[c][k];
      }
    }
    add_gravity(n, m.data(), g, f[0].data(), f[1].data(), f[2].data());
    move(n, dt, inv_m.data(), f[0].data(), f[1].data(), f[2].data(), x[0].data(), x[1].data(),
         x[2].data(), v[0].data(), v[1].data(), v[2].data());
  }

 private:
  // The stages, each a loop of its own over arrays that do not overlap, the kernels inlined, so
  // that the compiler takes several springs or particles an instruction where it can: every
  // spring's force (the ends' coordinates gathered by index), gravity, the move. Adding the
  // springs' forces to their ends stays one spring at a time: two springs may share an end.
  [[gnu::flatten, gnu::noinline]] static void spring_forces(
      size_t count, const Index* __restrict i, const Index* __restrict j,
      const double* __restrict x, const double* __restrict y, const double* __restrict z,
      const double* __restrict vx, const double* __restrict vy, const double* __restrict vz,
      const double* __restrict ks, const double* __restrict kd, const double* __restrict l0,
      double* __restrict fx, double* __restrict fy, double* __restrict fz) {
    for (size_t k = 0; k < count; ++k) {
      const Index a = i[k], b = j[k];
      const Vec3 f1 = spring_damper_force(Vec3(x[a], y[a], z[a]), Vec3(x[b], y[b], z[b]),
                                          Vec3(vx[a], vy[a], vz[a]), Vec3(vx[b], vy[b], vz[b]),
                                          ks[k], kd[k], l0[k]);
      fx[k] = f1.x();
      fy[k] = f1.y();
      fz[k] = f1.z();
    }
  }
  [[gnu::flatten, gnu::noinline]] static void add_gravity(size_t n, const double* __restrict m,
                                                          const Vec3& g, double* __restrict fx,
                                                          double* __restrict fy,
                                                          double* __restrict fz) {
    const Vec3 field = g;  // a copy: the stores to f cannot change it, and the loop vectorises
    for (size_t p = 0; p < n; ++p) {
      const Vec3 fg = gravity_force(m[p], field);
      fx[p] += fg.x();
      fy[p] += fg.y();
      fz[p] += fg.z();
    }
  }
  [[gnu::flatten, gnu::noinline]] static void move(
      size_t n, double dt, const double* __restrict inv_m, const double* __restrict fx,
      const double* __restrict fy, const double* __restrict fz, double* __restrict x,
      double* __restrict y, double* __restrict z, double* __restrict vx, double* __restrict vy,
      double* __restrict vz) {
    for (size_t p = 0; p < n; ++p) {
      PointState next =  // not const: GCC 12 does not split a const aggregate
          symplectic_euler_step(Vec3(x[p], y[p], z[p]), Vec3(vx[p], vy[p], vz[p]),
                                Vec3(fx[p], fy[p], fz[p]), inv_m[p], dt);
      x[p] = next.r.x();
      y[p] = next.r.y();
      z[p] = next.r.z();
      vx[p] = next.v.x();
      vy[p] = next.v.y();
      vz[p] = next.v.z();
    }
  }

  static Vec3 at(const std::vector<double> (&a)[3], Index p) {
    const auto q = static_cast<size_t>(p);
    return Vec3(a[0][q], a[1][q], a[2][q]);
  }
  static Matrix3X rows(const std::vector<double> (&a)[3]) {
    Matrix3X out(3, static_cast<Index>(a[0].size()));
    for (Index p = 0; p < out.cols(); ++p)
      out.col(p) = at(a, p);
    return out;
  }
};

// --- The variants --------------------------------------------------------------------------

bool wanted(const SpeedOptions& opt, const std::string& variant) {
  return opt.variants.empty() ||
         std::find(opt.variants.begin(), opt.variants.end(), variant) != opt.variants.end();
}

void measure_size(int n, int all_cores, const SpeedOptions& opt, std::vector<Measurement>& rows) {
  // Every contender's state lives here until all are measured.
  std::vector<std::unique_ptr<Scene>> scenes;
  std::vector<Contender> contenders;
  std::vector<std::string> notes;
  const auto engine = [&](const std::string& variant, int threads, bool fast,
                          const std::string& extra) {
    scenes.push_back(
        std::make_unique<Scene>(parse_scene(cloth_scene(n, threads, fast, extra), "<bench>")));
    contenders.push_back(stepping(variant, threads, *scenes.back()));
    notes.emplace_back();
  };
  std::vector<int> thread_counts{1};
  if (all_cores > 1) thread_counts.push_back(all_cores);

  if (wanted(opt, "reference")) {
    for (int threads : thread_counts)
      engine("reference", threads, true, "");
  }
  // The step in float, on `threads`, with the effects of `extra`; and how far single precision
  // takes the cloth from the double run in 20 steps, against the distance the cloth moved:
  // rounding's drift, not another physics.
  const auto in_float = [&](const std::string& variant, int threads, const std::string& extra) {
    scenes.push_back(std::make_unique<Scene>(parse_scene(
        cloth_scene(n, threads, true, extra, "symplectic-euler", kKs, kDt, true, /*single=*/true),
        "<bench>")));
    Scene& scene = *scenes.back();
    Scene check = parse_scene(
        cloth_scene(n, 1, true, extra, "symplectic-euler", kKs, kDt, true, /*single=*/true),
        "<bench>");
    Scene reference = parse_scene(cloth_scene(n, 1, true, extra), "<bench>");
    const Matrix3X start = reference.world.particles.x;
    for (int k = 0; k < 20; ++k) {
      check.world.step(check.dt);
      reference.world.step(reference.dt);
    }
    const double gap =
        (check.world.particles.x - reference.world.particles.x).cwiseAbs().maxCoeff();
    const double moved = (reference.world.particles.x - start).cwiseAbs().maxCoeff();
    contenders.push_back(stepping(variant, threads, scene));
    notes.push_back(
        fmt::format("{:.1e} m from the double run after 20 steps (moved {:.1e} m)", gap, moved));
  };
  if (wanted(opt, "float")) {
    for (int threads : thread_counts)
      in_float("float", threads, "");
  }
  if (wanted(opt, "readable")) engine("readable", 1, false, "");
  NaiveCloth naive;
  if (wanted(opt, "naive")) {
    Scene scene = parse_scene(cloth_scene(n, 1, true, ""), "<bench>");
    naive = naive_cloth(scene.world, n);
    // The same physics: after a few steps the two agree to rounding (the sums run in another
    // order), which the note shows.
    NaiveCloth check = naive;
    for (NaiveSpring& s : check.springs) {
      s.p1 = &check.particles[static_cast<size_t>(s.p1 - naive.particles.data())];
      s.p2 = &check.particles[static_cast<size_t>(s.p2 - naive.particles.data())];
    }
    for (int k = 0; k < 20; ++k) {
      check.Step(scene.dt);
      scene.world.step(scene.dt);
    }
    double gap = 0.0;
    for (size_t i = 0; i < check.particles.size(); ++i) {
      const Vec3 x = scene.world.particles.x.col(static_cast<Index>(i));
      gap = std::max(gap, (check.particles[i].x - x).cwiseAbs().maxCoeff());
    }
    const double dt = scene.dt;
    contenders.push_back({"naive",
                          1,
                          static_cast<long>(naive.springs.size()),
                          [&naive, dt] { naive.Step(dt); },
                          {}});
    notes.push_back(fmt::format("agrees with reference to {:.1e} m after 20 steps", gap));
  }
  std::vector<std::unique_ptr<BareCloth>> bares;
  if (wanted(opt, "bare")) {
    for (int threads : thread_counts) {
      scenes.push_back(
          std::make_unique<Scene>(parse_scene(cloth_scene(n, 1, true, ""), "<bench>")));
      Scene& scene = *scenes.back();
      // The same physics, bit for bit, which the note shows: a copy of the scene, stepped by
      // the engine, against the bare loop on the same start.
      Scene check = parse_scene(cloth_scene(n, 1, true, ""), "<bench>");
      BareCloth bare_check(check.world, threads);
      for (int k = 0; k < 20; ++k) {
        bare_check.step(check.dt);
        check.world.step(check.dt);
      }
      const double gap_x = (bare_check.positions() - check.world.particles.x).cwiseAbs().maxCoeff();
      const double gap_v =
          (bare_check.velocities() - check.world.particles.v).cwiseAbs().maxCoeff();
      bares.push_back(std::make_unique<BareCloth>(scene.world, threads));
      BareCloth& bare = *bares.back();
      const double dt = scene.dt;
      contenders.push_back(
          {"bare", threads, spring_count(scene.world), [&bare, dt] { bare.step(dt); }, {}});
      notes.push_back(gap_x == 0.0 && gap_v == 0.0
                          ? std::string("the same bits as reference after 20 steps")
                          : fmt::format("differs from reference after 20 steps: x by {:.1e} m, "
                                        "v by {:.1e} m/s",
                                        gap_x, gap_v));
    }
  }
  std::unique_ptr<PlainCloth> plain;
  if (wanted(opt, "plain")) {
    Scene scene = parse_scene(cloth_scene(n, 1, true, ""), "<bench>");
    plain = std::make_unique<PlainCloth>(scene.world);
    // The same physics, bit for bit, which the note shows: a copy stepped by the plain loops
    // against the engine on the same start.
    PlainCloth check(scene.world);
    for (int k = 0; k < 20; ++k) {
      check.step(scene.dt);
      scene.world.step(scene.dt);
    }
    const double gap_x = (check.positions() - scene.world.particles.x).cwiseAbs().maxCoeff();
    const double gap_v = (check.velocities() - scene.world.particles.v).cwiseAbs().maxCoeff();
    const double dt = scene.dt;
    PlainCloth& loops = *plain;
    contenders.push_back(
        {"plain", 1, static_cast<long>(loops.i.size()), [&loops, dt] { loops.step(dt); }, {}});
    notes.push_back(gap_x == 0.0 && gap_v == 0.0
                        ? std::string("the same bits as reference after 20 steps")
                        : fmt::format("differs from reference after 20 steps: x by {:.1e} m, "
                                      "v by {:.1e} m/s",
                                      gap_x, gap_v));
  }
  KernelRun kernel;
  if (wanted(opt, "kernel")) {
    // No bending springs: the kernel row needs only lessons 01 and 02's exercises, so a student
    // can time their spring kernel as soon as it is written.
    Scene scene = parse_scene(
        cloth_scene(n, 1, true, "", "symplectic-euler", kKs, kDt, /*bending=*/false), "<bench>");
    for (int k = 0; k < 20; ++k)  // a cloth in motion: stretched springs, moving particles
      scene.world.step(scene.dt);
    kernel = kernel_run(scene.world);
    contenders.push_back(
        {"kernel", 1, KernelRun::kPasses * kernel.count, [&kernel] { kernel.evaluate(); }, {}});
    notes.push_back(fmt::format("{} springs in the first-level cache, {} passes a \"step\"",
                                kernel.count, KernelRun::kPasses));
  }
  const std::string aero = "[aerodynamics]\nwind = [2.0, 0.0, 1.0]\n";
  const std::string ground = "[ground]\ny = 0.5\ne = 0.2\nmu_s = 0.5\nmu_d = 0.3\n";
  if (wanted(opt, "+aerodynamics")) {
    for (int threads : thread_counts)
      engine("+aerodynamics", threads, true, aero);
  }
  if (wanted(opt, "+aerodynamics+ground")) {
    for (int threads : thread_counts)
      engine("+aerodynamics+ground", threads, true, aero + ground);
  }
  if (wanted(opt, "float+aerodynamics")) {
    for (int threads : thread_counts)
      in_float("float+aerodynamics", threads, aero);
  }
  const ImplicitEuler* implicit = nullptr;
  if (wanted(opt, "implicit")) {
    // Stiff: 100 times the springs' ks, dt 4 times the scene's; explicit methods would need
    // dt < 2 / w ~ 0.2 ms here, implicit Euler takes 2 ms.
    scenes.push_back(std::make_unique<Scene>(parse_scene(
        cloth_scene(n, 1, true, "", "implicit-euler", 100.0 * kKs, 4 * kDt), "<bench>")));
    Scene& scene = *scenes.back();
    implicit = dynamic_cast<const ImplicitEuler*>(scene.world.integrator.get());
    contenders.push_back(
        {"implicit", 1, spring_count(scene.world), [&scene] { scene.world.step(scene.dt); }, {}});
    notes.emplace_back();
  }

  time_steps(contenders, opt);
  const size_t first_row = rows.size();
  for (size_t k = 0; k < contenders.size(); ++k) {
    const Contender& c = contenders[k];
    rows.push_back(make_row(c.variant, n, c.threads, c.springs, median(c.samples), notes[k]));
  }
  // The ratios of this run, turn by turn (ratio_of_turns): contenders k and r are rows
  // first_row + k and first_row + r.
  const auto ratio = [&](size_t k, size_t r) {
    return ratio_of_turns(contenders[k].samples, contenders[r].samples);
  };
  // A float step over its double step on as many threads: float over reference,
  // float+aerodynamics over +aerodynamics.
  for (size_t k = 0; k < contenders.size(); ++k) {
    if (contenders[k].variant.rfind("float", 0) != 0) continue;
    const std::string twin =
        contenders[k].variant == "float" ? "reference" : contenders[k].variant.substr(5);
    for (size_t r = 0; r < contenders.size(); ++r) {
      if (contenders[r].variant == twin && contenders[r].threads == contenders[k].threads) {
        Measurement& row = rows[first_row + k];
        row.note = fmt::format("{} / {} {}; {}", row.variant, twin, ratio(k, r), row.note);
      }
    }
  }
  // The engine's one-thread step over the plain loops'; the engine on every core against one.
  for (size_t k = 0; k < contenders.size(); ++k) {
    const bool anchor = contenders[k].variant == "plain";
    const bool threads = contenders[k].variant == "reference" && contenders[k].threads > 1;
    if (!anchor && !threads) continue;
    for (size_t r = 0; r < contenders.size(); ++r) {
      if (contenders[r].variant != "reference" || contenders[r].threads != 1) continue;
      Measurement& row = rows[first_row + k];
      row.note = anchor ? fmt::format("reference / plain {}; {}", ratio(r, k), row.note)
                        : fmt::format("speed-up over 1 thread {}", ratio(r, k));
    }
  }
  if (implicit) {
    // Its assembly and its solve, as averages over every step it took (the figure above is
    // the median of the repeats).
    const LinearSolveStats& st = implicit->stats();
    const double per_solve = 1.0 / static_cast<double>(std::max(st.solves, 1L));
    const long springs = contenders.back().springs;
    rows.back().note =
        fmt::format("ks = {} N/m, dt = {} s, {:.1f} CG iterations per solve", 100.0 * kKs, 4 * kDt,
                    static_cast<double>(st.iterations) * per_solve);
    rows.push_back(make_row("implicit-assembly", n, 1, springs, st.assembly_seconds * per_solve,
                            "f0, Jacobians, A and b (mean)"));
    rows.push_back(make_row("implicit-solve", n, 1, springs, st.solve_seconds * per_solve,
                            "conjugate gradients (mean)"));
  }
}

// --- The student build, as a subprocess -----------------------------------------------------

// Runs clothlab-student (found beside this program) on the reference variant and adds its rows
// as "student"; returns why not, when it could not.
std::string measure_student(const SpeedOptions& opt, std::vector<Measurement>& rows) {
  const fs::path student = fs::path(build_dir()) / "clothlab-student";
  if (!fs::exists(student)) return "clothlab-student was not found beside clothlab";
  const fs::path dir = fs::temp_directory_path() / fmt::format("clothlab-bench-{}", getpid());
  fs::create_directories(dir);
  const fs::path csv = dir / "student.csv";
  std::vector<std::string> args{student.string(), "bench",
                                "speed",          "--no-student",
                                "--variants",     "reference",
                                "--threads",      "1",
                                "--repeats",      std::to_string(opt.repeats),
                                "--min-seconds",  fmt::format("{}", opt.min_seconds),
                                "--csv",          csv.string(),
                                "--sizes"};
  for (int n : opt.sizes)
    args.push_back(std::to_string(n));
  const ProcessResult run = run_process(args, 24 * 3600);
  const std::string& output = run.output;
  std::string why;
  if (run.exit_code == 127) return "clothlab-student could not be started";
  if (run.timed_out || run.signal != 0 || run.exit_code != 0) {
    // A stub names its exercise: "exercise ex02.1 is not implemented yet: see ...".
    const size_t at = output.find("exercise ex");
    if (at != std::string::npos) {
      const std::string exercise = output.substr(at + 9, output.find(' ', at + 9) - (at + 9));
      why = fmt::format("{} is not done yet in exercises/", exercise);
    } else {
      why = fmt::format("clothlab-student failed:\n{}", output);
    }
  } else {
    std::ifstream file(csv);
    std::string line;
    std::getline(file, line);  // the header
    while (std::getline(file, line)) {
      std::stringstream in(line);
      Measurement m;
      std::string field;
      std::getline(in, m.variant, ',');
      std::getline(in, field, ',');
      m.n = std::stoi(field);
      std::getline(in, field, ',');
      m.threads = std::stoi(field);
      std::getline(in, field, ',');
      m.springs = std::stol(field);
      std::getline(in, field, ',');
      m.ns_per_spring_step = std::stod(field);
      std::getline(in, field, ',');
      m.steps_per_s = std::stod(field);
      m.variant = "student";
      m.note = "clothlab-student, your kernels";
      rows.push_back(m);
    }
  }
  std::error_code error;
  fs::remove_all(dir, error);
  return why;
}

void print_table(const std::vector<Measurement>& rows) {
  fmt::print("  {:>4} {:>7}  {:<21} {:>7} {:>13} {:>11} {:>9}  {}\n", "N", "springs", "variant",
             "threads", "ns/spring-step", "steps/s", "vs naive", "");
  int n = -1;
  for (const Measurement& m : rows) {
    if (m.n != n && n != -1) fmt::print("\n");
    n = m.n;
    // The ratio to the naive baseline of the same size, measured in this run.
    std::string ratio;
    for (const Measurement& naive : rows) {
      if (naive.variant == "naive" && naive.n == m.n && m.variant != "naive" &&
          m.variant.rfind("implicit", 0) != 0) {
        ratio = fmt::format("{:.2f}x", naive.ns_per_spring_step / m.ns_per_spring_step);
      }
    }
    fmt::print("  {:>4} {:>7}  {:<21} {:>7} {:>13.3f} {:>11.1f} {:>9}  {}\n", m.n, m.springs,
               m.variant, m.threads, m.ns_per_spring_step, m.steps_per_s, ratio, m.note);
  }
}

constexpr std::string_view kSpeedHeader =
    "variant,n,threads,springs,ns_per_spring_step,steps_per_s,particles";

int bench_speed(SpeedOptions opt) {
  // Where the CSV goes, before the measurements' minutes are spent.
  if (!opt.csv.empty()) check_bench_file(opt.csv, "--csv", kSpeedHeader, opt.force);
  if (opt.single) {
    opt.variants = {"reference", "bare", "float"};
  }
  if (opt.quick) {
    opt.sizes = {16, 32};
    opt.repeats = 1;
    opt.min_seconds = 0.01;
  }
  const int all_cores = opt.threads > 0 ? opt.threads : ThreadTeam::hardware_threads();
  fmt::print(
      "bench speed: N x N cloth, structural + shear + bending springs, gravity, symplectic Euler, "
      "two pinned corners\n  {} build, {}; median of {} repeats of at least {} s; 1 thread{}\n"
      "  the engine's rows take {} steps at a time, as clothlab run does (World::advance)\n\n",
      kKernels,
      kLinkTimeOptimised ? "kernels inlined by link-time optimisation"
                         : "link-time optimisation off",
      opt.repeats, opt.min_seconds,
      all_cores <= 1    ? std::string()
      : opt.threads > 0 ? fmt::format(" and {} (--threads)", all_cores)
                        : fmt::format(" and {} (every core)", all_cores),
      kRunStepsAtOnce);
  std::vector<Measurement> rows;
  for (int n : opt.sizes)
    measure_size(n, all_cores, opt, rows);

  std::string student_skipped;
  if (!opt.no_student && wanted(opt, "student")) {
    if (std::string(kKernels) == "student") {
      student_skipped = "this is the student build already";
    } else {
      student_skipped = measure_student(opt, rows);
      // Keep each size's rows together.
      std::stable_sort(rows.begin(), rows.end(),
                       [](const Measurement& a, const Measurement& b) { return a.n < b.n; });
    }
  }
  print_table(rows);
  if (!student_skipped.empty()) fmt::print("\n  student: skipped: {}\n", student_skipped);

  if (!opt.csv.empty()) {
    const fs::path csv = opt.csv;
    if (csv.has_parent_path()) fs::create_directories(csv.parent_path());
    std::string table = std::string(kSpeedHeader) + "\n";
    for (const Measurement& m : rows) {
      fmt::format_to(std::back_inserter(table), "{},{},{},{},{:.6g},{:.6g},{}\n", m.variant, m.n,
                     m.threads, m.springs, m.ns_per_spring_step, m.steps_per_s, m.n * m.n);
    }
    write_whole_file(csv, table);
    fmt::print("\n  wrote {}\n", csv.string());
  }
  return 0;
}

}  // namespace

std::string speed_cloth_scene(int n, int threads) {
  return cloth_scene(n, threads, /*fast=*/true, "");
}

namespace {

// One variant's row on an n x n cloth, 1 thread: ns per spring-step.
double one_row(const char* variant, int n, int repeats, double min_seconds) {
  SpeedOptions opt;
  opt.variants = {variant};
  opt.repeats = repeats;
  opt.min_seconds = min_seconds;
  std::vector<Measurement> rows;
  measure_size(n, /*all_cores=*/1, opt, rows);
  return rows.at(0).ns_per_spring_step;
}

}  // namespace

double reference_ns_per_spring_step(int n, int repeats, double min_seconds) {
  return one_row("reference", n, repeats, min_seconds);
}

double kernel_ns_per_spring(int repeats, double min_seconds) {
  return one_row("kernel", 32, repeats, min_seconds);
}

void add_cloth_sizes_option(CLI::App& command, std::vector<int>& sizes) {
  command.add_option("--sizes", sizes, "Cloth sizes N (N x N particles)")
      ->delimiter(',')
      ->check(CLI::Range(3, 2048))
      ->capture_default_str();
}

void add_bench_speed_command(CLI::App& bench) {
  static SpeedOptions options;
  SpeedOptions& o = options;
  CLI::App* speed = bench.add_subcommand(
      "speed",
      "The engine's speed on N x N cloths: ns per spring and step, steps per second, against a "
      "naive baseline, with effects added, on 1 thread and all cores (table and CSV)");
  add_cloth_sizes_option(*speed, o.sizes);
  speed->add_option("--repeats", o.repeats, "Repeats of each measurement (the median is shown)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  speed->add_option("--min-seconds", o.min_seconds, "Wall time [s] of each repeat")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  speed->add_option("--threads", o.threads, "Threads of the all-cores rows (default: every core)")
      ->check(CLI::Range(1, 1024));
  speed->add_option("--csv", o.csv, "Write one row per measurement to this CSV file");
  add_bench_force_option(*speed, o.force);
  // A misspelt variant is an error, not an empty table.
  CLI::Option* variants =
      speed->add_option("--variants", o.variants, "Variants to measure (default: all)")
          ->delimiter(',')
          ->check(CLI::IsMember({"reference", "float", "readable", "naive", "bare", "plain",
                                 "kernel", "+aerodynamics", "+aerodynamics+ground",
                                 "float+aerodynamics", "implicit", "student"}));
  speed
      ->add_flag("--float", o.single,
                 "The float rows (the step in single precision, [engine] precision = \"float\") "
                 "and the double rows they are compared with: --variants reference,bare,float")
      ->excludes(variants);
  speed->add_flag("--quick", o.quick, "Sizes 16 and 32, one short repeat (for tests)");
  speed->add_flag("--no-student", o.no_student, "Do not run clothlab-student");
  speed->callback([] {
    int status = 0;
    try {
      status = bench_speed(options);
    } catch (const NotImplemented& e) {
      std::fflush(stdout);
      fmt::print(stderr, "error: {}\n", e.what());
      status = 4;  // as `clothlab run`: an exercise kernel is still a stub
    } catch (const std::exception& e) {
      std::fflush(stdout);
      fmt::print(stderr, "error: bench speed: {}\n", e.what());
      status = 1;
    }
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace clothlab::app
