// bench_roofline.cpp: `clothlab bench roofline`, the engine's step against this machine's limits.
//
// A roofline bounds how fast a program can run on a machine from what the program must do and
// what the machine can do of it per second. A spring of the engine room's symplectic Euler step
// (engine/fast/springs.cpp, through the reference kernel of solutions/02_spring_dampers.cpp) must
// take one square root (l = |e*|) and one division (1 / l), its slowest instructions; and the
// step must move the particles' state and the springs' constants between the processor and
// wherever they are kept. The bench measures, on one thread:
//
//   arithmetic  the throughput of square root, division, and the two in a row as a spring has
//               them, in double and in float: a loop that does nothing else over kValues
//               independent values in the first-level cache, compiled as the engine's spring
//               loops are (the same flags; vectorised across values, as they are across
//               springs), and the same loop one value at a time;
//   memory      a streaming copy and a streaming read over arrays well past the last-level cache;
//   a floor     for each of bench speed's cloths: compute, a square root then a division per
//               spring; bandwidth, the bytes the step must move at the rate of a streaming copy
//               over as many bytes as the step touches (so the rate of whichever level of the
//               memory holds them); the floor is the larger of the two;
//   the engine  bench speed's `reference` row on 1 thread (its own code, run from here), and its
//               ratio to the floor.
//
//   threads     the engine's step on 1 and 2 threads (bench speed's cloth, taking turns), what two
//               threads lose of twice one's speed and to what (the step's serial part, the wake and
//               the barrier, the imbalance of the two ranges, each thread's share taking longer
//               than half the whole), and a model of the step on 8 and 16 cores from this run's
//               figures and an assumed bandwidth of a server socket.
//
// Limits are the fastest of their repeats (a busy machine only slows a repeat: the fastest is the
// nearest to what the machine can do), the engine the median of its repeats, as in bench speed.
// engine/fast/SPEED.md ("The roofline") explains the model and what it leaves out.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/resource.h>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "app/bench.hpp"
#include "app/build_info.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "fast/springs.hpp"
#include "io/files.hpp"
#include "io/run.hpp"
#include "scene/scene.hpp"

// The arithmetic loops' twins that take one value at a time: the compiler must not vectorise them.
#if defined(__clang__)
#define CLOTHLAB_NOT_VECTORISED
#define CLOTHLAB_NOT_VECTORISED_LOOP _Pragma("clang loop vectorize(disable) interleave(disable)")
#else
#define CLOTHLAB_NOT_VECTORISED __attribute__((optimize("no-tree-vectorize")))
#define CLOTHLAB_NOT_VECTORISED_LOOP
#endif

namespace clothlab::app {

namespace {

using Clock = std::chrono::steady_clock;

struct RooflineOptions {
  std::vector<int> sizes{64, 128, 256, 512};
  int repeats = 5;
  double min_seconds = 0.25;  // [s] one repeat of the engine's step; a hundredth for the limits
  double stream_mib = 0.0;    // [MiB] each array of the memory figures; 0: 4 x the last level
  double socket_gbs = 100.0;  // [GB/s] the model's server socket: an assumption, not measured
  std::string csv;
  bool force = false;  // --csv may replace a file the bench did not write
  bool quick = false;
};

// The least wall time [s] of one call of work(), over `repeats` repeats of as many calls as last
// `seconds` (calibrated on batches of 1, 2, 4, ... calls first).
template <class Work>
double fastest_call(int repeats, double seconds, Work work) {
  long calls = 1;
  for (;; calls *= 2) {
    const Clock::time_point start = Clock::now();
    for (long c = 0; c < calls; ++c)
      work();
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (elapsed >= seconds / 4 || calls >= (1L << 40)) {
      calls = std::max(1L, std::lround(static_cast<double>(calls) * seconds / elapsed));
      break;
    }
  }
  double best = HUGE_VAL;
  for (int r = 0; r < repeats; ++r) {
    const Clock::time_point start = Clock::now();
    for (long c = 0; c < calls; ++c)
      work();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count() /
                              static_cast<double>(calls));
  }
  return best;
}

// --- Arithmetic ----------------------------------------------------------------------------
//
// A pass replaces each of kValues values by op(value). The values are independent, so the
// processor has hundreds of operations in flight and the loop runs at the units' throughput, not
// at their latency. Each pass is a call of its own, kept out of line, so that the compiler cannot
// turn the loops inside out (one value through every pass: a chain, latency again). No value
// drifts to 0, 1 or infinity, which some dividers take faster: each op keeps a full mantissa
// (sqrt(v) 1.1 tends to 1.21, 1.7 / v swaps two values, 1.7 / sqrt(v) tends to 1.7^(2/3)).

constexpr long kValues = 512;  // 4 KiB of doubles: in the first-level cache

template <class T, class Op>
[[gnu::noinline]] void pass_vectorised(T* __restrict values, Op op) {
  for (long k = 0; k < kValues; ++k)
    values[k] = op(values[k]);
}

template <class T, class Op>
[[gnu::noinline]] CLOTHLAB_NOT_VECTORISED void pass_one_at_a_time(T* __restrict values, Op op) {
  CLOTHLAB_NOT_VECTORISED_LOOP
  for (long k = 0; k < kValues; ++k)
    values[k] = op(values[k]);
}

struct Throughput {
  double per_lane = 0.0;  // [ns] per value, the loop vectorised
  double scalar = 0.0;    // [ns] per value, one value an instruction
};

template <class T, class Op>
Throughput measure_op(Op op, int repeats, double seconds) {
  std::vector<T> values(kValues);
  const auto reset = [&] {
    for (long k = 0; k < kValues; ++k)
      values[static_cast<size_t>(k)] = T(1) + T(k) / T(kValues);
  };
  reset();
  const double vectorised =
      fastest_call(repeats, seconds, [&] { pass_vectorised(values.data(), op); });
  reset();
  const double scalar =
      fastest_call(repeats, seconds, [&] { pass_one_at_a_time(values.data(), op); });
  if (!std::isfinite(values[0])) throw std::logic_error("the arithmetic loop left its range");
  return {1e9 * vectorised / kValues, 1e9 * scalar / kValues};
}

struct Arithmetic {
  Throughput sqrt_d, div_d, pair_d, sqrt_f, div_f, pair_f;
};

template <class T>
void measure_ops(Throughput& sqrt_op, Throughput& div_op, Throughput& pair_op, int repeats,
                 double seconds) {
  // The multiplication of the first is not a division nor a root: it runs beside them, free.
  sqrt_op = measure_op<T>([](T v) { return std::sqrt(v) * T(1.1); }, repeats, seconds);
  div_op = measure_op<T>([](T v) { return T(1.7) / v; }, repeats, seconds);
  // A spring's pair: l = sqrt(e* . e*), then 1 / l, which waits for l.
  pair_op = measure_op<T>([](T v) { return T(1.7) / std::sqrt(v); }, repeats, seconds);
}

Arithmetic measure_arithmetic(int repeats, double seconds) {
  Arithmetic a;
  measure_ops<double>(a.sqrt_d, a.div_d, a.pair_d, repeats, seconds);
  measure_ops<float>(a.sqrt_f, a.div_f, a.pair_f, repeats, seconds);
  return a;
}

// --- Memory --------------------------------------------------------------------------------
//
// 64-bit words. The copy writes b = a xor s, with s = 0 known only at run time: a plain copy loop
// may become a call to memcpy, whose string moves can write whole cache lines without reading
// them first, which no store of the engine's loops does. The read takes the bitwise or of every
// word (associative, so it is vectorised, unlike a sum of doubles).

[[gnu::noinline]] void copy_words(const std::uint64_t* __restrict a, std::uint64_t* __restrict b,
                                  long n, std::uint64_t s) {
  for (long i = 0; i < n; ++i)
    b[i] = a[i] ^ s;
}

[[gnu::noinline]] std::uint64_t read_words(const std::uint64_t* __restrict a, long n) {
  std::uint64_t bits = 0;
  for (long i = 0; i < n; ++i)
    bits |= a[i];
  return bits;
}

// The largest cache of the first processor, as Linux describes it [bytes]; 0 if it does not.
double last_level_cache_bytes() {
  double largest = 0.0;
  for (int index = 0; index < 8; ++index) {
    std::ifstream in(fmt::format("/sys/devices/system/cpu/cpu0/cache/index{}/size", index));
    double size = 0.0;
    std::string unit;
    if (!(in >> size)) continue;
    in >> unit;
    const double scale = unit == "K"   ? 1024.0
                         : unit == "M" ? 1048576.0
                         : unit == "G" ? 1073741824.0
                                       : 1.0;
    largest = std::max(largest, size * scale);
  }
  return largest;
}

struct Memory {
  std::vector<std::uint64_t> a, b;
  double array_bytes = 0.0;  // of each array, for the figures past the last-level cache
  std::string why_size;
  double copy_gbs = 0.0, read_gbs = 0.0;  // [GB/s] past the last-level cache
  double copy_gbs_2 = 0.0;                // [GB/s] the copy split over 2 threads
  double socket_gbs = 0.0;  // [GB/s] the model's server socket (an assumption, --socket-gbs)
};

// A copy pass over `bytes` bytes in all (bytes / 2 read, bytes / 2 written) [GB/s], fastest of
// the repeats; the copy of the memory figures is the same with bytes = 2 arrays.
double copy_gbs(Memory& m, double bytes, int repeats, double seconds) {
  const long words = std::max(1L, std::lround(bytes / 16.0));
  const std::uint64_t zero = static_cast<std::uint64_t>(m.b.size() == 0);  // 0, unknown to GCC
  const double s =
      fastest_call(repeats, seconds, [&] { copy_words(m.a.data(), m.b.data(), words, zero); });
  return 16.0 * static_cast<double>(words) / s * 1e-9;
}

// The same copy split over the threads of `team` (each copies its own contiguous part), 8 bytes
// read and 8 written a word [GB/s], fastest of the repeats: the bandwidth the cores share.
double copy_gbs_threads(Memory& m, ThreadTeam& team, double bytes, int repeats, double seconds) {
  const long words = std::max(1L, std::lround(bytes / 16.0));
  const std::uint64_t zero = static_cast<std::uint64_t>(m.b.size() == 0);
  const long parts = team.size();
  const double s = fastest_call(repeats, seconds, [&] {
    team.run([&](int t) {
      const long begin = words * t / parts, end = words * (t + 1) / parts;
      copy_words(m.a.data() + begin, m.b.data() + begin, end - begin, zero);
    });
  });
  return 16.0 * static_cast<double>(words) / s * 1e-9;
}

// --- The bytes of a step -------------------------------------------------------------------

struct StepBytes {
  long particles = 0;
  long springs = 0;
  double moved = 0.0;    // [bytes] the least a step moves, each array once
  double touched = 0.0;  // [bytes] every byte a step reads or writes, counted once
};

// From the engine room's layout (fast/engine.cpp, fast/copies.hpp, fast/springs.cpp), for a cloth
// of springs and gravity moved by symplectic Euler in runs of steps (fast/resident.hpp), as
// bench speed and this bench step it:
//   per particle: x and v read from one copy and written to the other (4 x 24 bytes), f written
//     (24; the move reads it back), 1/m read by the move (8), m read by gravity (8): 136 bytes
//     moved, and as many touched, every array once (the two copies of x and v, their one f). The
//     world's own layout is read and written once a run, every 32 steps: not counted;
//   per spring: its l0 (8 bytes); and its ks and kd (16) unless its run is uniform, whose ks and
//     kd are read once for the run (16 bytes a run). A grid stencil's springs (fast/springs.hpp)
//     read their ks and kd once (16), and their rest lengths from its distinct rows of them
//     (8 bytes each) through one offset a row (8).
StepBytes step_bytes(const World& world) {
  StepBytes b;
  b.particles = static_cast<long>(world.particles.size());
  const double p = static_cast<double>(b.particles);
  b.moved = 4 * 24 * p + 24 * p + 8 * p;
  b.touched = (4 * 24 + 24 + 8) * p;
  for (const auto& effect : world.force_effects) {
    if (dynamic_cast<const UniformGravity*>(effect.get())) {
      b.moved += 8 * p;
      b.touched += 8 * p;
    } else if (const auto* s = dynamic_cast<const SpringDampers*>(effect.get())) {
      const fast::SpringLayout layout =
          fast::spring_layout(s->springs(), fast::spring_runs(s->springs()));
      double constants = 0.0;
      for (const fast::SpringRun& run : layout.runs) {
        const double length = static_cast<double>(run.length);
        constants += 8.0 * length + (run.uniform ? 16.0 : 16.0 * length);
      }
      for (const fast::SpringStencil& stencil : layout.stencils) {
        constants += 16.0 + 8.0 * static_cast<double>(stencil.l0.size()) +
                     8.0 * static_cast<double>(stencil.rows);
      }
      b.springs += static_cast<long>(s->springs().size());
      b.moved += constants;
      b.touched += constants;
    } else {
      throw std::logic_error(fmt::format("no byte count for the effect \"{}\"", effect->name()));
    }
  }
  return b;
}

// --- Threads -------------------------------------------------------------------------------
//
// bench speed's cloth stepped on 1 and on 2 threads, taking turns repeat by repeat (a busy
// machine slows both alike), each repeat a multiple of 32 steps so that it holds its share of
// the guard's energy check (every 32 steps: the springs' energies on the threads, their sum and
// the rest on the calling thread). World::thread_profile
// records, for each step's pass (the job of the threads, FastEngine::pass), how long it took as
// the step waited for it, and how long each thread worked in it (its time less its waits at the
// barrier). With T the step, J its pass, W the busiest thread's work and B the threads' mean
// work (2 threads; on 1 thread B1 is the pass's work and S1 = T1 - B1 the rest of the step),
// the 2-thread step's excess over half the 1-thread step splits exactly into four parts:
//
//   T2 - T1 / 2 = (T2 - J2 - S1 / 2)   serial: what the step does outside its pass, one thread
//               + (J2 - W2)            the wake and the barrier: the pass's time no thread worked
//                                      for (the last thread to wake, the first to wait)
//               + (W2 - B2)            imbalance: the busiest thread against the mean
//               + (B2 - B1 / 2)        slower work: a thread's half took longer than half the
//                                      whole (the memory they share; springs at the border of
//                                      the two ranges, taken by both)
//
// Times 2 / T2, each is what two threads lose of a speed-up of 2: T1 / T2 = 2 - their sum.

struct ThreadsSample {
  double step = 0.0;       // [s] a step
  ThreadProfile per_step;  // its pass, per step [s]
};

struct ThreadsRow {
  int n = 0;
  StepBytes bytes;
  ThreadsSample one, two;  // the repeat of median step time on 1 and on 2 threads
  // [s] the guard's energy check once (every 32 steps) on 1 and on 2 threads, fastest of 5
  double energy_check_one = 0.0, energy_check_two = 0.0;

  // What two threads lose of 2 (units of speed-up): they sum to 2 - speedup().
  double speedup() const { return one.step / two.step; }
  double lost(double seconds) const { return 2.0 * seconds / two.step; }
  double lost_serial() const {
    return lost(two.step - two.per_step.wall - (one.step - one.per_step.busy) / 2);
  }
  double lost_wake() const { return lost(two.per_step.wall - two.per_step.busiest); }
  double lost_imbalance() const { return lost(two.per_step.busiest - two.per_step.busy); }
  double lost_work() const { return lost(two.per_step.busy - one.per_step.busy / 2); }
  // Of the serial part, the energy check's: a 32nd of it a step on either; on 2 threads, what it
  // takes beyond half of its 1-thread time (were it split evenly, it would take that half).
  double lost_energy_check() const { return lost((energy_check_two - energy_check_one / 2) / 32); }
};

ThreadsRow measure_threads(int n, int repeats, double min_seconds) {
  ThreadsRow row;
  row.n = n;
  std::vector<std::unique_ptr<Scene>> scenes;
  std::vector<ThreadProfile> profiles(2);
  for (int threads : {1, 2}) {
    scenes.push_back(std::make_unique<Scene>(
        parse_scene(speed_cloth_scene(n, threads), "<bench roofline threads>")));
    scenes.back()->world.thread_profile = &profiles[static_cast<size_t>(threads - 1)];
  }
  row.bytes = step_bytes(scenes[0]->world);
  const auto steps = [](Scene& scene, long count) {
    for (long s = 0; s < count; s += kRunStepsAtOnce)  // as bench speed and clothlab run step
      scene.world.advance(scene.dt, std::min(kRunStepsAtOnce, count - s));
  };
  for (auto& scene : scenes) {
    steps(*scene, 2);  // warm up: the caches, the guard's start, the threads
    // Up to the guard's next energy check: from there each run of steps is one pass (it ends
    // at the check after it).
    steps(*scene, kRunStepsAtOnce - scene->world.steps % kRunStepsAtOnce);
  }
  // Steps a repeat: a multiple of 32 that lasts min_seconds on 1 thread.
  const Clock::time_point start = Clock::now();
  steps(*scenes[0], 32);
  const double batch = std::chrono::duration<double>(Clock::now() - start).count();
  const long count = 32 * std::max(1L, std::lround(min_seconds / batch));
  std::vector<std::vector<ThreadsSample>> samples(2);
  for (int r = 0; r < repeats; ++r) {
    for (size_t k = 0; k < 2; ++k) {
      profiles[k] = ThreadProfile{};
      const Clock::time_point begun = Clock::now();
      steps(*scenes[k], count);
      const double seconds = std::chrono::duration<double>(Clock::now() - begun).count();
      const double per = 1.0 / static_cast<double>(count);
      const ThreadProfile& p = profiles[k];
      samples[k].push_back({seconds * per, {p.jobs, p.wall * per, p.busiest * per, p.busy * per}});
      if (p.jobs != count / kRunStepsAtOnce) {
        throw std::logic_error(fmt::format(
            "bench roofline: {} steps on {} threads made {} passes of the threads; expected one "
            "for each {} steps",
            count, k + 1, p.jobs, kRunStepsAtOnce));
      }
    }
  }
  const auto median_sample = [](std::vector<ThreadsSample> all) {
    std::sort(all.begin(), all.end(),
              [](const ThreadsSample& a, const ThreadsSample& b) { return a.step < b.step; });
    return all[all.size() / 2];
  };
  row.one = median_sample(samples[0]);
  row.two = median_sample(samples[1]);
  for (size_t k = 0; k < 2; ++k) {
    const World& world = scenes[k]->world;
    (k == 0 ? row.energy_check_one : row.energy_check_two) =
        fastest_call(5, 0.0, [&] { world.guard.check_energy(world); });
  }
  return row;
}

// The model of a step on P cores: serial + max(work / P, bytes / bandwidth(P)) + wake(P).
struct CoresModel {
  double serial = 0.0;                                // [s] the 1-thread step outside its pass
  double work = 0.0;                                  // [s] the 1-thread pass's work
  double bytes = 0.0;                                 // [bytes] what a step must move
  double gbs_1 = 0.0, gbs_2 = 0.0, gbs_socket = 0.0;  // [GB/s] 1, 2 threads; a socket, assumed
  double wake_2 = 0.0;  // [s] a wake of 2 threads with a barrier in the job, nothing to do

  double bandwidth(int cores) const {  // [bytes/s]
    if (cores <= 1) return 1e9 * gbs_1;
    if (cores == 2) return 1e9 * gbs_2;
    return 1e9 * std::min(cores * gbs_2 / 2, gbs_socket);
  }
  // Each thread's arrival at the job's end and at its barrier is a turn at one shared counter:
  // assumed to grow with the threads that arrive after the first.
  double wake(int cores) const { return wake_2 * (cores - 1); }
  double compute(int cores) const { return work / cores; }
  double memory(int cores) const { return bytes / bandwidth(cores); }
  double step(int cores) const {
    return serial + std::max(compute(cores), memory(cores)) + wake(cores);
  }
  // What bounds P cores: the largest of the three terms after the serial part.
  const char* bound(int cores) const {
    const double c = compute(cores), m = memory(cores), w = wake(cores) + serial;
    return c >= m && c >= w ? "compute" : m >= w ? "bandwidth" : "serial+wake";
  }
  // The cores at which the socket's bandwidth catches up with the compute: work / P = bytes /
  // socket.
  double bandwidth_caps_at() const { return work * gbs_socket * 1e9 / bytes; }
};

CoresModel cores_model(const ThreadsRow& r, const Memory& m, double wake_2) {
  CoresModel model;
  model.work = r.one.per_step.busy;
  model.serial = r.one.step - model.work;
  model.bytes = r.bytes.moved;
  model.gbs_1 = m.copy_gbs;
  model.gbs_2 = m.copy_gbs_2;
  model.gbs_socket = m.socket_gbs;
  model.wake_2 = wake_2;
  return model;
}

std::string peak_memory() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return "unknown";
  return fmt::format("{:.0f} MB", static_cast<double>(usage.ru_maxrss) * 1024 * 1e-6);
}

// --- The table -----------------------------------------------------------------------------

struct Row {
  int n = 0;
  StepBytes bytes;
  double copy_gbs = 0.0;      // [GB/s] a streaming copy over bytes.touched
  double compute_ns = 0.0;    // [ns per spring] a square root then a division
  double bandwidth_ns = 0.0;  // [ns per spring] bytes.moved at copy_gbs
  double engine_ns = 0.0;     // [ns per spring-step] bench speed's reference, 1 thread
  double floor_ns() const { return std::max(compute_ns, bandwidth_ns); }
};

std::string load_average() {
  double load[1];
  return getloadavg(load, 1) == 1 ? fmt::format("{:.2f}", load[0]) : "unknown";
}

constexpr std::string_view kRooflineHeader =
    "n,particles,springs,data_bytes,bytes_per_spring,copy_gb_per_s,compute_floor_ns,"
    "bandwidth_floor_ns,floor_ns,engine_ns,engine_over_floor,engine_1_thread_ns,"
    "engine_2_threads_ns,speedup_2,lost_serial,lost_energy_check,lost_wake,lost_imbalance,"
    "lost_work,model_2_ns,model_8_ns,model_16_ns,kernel_ns,engine_over_kernel";

int bench_roofline(RooflineOptions opt) {
  // Where the CSV goes, before the measurements' minutes are spent.
  if (!opt.csv.empty()) check_bench_file(opt.csv, "--csv", kRooflineHeader, opt.force);
  if (opt.quick) {
    opt.sizes = {16, 32};
    opt.repeats = 3;
    opt.min_seconds = 0.02;
    if (opt.stream_mib == 0.0) opt.stream_mib = 16.0;
  }
  // The limits in many short repeats: on a machine shared with other programs, a repeat shorter
  // than the scheduler's time slice often runs alone on its core, and the fastest one counts.
  const double seconds = opt.min_seconds / 100;
  const int limit_repeats = std::max(3, 4 * opt.repeats);
  const int stream_repeats = std::max(3, opt.repeats);  // a pass past the cache takes long anyway
  fmt::print(
      "bench roofline: this machine's limits on one thread, and the engine's symplectic Euler "
      "step\n  against them ({} build, {}; load average {} at the start)\n\n",
      kKernels,
      kLinkTimeOptimised ? "kernels inlined by link-time optimisation"
                         : "link-time optimisation off: the spring loops are not vectorised",
      load_average());

  const Arithmetic a = measure_arithmetic(limit_repeats, seconds);
  fmt::print(
      "  arithmetic: {} independent values in the first-level cache, each pass replacing every one "
      "(fastest of {} repeats)\n",
      kValues, limit_repeats);
  fmt::print("  {:<34} {:>15} {:>15} {:>15} {:>15}\n", "ns per value", "double, vector",
             "double, scalar", "float, vector", "float, scalar");
  const auto op_row = [](const char* name, const Throughput& d, const Throughput& f) {
    fmt::print("  {:<34} {:>15.3f} {:>15.3f} {:>15.3f} {:>15.3f}\n", name, d.per_lane, d.scalar,
               f.per_lane, f.scalar);
  };
  op_row("square root", a.sqrt_d, a.sqrt_f);
  op_row("division", a.div_d, a.div_f);
  op_row("square root, then division", a.pair_d, a.pair_f);
  fmt::print(
      "  (vector: the loop compiled as the engine's spring loops, several values an instruction; "
      "ns per lane.\n   scalar: the same loop one value an instruction; ns per operation.)\n\n");

  // The memory figures, past the last-level cache: 4 times its size, within 64 MiB to 2 GiB.
  Memory m;
  const double llc = last_level_cache_bytes();
  if (opt.stream_mib > 0.0) {
    m.array_bytes = opt.stream_mib * 1048576.0;
    m.why_size = opt.quick ? "--quick: a test of the wiring, not past the caches" : "--stream-mib";
  } else {
    m.array_bytes = std::clamp(4.0 * llc, 64.0 * 1048576.0, 2048.0 * 1048576.0);
    m.why_size = llc > 0.0 ? fmt::format("the last-level cache is {:.0f} MiB", llc / 1048576.0)
                           : "the cache sizes are unknown";
  }
  // Room for the cloths' copies too, each over as many bytes as the step touches.
  std::vector<Row> rows;
  double largest = m.array_bytes;
  for (int n : opt.sizes) {
    Row row;
    row.n = n;
    row.bytes = step_bytes(parse_scene(speed_cloth_scene(n, 1), "<bench roofline>").world);
    largest = std::max(largest, row.bytes.touched / 2);
    rows.push_back(row);
  }
  const size_t words = static_cast<size_t>(std::ceil(largest / 8));
  m.a.resize(words);
  m.b.resize(words);
  for (size_t i = 0; i < words; ++i)  // every page touched before the clock starts
    m.a[i] = i;
  const long stream_words = std::lround(m.array_bytes / 8);
  m.copy_gbs = copy_gbs(m, 16.0 * static_cast<double>(stream_words), stream_repeats, seconds);
  std::uint64_t bits = 0;
  const double read_s =
      fastest_call(stream_repeats, seconds, [&] { bits |= read_words(m.a.data(), stream_words); });
  m.read_gbs = 8.0 * static_cast<double>(stream_words) / read_s * 1e-9;
  if (bits == 0) throw std::logic_error("the streaming read read nothing");
  ThreadTeam pair(2);
  m.copy_gbs_2 =
      copy_gbs_threads(m, pair, 16.0 * static_cast<double>(stream_words), stream_repeats, seconds);
  m.socket_gbs = opt.socket_gbs;
  fmt::print(
      "  memory: arrays of {:.0f} MiB each ({}), fastest of {} repeats\n"
      "    streaming copy, b = a xor s (8 bytes read and 8 written a word)  {:8.2f} GB/s\n"
      "    the same copy on 2 threads, each its half                         {:8.2f} GB/s "
      "({:.2f} times 1 thread)\n"
      "    streaming read, the or of every word                             {:8.2f} GB/s\n\n",
      m.array_bytes / 1048576.0, m.why_size, stream_repeats, m.copy_gbs, m.copy_gbs_2,
      m.copy_gbs_2 / m.copy_gbs, m.read_gbs);

  for (Row& row : rows) {
    row.copy_gbs = copy_gbs(m, row.bytes.touched, limit_repeats, seconds);
    row.compute_ns = a.pair_d.per_lane;
    row.bandwidth_ns = row.bytes.moved / row.copy_gbs / static_cast<double>(row.bytes.springs);
    row.engine_ns = reference_ns_per_spring_step(row.n, opt.repeats, opt.min_seconds);
  }
  const double kernel_ns = kernel_ns_per_spring(opt.repeats, opt.min_seconds);

  fmt::print(
      "  the floor of a step, per spring: compute = a square root then a division (double, "
      "vector); bandwidth =\n  the bytes a step moves at a streaming copy's rate over as many "
      "bytes as it touches; floor = the larger.\n  engine: bench speed's reference, 1 thread, "
      "median of {} repeats of at least {} s.\n",
      opt.repeats, opt.min_seconds);
  fmt::print("  {:>4} {:>8} {:>8} {:>9} {:>9} {:>10} {:>10} {:>8}  {:<9} {:>9} {:>12} {:>13}\n",
             "N", "springs", "data MB", "B/spring", "copy GB/s", "compute ns", "bandwidth",
             "floor ns", "bound by", "engine ns", "engine/floor", "engine/kernel");
  for (const Row& r : rows) {
    fmt::print(
        "  {:>4} {:>8} {:>8.2f} {:>9.1f} {:>9.2f} {:>10.3f} {:>10.3f} {:>8.3f}  {:<9} {:>9.3f} "
        "{:>12.2f} {:>13.2f}\n",
        r.n, r.bytes.springs, r.bytes.touched * 1e-6,
        r.bytes.moved / static_cast<double>(r.bytes.springs), r.copy_gbs, r.compute_ns,
        r.bandwidth_ns, r.floor_ns(), r.compute_ns >= r.bandwidth_ns ? "compute" : "bandwidth",
        r.engine_ns, r.engine_ns / r.floor_ns(), r.engine_ns / kernel_ns);
  }
  // The kernel against the compute floor: how much of a spring's own arithmetic the floor's
  // square root and division are. Where the divider is fast, the rest of the kernel's work (its
  // other operations, loads and stores) sets its pace, and no arrangement of the step that keeps
  // the kernel's operations can come near the floor.
  fmt::print(
      "  kernel: the spring loop alone (bench speed's kernel row: 256 springs in the first-level "
      "cache, no copies,\n  no guard, no move), median of {} repeats: {:.3f} ns per spring, {:.2f} "
      "times the compute floor.\n",
      opt.repeats, kernel_ns, kernel_ns / a.pair_d.per_lane);

  // Threads: 1 against 2, what two lose of 2, and the model for 8 and 16 cores.
  std::vector<ThreadsRow> threads;
  for (const Row& r : rows)
    threads.push_back(measure_threads(r.n, opt.repeats, opt.min_seconds));
  const double wake_2 = 1e-9 * wake_ns(2, 1, opt.quick ? 500 : 20000);
  fmt::print(
      "\n  threads: the same step on 1 and on 2 threads, taking turns, {} repeats of a multiple of "
      "32 steps (the guard's\n  energy check comes every 32), the repeat of median time; ns per "
      "spring-step. Two threads lose of a speed-up of 2:\n  serial, the step's work outside its "
      "pass (of which the energy check: on 2 threads, its time beyond half its 1-thread time);\n  "
      "wake, the pass's time no thread worked; imbalance, "
      "the busiest thread over the mean; slower work, a thread's half over half of one thread's "
      "whole.\n  They add up to 2 - speed-up. (A wake of 2 threads with one barrier and nothing "
      "to do: {:.0f} ns.)\n",
      opt.repeats, wake_2 * 1e9);
  fmt::print("  {:>4} {:>9} {:>9} {:>8}  {:>8} {:>14} {:>7} {:>9} {:>11}\n", "N", "1 thread",
             "2 threads", "speed-up", "serial", "(energy check)", "wake", "imbalance",
             "slower work");
  for (const ThreadsRow& t : threads) {
    const double springs = static_cast<double>(t.bytes.springs);
    fmt::print(
        "  {:>4} {:>9.3f} {:>9.3f} {:>8.2f}  {:>8.3f} {:>14.3f} {:>7.3f} {:>9.3f} {:>11.3f}\n", t.n,
        1e9 * t.one.step / springs, 1e9 * t.two.step / springs, t.speedup(), t.lost_serial(),
        t.lost_energy_check(), t.lost_wake(), t.lost_imbalance(), t.lost_work());
  }

  fmt::print(
      "\n  model of a step on P cores: serial + max(work / P, bytes / bandwidth(P)) + wake(P), "
      "from this run:\n  serial and work, the 1-thread step outside and inside its pass; bytes, "
      "what a step must move (above);\n  bandwidth(P), the streaming copy on 1 and 2 threads as "
      "measured, past 2 min(P x the 2-thread copy's\n  share a core, {:.0f} GB/s), a server "
      "socket's bandwidth: ASSUMED, not measured (--socket-gbs); wake(P), the\n  2-thread wake "
      "with a barrier above, times P - 1 (assumed: each thread's arrival a turn at one shared "
      "counter).\n  The 2-core model leaves out the imbalance and the slower work measured above. "
      "ns per spring-step:\n",
      m.socket_gbs);
  fmt::print("  {:>4} {:>8} {:>9} {:>9} {:>9} {:>9} {:>8} {:>9} {:>8} {:>11} {:>14}\n", "N",
             "serial", "work", "P=2 model", "measured", "P=8", "speed-up", "P=16", "speed-up",
             "bound at 16", "bandwidth caps");
  std::vector<CoresModel> models;
  for (const ThreadsRow& t : threads) {
    models.push_back(cores_model(t, m, wake_2));
    const CoresModel& model = models.back();
    const double ns = 1e9 / static_cast<double>(t.bytes.springs);
    fmt::print(
        "  {:>4} {:>8.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>8.2f} {:>9.3f} {:>8.2f} {:>11} "
        "{:>14}\n",
        t.n, ns * model.serial, ns * model.work, ns * model.step(2), ns * t.two.step,
        ns * model.step(8), model.step(1) / model.step(8), ns * model.step(16),
        model.step(1) / model.step(16), model.bound(16),
        fmt::format("at {:.0f} cores", model.bandwidth_caps_at()));
  }
  fmt::print("  (load average {} at the end; peak memory of this run {})\n", load_average(),
             peak_memory());

  if (!opt.csv.empty()) {
    const std::filesystem::path csv = opt.csv;
    if (csv.has_parent_path()) std::filesystem::create_directories(csv.parent_path());
    std::string table = std::string(kRooflineHeader) + "\n";
    for (size_t k = 0; k < rows.size(); ++k) {
      const Row& r = rows[k];
      const ThreadsRow& t = threads[k];
      const CoresModel& model = models[k];
      const double ns = 1e9 / static_cast<double>(t.bytes.springs);
      fmt::format_to(std::back_inserter(table),
                     "{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},"
                     "{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},"
                     "{:.6g},{:.6g},{:.6g}\n",
                     r.n, r.bytes.particles, r.bytes.springs, r.bytes.touched,
                     r.bytes.moved / static_cast<double>(r.bytes.springs), r.copy_gbs, r.compute_ns,
                     r.bandwidth_ns, r.floor_ns(), r.engine_ns, r.engine_ns / r.floor_ns(),
                     ns * t.one.step, ns * t.two.step, t.speedup(), t.lost_serial(),
                     t.lost_energy_check(), t.lost_wake(), t.lost_imbalance(), t.lost_work(),
                     ns * model.step(2), ns * model.step(8), ns * model.step(16), kernel_ns,
                     r.engine_ns / kernel_ns);
    }
    write_whole_file(csv, table);
    fmt::print("\n  wrote {}\n", csv.string());
  }
  return 0;
}

}  // namespace

void add_bench_roofline_command(CLI::App& bench) {
  static RooflineOptions options;
  RooflineOptions& o = options;
  CLI::App* roofline = bench.add_subcommand(
      "roofline",
      "This machine's limits (square root and division throughput, memory bandwidth) and the "
      "engine's step on N x N cloths against the floor they set (table and CSV)");
  add_cloth_sizes_option(*roofline, o.sizes);
  roofline->add_option("--repeats", o.repeats, "Repeats of each measurement")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  roofline
      ->add_option(
          "--min-seconds", o.min_seconds,
          "Wall time [s] of each repeat of the engine's step (a hundredth for the limits')")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  roofline
      ->add_option("--stream-mib", o.stream_mib,
                   "Size [MiB] of each array of the memory figures (default: 4 x the last-level "
                   "cache, within 64 to 2048)")
      ->check(CLI::Range(1.0, 65536.0));
  roofline
      ->add_option("--socket-gbs", o.socket_gbs,
                   "Bandwidth [GB/s] the model of 8 and 16 cores assumes for a server socket (an "
                   "assumption, not a measurement)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  roofline->add_option("--csv", o.csv, "Write one row per cloth size to this CSV file");
  add_bench_force_option(*roofline, o.force);
  roofline->add_flag("--quick", o.quick,
                     "Sizes 16 and 32, short repeats, 16 MiB arrays (for tests)");
  roofline->callback([] { run_bench_command("roofline", [] { return bench_roofline(options); }); });
}

}  // namespace clothlab::app
