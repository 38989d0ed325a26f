// scene_warnings.hpp: checks of a whole scene that warn rather than refuse.
//
// The scene reader warns (Scene::warnings) about inputs that run but are likely mistakes. Most
// are found where a table is read; those here need every particle and the run's length:
// particles that start at the same position or inside a collider, and an all-pairs effect on a
// large scene.
#pragma once

#include <string>
#include <vector>

#include "clothlab/core/types.hpp"
#include "scene/scene.hpp"

namespace clothlab {

// Particles that start at exactly the same position as a lower-numbered one.
struct CoincidentParticles {
  Index count = 0;    // particles that start where a lower-numbered one does
  Index first = -1;   // of the pair with the lowest `second`: the lower-numbered particle
  Index second = -1;  // the lowest-numbered particle that starts where an earlier one does
};

// Sorts the particles by position, O(n log n): comparing every pair would take n(n-1)/2 steps,
// 5e11 comparisons for the 10^6 particles a scene may hold.
CoincidentParticles find_coincident_particles(const Matrix3X& x);

// Free particles (not pinned) that start inside one collider: the ground, a [[plane]] or the
// [sphere]. Its first contact pushes them out to its surface at once, whatever their depth: a
// jump, and energy that no force gave.
struct StartInside {
  const PostStepEffect* collider = nullptr;
  std::string what;      // the collider, for people: "the ground (y = 0 m)", ...
  Index count = 0;       // free particles that start inside it
  Index first = -1;      // the lowest-numbered of them
  double depth = 0.0;    // how deep the first is [m]
  double deepest = 0.0;  // how deep the deepest is [m]
};

// One entry for each collider of the scene with a particle inside, in the world's order.
std::vector<StartInside> find_particles_inside(const World& world);

// [gravitation]'s cost per pair and force evaluation [s], measured with the Release build on
// this project's two-core AMD EPYC build machine (the fastest of six runs, the machine shared):
//   ./build/clothlab run tests/scenes/gravitation_3000.toml --stats --no-html
// says "gravitation 0.9753 s" for 50 steps of n(n-1)/2 = 4,498,500 pairs: 4.3e-9 s a pair.
// A step then costs this times the pairs times the integrator's force evaluations (and a little
// for the energy); other machines differ by a small factor, which is all the warning needs.
inline constexpr double kGravitationSecondsPerPair = 4.3e-9;

// Above this many particles [gravitation] warns of its cost before a run: 2,000 particles are
// 2e6 pairs, 8.6 ms a step at kGravitationSecondsPerPair, so a lesson-length run of 10^4 steps
// (dt = 0.0005 s for 5 s) already spends a minute and a half in gravitation alone; smaller
// scenes stay quiet.
inline constexpr Index kAllPairsWarnAbove = 2000;

// Where particle i of the scene came from, for messages: "[[particle]] #3", "the cloth's
// particle 5 (row 0, column 5)", ...
std::string describe_particle(const Scene& scene, Index i);

// The warning about an all-pairs effect ([gravitation]) on a scene of more than
// kAllPairsWarnAbove particles: its pairs, and its estimated cost a step and for the run; "" when
// there is nothing to say.
std::string all_pairs_warning(const Scene& scene);

// A duration for people: "0.42 s", "12 min", "3.5 h", "41 days", "1.2e+03 years".
std::string human_duration(double seconds);

}  // namespace clothlab
