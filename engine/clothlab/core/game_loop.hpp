// game_loop.hpp: driving the engine from a game or an interactive program (lesson 11).
//
// Game-physics lecture, "game engine interface": the game owns the clock and the screen, the
// engine owns the physics. A game's frames last whatever the machine makes them (16.7 ms at
// 60 fps, 33 ms at 30 fps, a 200 ms hitch now and then), but the engine must always step by
// the scene's dt: a larger step may be unstable (lesson 08), and a step that changes with the
// frame rate makes the motion depend on the machine. So a frame's time goes into an
// accumulator, and the engine takes as many whole steps of dt (substeps) as it holds:
//
//   accumulator += frame_time
//   while accumulator >= dt:  step(dt), accumulator -= dt
//
// The time left over, less than one dt, waits for the next frame. What the game draws lies
// between the last two states, alpha = leftover / dt of the way from the older to the newer.
//
// Determinism. The substeps a sequence of frames takes depends only on the total time, not on
// how it was cut into frames: 120 frames of 1/60 s, 60 of 1/30 s and one of 2 s all take 1200
// steps of dt = 1/600 s. In floating point 1/60 and 1/600 are not exact, and the leftover after
// "10 steps" can come out as -1e-19 s or as dt - 1e-19 s; the second would delay a step by a
// whole frame. So a time within kStepTolerance * dt short of a whole step counts as that step,
// and the leftover it leaves (a rounding error, never more than that tolerance) is taken as 0.
// The leftover stays below dt, so rounding errors never grow with the length of the run.
//
// The spiral of death. If a step costs more wall time than the dt it simulates, each frame
// lasts longer than the one before and asks for yet more steps. A cap on the substeps of one
// frame breaks the loop: the time beyond it is dropped (the game slows down instead of
// freezing), and dropped_time() says how much.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "scene/scene.hpp"

namespace clothlab {

class Aerodynamics;

// A time this close to a whole number of steps, as a fraction of dt, counts as that number.
// 1e-6 dt is a millionth of a step: far above the rounding of a sum of frame times (about
// 1e-16 dt per frame, and the leftover is reset at every whole step), far below anything a
// clock measures or a player notices.
inline constexpr double kStepTolerance = 1e-6;

// What one frame asks of the engine.
struct Substeps {
  long count = 0;         // whole steps of dt to take now
  double leftover = 0.0;  // time carried to the next frame [s], in [0, dt)
  double dropped = 0.0;   // time given up because the steps due exceeded the cap [s]
};

// Exercise ex11.1: the accumulator's arithmetic for one frame. `leftover` [s] is what the last
// frame left, `frame_time` [s] this frame's time (both >= 0), `dt` [s] the step and
// `max_substeps` (>= 1) the cap. The steps due are the whole steps of dt in leftover +
// frame_time, a time within kStepTolerance * dt short of a step counting as that step; at most
// max_substeps are taken and the whole steps beyond the cap are dropped; the fraction of a step
// that remains is the new leftover.
Substeps accumulate(double leftover, double frame_time, double dt, long max_substeps);

// A scene, stepped by frame times. Errors of the engine (SimulationError from the guard)
// propagate from advance() with their message; the simulation cannot continue after one.
class Simulation {
 public:
  // max_substeps: the cap per frame; 0 takes the steps of a quarter of a second, at least 1.
  explicit Simulation(Scene scene, long max_substeps = 0);
  explicit Simulation(const std::filesystem::path& scene_file, long max_substeps = 0);

  // Adds frame_time [s] (finite, >= 0) to the accumulator and takes the substeps of dt that are
  // due (accumulate() above). Returns how many it took.
  long advance(double frame_time);

  // Where rendering lies between the last two states: leftover / dt, in [0, 1).
  double alpha() const { return leftover_ / scene_.dt; }
  double leftover() const { return leftover_; }     // [s] time waiting for the next step
  double dropped_time() const { return dropped_; }  // [s] time given up at the cap, in all
  long max_substeps() const { return max_substeps_; }
  void set_max_substeps(long n);  // n >= 1

  // Particle positions [m], one column per particle (a reference: no copy).
  const Matrix3X& positions() const { return scene_.world.particles.x; }
  // Positions between the state before the last substep and the current one, alpha of the
  // way: (1 - alpha) x_before + alpha x. Draws smooth motion when frames and steps do not line
  // up, one step behind the simulation. Updated in a buffer kept between calls.
  const Matrix3X& interpolated_positions();
  // Unit per-particle normals for shading: the area-weighted average of the normals of the
  // triangles around each particle (zero for a particle in no triangle, all zero when the
  // scene has no surface). Recomputed in a buffer kept between calls, only after a step (a
  // program that moves particles by hand between steps sees the normals of the last step).
  const Matrix3X& normals();

  // Adds force [N] on particle i in every substep from the next one on, until clear_forces().
  void apply_force(Index i, const Vec3& force);
  void clear_forces();

  // Pins particle i where it is (inv_m = 0, v = 0) / frees it again (inv_m = 1/m).
  void pin(Index i);
  void unpin(Index i);
  // Moves pinned particle i to target [m] during the substeps of the next advance that takes
  // any: in each substep by an equal share, at the velocity (target - start) / (n dt), so its
  // springs and dampers see a moving particle, never a jump. It stays pinned, at rest, at the
  // target afterwards. Dragging with a mouse is a pin and one move_pin per frame. A move_pin
  // called from on_substep, in the middle of a frame, waits for the next frame.
  void move_pin(Index i, const Vec3& target);

  // Changes the wind of [aerodynamics] to v_air [m/s], linearly over ramp_time [s] of
  // simulated time, one share per substep, so the force on the cloth changes by a little each
  // step instead of jumping (ramp_time 0: from the next substep on). A second call during a
  // ramp starts from the wind blowing then. Throws std::logic_error if the scene has none.
  void set_wind(const Vec3& v_air, double ramp_time);
  Vec3 wind() const;  // the wind blowing now [m/s]

  // Called before every substep, with the simulation: the place for input that must land on
  // a substep rather than on a frame (a force switched on at step 500 acts from step 500 on,
  // whatever the frame times). Empty: nothing is called.
  void on_substep(std::function<void(Simulation&)> callback) { on_substep_ = std::move(callback); }

  double time() const { return scene_.world.t; }  // simulated time [s]
  long steps() const { return scene_.world.steps; }
  double dt() const { return scene_.dt; }  // [s]
  Scene& scene() { return scene_; }
  World& world() { return scene_.world; }
  const World& world() const { return scene_.world; }

 private:
  struct PinMove {
    Index i;
    Vec3 target;  // [m]
  };
  struct WindRamp {
    Vec3 from, to;   // [m/s]
    long steps = 0;  // substeps the ramp takes
    long done = 0;   // substeps taken
  };
  class ExternalForces;

  void check_particle(Index i, const char* what) const;
  Aerodynamics& aerodynamics() const;

  Scene scene_;
  long max_substeps_;
  double leftover_ = 0.0;  // [s]
  double dropped_ = 0.0;   // [s]
  Matrix3X x_before_;      // positions before the last substep [m]
  Matrix3X x_shown_;       // interpolated positions [m]
  Matrix3X normals_;
  long normals_step_ = -1;  // the step normals_ belongs to
  std::vector<PinMove> moves_;
  WindRamp ramp_;
  ExternalForces* external_ = nullptr;  // owned by the world's force effects, made on demand
  bool restart_guard_ = false;
  std::function<void(Simulation&)> on_substep_;
};

}  // namespace clothlab
