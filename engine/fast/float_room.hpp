// float_room.hpp: the engine room in single precision, where a scene asks for it
// (`[engine] precision = "float"`, `clothlab run --float`).
//
// The engine keeps its state in doubles (Particles), and the readable engine and the fast path
// compute in doubles. A step in the float room takes the fast path's one pass (engine.hpp) with
// every number of the step in float: it rounds x and v to floats as it copies them into its
// copies (CopiesOf<float>, checking them for the guard on the way, as the fast path does), sums
// the forces there in float (the spring runs of springs.cpp and the triangle groups of
// aerodynamics.cpp on floats, through spring_force and aerodynamic_force_of of
// scalar_kernels.hpp; gravity and damping of forces.cpp on floats), moves each particle with the
// Euler kernel in float, and writes x, v and f back into the engine's doubles, exactly (a float
// is a double). So the state between steps holds floats, and what the world does between two
// steps (the post-step effects, the guard, the outputs) reads it as it reads any state.
//
// What it covers: symplectic and explicit Euler (one evaluation a step, each particle moved by
// its own force); the force effects gravity, springs and bending (spring-dampers), damping,
// aerodynamics (its wind and gusts read at each step); and, after the step, on the state it
// wrote, the world's contacts and pins that move (ground, plane, sphere, moving_pins), in double
// as always. Anything else (another method, drag, buoyancy, gravitation, plasticity, tearing,
// strain limiting, self-collision) is an error when the scene loads, never a quiet step in
// double: a threshold (a yield, a tear, a contact between two cloths) decided on float rounding
// can part from the double run at once, and the float room has no kernel for the others.
//
// Each particle gets the same operations in the same order whatever the threads and the blocks:
// the float run gives the same bits on any number of threads (tests/fast/float.cpp), though not
// the double run's bits. How far it drifts from them, the same file bounds.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "clothlab/core/backend.hpp"
#include "fast/copies.hpp"
#include "fast/forces.hpp"

namespace clothlab::fast {

// What the float room covers, as the scene's error says it.
inline constexpr std::string_view kFloatCovers =
    "methods symplectic-euler and explicit-euler; effects gravity, springs, bending, damping, "
    "aerodynamics, ground, plane, sphere and moving pins";

// "" when the float room covers the world's integrator and every effect of it; else what it
// does not cover: "the method rk4", "the effects drag, tearing".
std::string float_room_declines(const World& world);

// Makes the world's steps run in the float room: "" when done; else why not, in a sentence that
// names what float covers (the world has no engine room, or holds something not covered), and
// the world is left as it was. The scene's `precision = "float"` and `clothlab run --float`.
std::string use_float(World& world);

class FloatRoom {
 public:
  // One step of dt [s] in float (see above): forces summed and every particle moved, the
  // state it started from checked as it was read (the guard's error, thrown before anything
  // moves, if it was bad) and the new state checked after the move (BackendStep::checked_after).
  // Throws std::logic_error when the world holds something it does not cover (the scene
  // reader refuses such a scene; a program that added an effect since gets the same words).
  BackendStep step(World& world, double dt);
  // Steps in float with the state kept in float between them (resident.hpp), for a world with
  // no post-step effect whose every force effect the float room covers; {} otherwise.
  BackendSteps steps(World& world, double dt, long count);

 private:
  // Each of the world's force effects' float form in forces_, made again only for an effect not
  // seen at its place; false if one has none.
  bool match_forces(const World& world);

  std::vector<FastForceSlot<float>> forces_;  // the world's force effects, in float
  CopiesOf<float> copies_;
  ResidentOf<float> resident_;  // steps' two copies of the state
  std::vector<float> inv_m_;    // and the particles' 1/m, rounded to float
};

}  // namespace clothlab::fast
