// The engine runs the exercise kernels of the build it is linked with: the reference build runs
// solutions/, the student build exercises/. This binary is linked with the shipped stubs (which
// tests/grade regenerates from exercises/), so wherever the engine calls a kernel it must stop
// with that exercise's NotImplemented: proof that a student's scene runs the student's code.
#include <doctest/doctest.h>

#include <string>

#include "analysis/stability.hpp"
#include "clothlab/after_step/self_collision.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "scene/scene.hpp"

namespace {

// Which exercise `run` stops at, or "" if it runs through.
template <class F>
std::string stops_at(F&& run) {
  try {
    run();
  } catch (const clothlab::NotImplemented& e) {
    return e.exercise();
  }
  return "";
}

// One 1 kg particle on a spring (ks = 100 N/m, l0 = 1 m, stretched to 1.5 m, no damper) from a
// pinned one, no other force, stepped by `method` at dt = 0.01 s.
std::string one_spring(const std::string& method) {
  return R"(
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
pinned = true
[[particle]]
position = [1.5, 0.0, 0.0]
mass = 1.0
[[spring]]
i = 0
j = 1
ks = 100.0
l0 = 1.0
[integrator]
dt = 0.01
duration = 1
method = ")" +
         method + "\"\n";
}

}  // namespace

TEST_CASE("student build: [self_collision] calls the student's kernels (ex10.1, ex10.2)") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
[[particle]]
position = [0.0, 0.1, 0.0]
mass = 1.0
[self_collision]
thickness = 0.05
[integrator]
dt = 0.001
duration = 1
)",
                                                "stubs.toml");
  clothlab::World& w = scene.world;
  REQUIRE(w.post_step_effects.size() == 1);
  auto* effect = dynamic_cast<clothlab::SelfCollision*>(w.post_step_effects[0].get());
  REQUIRE(effect != nullptr);
  // The effect's own step, as World::step calls it after the integrator (whose kernels are
  // stubs too, so the step itself would stop at lesson 01).
  CHECK(stops_at([&] { effect->apply(w, clothlab::StepTime::whole(w.t, scene.dt)); }) == "ex10.1");
  CHECK(stops_at([&] { effect->detect(w.particles.x, 1e6); }) == "ex10.1");
  // The response, given the pair that detection finds once ex10.1 is done: the two particles
  // brought within the thickness (0.01 m apart, thickness 0.05 m) go through the student's
  // pair_response.
  w.particles.x(1, 1) = 0.01;
  CHECK(stops_at([&] { effect->respond(w.particles, {{0, 1}}); }) == "ex10.2");
}

TEST_CASE("student build: the advisor's explicit Euler limit is the student's kernel (ex08.1)") {
  // A unit mass on a spring (w = 10 rad/s) with a damper (beta = 2 1/s): the limit is asked of
  // largest_stable_dt_explicit_euler, which the stubs have not written yet.
  CHECK(stops_at([] { clothlab::oscillator_dt_limit("explicit-euler", 10.0, 2.0); }) == "ex08.1");
  // The advisor itself keeps working on a stub (a student at lesson 02 runs explicit Euler on
  // springs long before lesson 08): it takes the limit from the eigenvalues, c / k = 0.02 s.
  clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
pinned = true
[[particle]]
position = [1.0, 0.0, 0.0]
mass = 1.0
[[spring]]
i = 0
j = 1
ks = 100.0
kd = 2.0
[integrator]
method = "explicit-euler"
dt = 0.001
duration = 1
)",
                                                "stubs.toml");
  double limit = 0.0;
  CHECK(stops_at([&] {
          limit = clothlab::advise_time_step(scene.world, scene.dt, scene.step_count()).dt_limit;
        }) == "");
  CHECK(limit == doctest::Approx(0.02).epsilon(1e-9));
}

TEST_CASE("student build: method = \"xpbd\" projects with the student's kernel (ex12.1)") {
  // One spring without a damper and no other force: nothing in the substep calls a kernel of
  // lessons 01 to 11 before the first projection, the student's xpbd_distance_projection.
  clothlab::Scene scene = clothlab::parse_scene(one_spring("xpbd"), "stubs.toml");
  // The integrator's advance, as World::step calls it (the step itself first asks the guard for
  // the springs' energy, lesson 02's ex02.2).
  clothlab::World& w = scene.world;
  CHECK(stops_at([&] { w.integrator->advance(w, scene.dt); }) == "ex12.1");
}

TEST_CASE("student build: method = \"local-global\" projects with the student's kernel (ex13.1)") {
  // The same spring: the step factors its matrix (no kernel) and then calls, first of all
  // kernels, the student's local_step_projection.
  clothlab::Scene scene = clothlab::parse_scene(one_spring("local-global"), "stubs.toml");
  clothlab::World& w = scene.world;
  CHECK(stops_at([&] { w.integrator->advance(w, scene.dt); }) == "ex13.1");
}

TEST_CASE("student build: method = \"vbd\" steps each vertex with the student's kernel (ex14.1)") {
  // The same spring: the step sums no external force (there is none), builds the colouring (no
  // kernel), and then calls, first of all kernels, the student's vbd_vertex_step.
  clothlab::Scene scene = clothlab::parse_scene(one_spring("vbd"), "stubs.toml");
  clothlab::World& w = scene.world;
  CHECK(stops_at([&] { w.integrator->advance(w, scene.dt); }) == "ex14.1");
}
