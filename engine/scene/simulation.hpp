// simulation.hpp: a scene driven by frame times, for games and interactive programs (lesson 11).
//
// The accumulator's arithmetic (exercise ex11.1) lives in the physics core,
// clothlab/core/game_loop.hpp; this is the driver around it: a scene read from a file, stepped by
// the substeps each frame is due, with the game's inputs (forces, pins dragged along a path,
// wind ramped over substeps) landing on substeps, and positions interpolated between the last
// two states for drawing.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "clothlab/core/game_loop.hpp"
#include "scene/scene.hpp"

namespace clothlab {

class Aerodynamics;

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
