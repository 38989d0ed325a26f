// Lesson 11: the game loop. Drives banner.toml through clothlab::Simulation the way a game
// would, on a simulated frame clock (nothing sleeps: the frames are as long as the program
// says, so the output is the same on every machine), and measures what the lesson quotes:
//   1. the accumulator frame by frame: substeps, leftover, alpha, dropped time;
//   2. the same 2 s cut into frames four ways: the same steps and the same state, bit for bit,
//      and what a plain `while (acc >= dt)` loop counts instead;
//   3. a game session at 60 frames per second: a corner dragged with move_pin, a gust of wind
//      ramped in with set_wind, the banner's state every half second;
//   4. the same gust switched on at once: how much harder the force jumps;
//   5. the spiral of death on a machine too slow for its step, with and without the cap;
//   6. a frame that ends on a whole step, and a frame after an hour's pause: the leftover to
//      its last digits, where a negative one or a counting loop's drift would show.
// `lesson11 --view FILE.html` also writes the viewer page of the session in 3.
// ./build/lesson11 runs on the reference solutions, ./build/lesson11-student on your exercises;
// while an exercise is still a stub, the program names it and exits with code 4.
#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "../common/lesson.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "io/viewer.hpp"
#include "scene/simulation.hpp"

using namespace clothlab;
using namespace clothlab::lesson;

namespace {

// The scene lies next to this file.
const std::filesystem::path kBanner = std::filesystem::path(__FILE__).parent_path() / "banner.toml";

constexpr Index kGrabbed = 12;  // the top-right corner, pinned by the scene

void accumulator_by_hand() {
  Simulation sim(kBanner);
  fmt::print("1. The accumulator, frame by frame (dt = {} ms, at most {} substeps a frame)\n",
             sim.dt() * 1e3, sim.max_substeps());
  fmt::print("   {:>10}  {:>9}  {:>12}  {:>6}  {:>12}\n", "frame [ms]", "substeps", "leftover [ms]",
             "alpha", "dropped [ms]");
  // 60 fps, a slow frame, two 144 Hz frames, a 0.4 s hitch (a window dragged), 60 fps again.
  for (double frame : {1.0 / 60, 1.0 / 60, 1.0 / 30, 1.0 / 144, 1.0 / 144, 0.4, 1.0 / 60}) {
    const long n = sim.advance(frame);
    fmt::print("   {:>10.3f}  {:>9}  {:>12.4f}  {:>6.3f}  {:>12.1f}\n", frame * 1e3, n,
               sim.leftover() * 1e3, sim.alpha(), sim.dropped_time() * 1e3);
  }
  fmt::print("   simulated {:.4f} s in {} steps; {:.1f} ms of the 0.4 s hitch were dropped.\n\n",
             sim.time(), sim.steps(), sim.dropped_time() * 1e3);
}

// Frame times of a jittery 60 fps game: 8 to 25 ms each, the last one cut to end at `total`.
std::vector<double> jittery_frames(double total, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> frame(0.008, 0.025);
  std::vector<double> frames;
  double t = 0.0;
  for (;;) {
    const double f = frame(rng);
    if (t + f >= total) break;
    frames.push_back(f);
    t += f;
  }
  frames.push_back(total - t);
  return frames;
}

void same_time_same_steps() {
  fmt::print("2. Two seconds, cut into frames four ways\n");
  struct Split {
    const char* name;
    std::vector<double> frames;
  };
  const std::vector<Split> splits = {{"120 frames of 1/60 s", std::vector<double>(120, 1.0 / 60)},
                                     {"60 frames of 1/30 s", std::vector<double>(60, 1.0 / 30)},
                                     {"jittery frames, 8-25 ms", jittery_frames(2.0, 2026)},
                                     {"one frame of 2 s", {2.0}}};
  Matrix3X x_first, v_first;
  for (const Split& split : splits) {
    Simulation sim(kBanner, 100000);
    long steps = 0;
    for (double frame : split.frames)
      steps += sim.advance(frame);
    const Particles& p = sim.world().particles;
    if (x_first.size() == 0) {
      x_first = p.x;
      v_first = p.v;
    }
    fmt::print("   {:<26} {:>4} frames  {:>5} steps   same state as the first: {}\n", split.name,
               split.frames.size(), steps,
               p.x == x_first && p.v == v_first ? "yes, bit for bit" : "NO");
  }
  // The textbook loop, `while (acc >= dt) { step; acc -= dt; }`, on the first split.
  const double dt = 0.001;
  double acc = 0.0;
  long plain = 0;
  for (int k = 0; k < 120; ++k) {
    acc += 1.0 / 60;
    while (acc >= dt) {
      acc -= dt;
      ++plain;
    }
  }
  fmt::print(
      "   the plain loop `while (acc >= dt) acc -= dt` counts {} steps in 120 frames of 1/60 s "
      "and\n"
      "   keeps {:.13f} dt for later: 1/60 and 0.001 are not exact in binary.\n\n",
      plain, acc / dt);
}

// The acceleration of the banner's centre of mass, F / M [m/s^2]: springs cancel, what is left
// is weight, wind and the pins' pull.
Vec3 centre_acceleration(const World& w) {
  Matrix3X f(3, w.particles.size());
  w.compute_forces(w.particles.x, w.particles.v, f);
  return f.rowwise().sum() / w.particles.m.sum();
}

struct Session {
  double largest_jerk = 0.0;  // the largest change of centre_acceleration in one substep
                              // while the gust comes in [m/s^2]
};

// Six seconds at 60 frames per second. From 1 s to 2 s the player drags the top-right corner
// out and back; at 3 s a gust (2, 0, 6) m/s comes in over `ramp` seconds.
Session game_session(double ramp, bool print, const std::string& view) {
  Simulation sim(kBanner);
  const Vec3 grab_start = sim.positions().col(kGrabbed);
  const Vec3 gust(2.0, 0.0, 6.0);
  ViewerRecorder viewer(sim.scene().title, "lessons/11-game-loop/banner.toml + lesson11", 362);
  Session out;
  Vec3 a_last = Vec3::Zero();
  bool measuring = false;
  // Measures the jerk in every substep while the gust comes in (3 s to 3 s + ramp + 0.1 s).
  sim.on_substep([&](Simulation& s) {
    if (!measuring) return;
    const Vec3 a = centre_acceleration(s.world());
    out.largest_jerk = std::max(out.largest_jerk, (a - a_last).norm());
    a_last = a;
  });
  if (print)
    fmt::print("   {:>5}  {:>5}  {:>16}  {:>22}  {:>10}  {:>8}\n", "t [s]", "steps", "wind [m/s]",
               "grabbed corner [m]", "billow [m]", "KE [mJ]");
  if (!view.empty()) viewer.offer(sim.world());
  const double frame = 1.0 / 60.0;
  for (int k = 1; k <= 360; ++k) {
    const double clock = k * frame;  // the game's clock at the end of this frame [s]
    if (clock > 1.0 && clock <= 2.0 + 1e-9) {
      // Dragging: where the mouse is at the end of this frame, out to 0.3 m along x and
      // 0.4 m against the wind, and back.
      const double s = std::sin(std::numbers::pi * (clock - 1.0));
      sim.move_pin(kGrabbed, grab_start + s * Vec3(0.3, 0.1, -0.4));
    }
    if (k == 180) {  // at 3 s, between frames
      sim.set_wind(gust, ramp);
      a_last = centre_acceleration(sim.world());
      measuring = true;
    }
    if (clock > 3.0 + ramp + 0.1) measuring = false;
    sim.advance(frame);
    if (!view.empty()) viewer.offer(sim.world());
    if (print && k % 30 == 0) {
      const Vec3 w = sim.wind();
      const Vec3 c = sim.positions().col(kGrabbed);
      const double cz = std::abs(c.z()) < 5e-4 ? 0.0 : c.z();  // back home: no "-0.000"
      fmt::print(
          "   {:>5.2f}  {:>5}  ({:>4.2f}, {:.0f}, {:>4.2f})  ({:>6.3f}, {:>5.3f}, {:>6.3f})  "
          "{:>10.3f}  {:>8.2f}\n",
          sim.time(), sim.steps(), w.x(), w.y(), w.z(), c.x(), c.y(), cz,
          sim.positions().row(2).mean(), sim.world().kinetic_energy() * 1e3);
    }
  }
  if (!view.empty()) {
    viewer.write(sim.world(), view);
    fmt::print("   wrote {}: play it to watch the drag (1-2 s) and the gust (from 3 s)\n", view);
  }
  return out;
}

void spiral_of_death() {
  fmt::print(
      "5. A machine too slow for its step: each step costs 1.25 ms of wall time for dt = 1 ms,\n"
      "   drawing costs 5 ms, and the next frame lasts as long as this one took.\n");
  for (long cap : {100000L, 20L}) {
    Simulation sim(kBanner, cap);
    fmt::print("   at most {} substeps a frame; frame time [ms] / substeps taken:\n   ", cap);
    double frame = 1.0 / 60;
    for (int k = 0; k < 10; ++k) {
      const long n = sim.advance(frame);
      fmt::print(" {:.0f}/{}", frame * 1e3, n);
      frame = 0.005 + 0.00125 * static_cast<double>(n);
    }
    fmt::print("\n   simulated {:.0f} ms, dropped {:.0f} ms of the {:.0f} ms the frames lasted\n",
               sim.time() * 1e3, sim.dropped_time() * 1e3,
               (sim.time() + sim.dropped_time() + sim.leftover()) * 1e3);
  }
}

// Three frames of 1/60 s (the third ends on a whole step: 50 ms), then a frame of an hour, the
// game's window left in the background, and one more. The leftover is printed in steps to three
// significant digits, so that a rounding error shows with its sign: the reference's is 0 or a
// fraction of a step, never below 0. The hour holds 3.6 million steps; all but the cap's are
// dropped, and a frame that counts them by subtracting dt one step at a time collects a
// rounding error from each subtraction.
void long_pause() {
  Simulation sim(kBanner);
  fmt::print(
      "6. Three frames of 1/60 s, a pause of an hour, one more frame (at most {} substeps a "
      "frame)\n",
      sim.max_substeps());
  fmt::print("   {:>12}  {:>9}  {:>15}  {:>10}  {:>12}\n", "frame [s]", "substeps", "leftover [dt]",
             "alpha", "dropped [s]");
  for (double frame : {1.0 / 60, 1.0 / 60, 1.0 / 60, 3600.0, 1.0 / 60}) {
    const long n = sim.advance(frame);
    fmt::print("   {:>12.6f}  {:>9}  {:>15.3g}  {:>10.3g}  {:>12.3f}\n", frame, n,
               sim.leftover() / sim.dt(), sim.alpha(), sim.dropped_time());
  }
}

}  // namespace

int main(int argc, char** argv) {
  return lesson::run("lesson11", [&]() -> int {
    std::string view;
    if (argc == 3 && std::string(argv[1]) == "--view") {
      view = argv[2];
    } else if (argc != 1) {
      fmt::print(stderr, "usage: lesson11 [--view FILE.html]\n");
      return 2;
    }
    accumulator_by_hand();
    same_time_same_steps();
    fmt::print(
        "3. A game session at 60 fps: the top-right corner dragged from 1 s to 2 s, a gust of\n"
        "   (2, 0, 6) m/s ramped in over 0.5 s from 3 s (billow: mean z of the banner)\n");
    const Session ramped = game_session(0.5, true, view);
    fmt::print("\n4. The gust's largest change of the centre's acceleration in one substep\n");
    const Session instant = game_session(0.0, false, "");
    fmt::print("   ramped over 0.5 s: {:.4f} m/s^2;  at once: {:.4f} m/s^2 ({:.0f} times more)\n\n",
               ramped.largest_jerk, instant.largest_jerk,
               instant.largest_jerk / ramped.largest_jerk);
    spiral_of_death();
    fmt::print("\n");
    long_pause();
    return 0;
  });
}
