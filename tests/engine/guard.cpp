// The guard: a blown-up state stops the run with an error that says where and why.
#include <doctest/doctest.h>

#include <limits>
#include <string>

#include "clothlab/gravity.hpp"
#include "test_util.hpp"

using clothlab::Vec3;

namespace {

// A force effect that misbehaves on purpose: from step `at` on, particle `victim` gets a NaN
// force (as a division by a zero length would give).
class NanInjector final : public clothlab::ForceEffect {
 public:
  NanInjector(const clothlab::World& world, long at, clothlab::Index victim)
      : world_(world), at_(at), victim_(victim) {}
  std::string_view name() const override { return "nan-injector"; }
  void add_forces(const clothlab::Particles&, const clothlab::Matrix3X&, const clothlab::Matrix3X&,
                  clothlab::Matrix3X& f) const override {
    if (world_.steps + 1 >= at_) f(1, victim_) = std::numeric_limits<double>::quiet_NaN();
  }

 private:
  const clothlab::World& world_;
  long at_;
  clothlab::Index victim_;
};

}  // namespace

TEST_CASE("guard: an injected NaN stops the run at that step naming the particle") {
  clothlab::World world = test::falling_particle("symplectic-euler");
  for (int i = 0; i < 4; ++i)
    world.particles.add(Vec3(i, 1, 0), Vec3::Zero(), 1.0);
  world.force_effects.push_back(std::make_unique<NanInjector>(world, 5, 3));
  for (int s = 1; s < 5; ++s)
    world.step(0.01);  // steps 1-4 are clean
  try {
    world.step(0.01);
    FAIL("the guard let a NaN through");
  } catch (const clothlab::SimulationError& e) {
    const std::string what = e.what();
    CAPTURE(what);
    CHECK(e.step() == 5);
    CHECK(e.particle() == 3);
    CHECK(what.find("step 5") != std::string::npos);
    CHECK(what.find("particle 3") != std::string::npos);
    CHECK(what.find("not finite") != std::string::npos);
    CHECK(what.find("gravity, nan-injector; integrator symplectic-euler") != std::string::npos);
  }
}

TEST_CASE("guard: a position beyond the bound stops the run") {
  clothlab::World world = test::falling_particle("explicit-euler");
  world.guard.max_position = 10.0;
  // Free fall passes 10 m after sqrt(2 * 10 / 9.8) = 1.43 s: the run must stop there.
  long stopped_at = -1;
  try {
    for (int s = 0; s < 300; ++s)
      world.step(0.01);
  } catch (const clothlab::SimulationError& e) {
    stopped_at = e.step();
    CHECK(std::string(e.what()).find("beyond the guard's bound of 10 m") != std::string::npos);
  }
  CHECK(stopped_at > 140);
  CHECK(stopped_at < 150);
}

TEST_CASE("guard: a speed beyond the bound stops the run") {
  clothlab::World world = test::falling_particle("symplectic-euler");
  world.guard.max_speed = 5.0;
  CHECK_THROWS_AS(
      [&] {
        for (int s = 0; s < 100; ++s)
          world.step(0.01);
      }(),
      clothlab::SimulationError);
  CHECK(world.particles.v.cwiseAbs().maxCoeff() > 5.0);
}

TEST_CASE("guard: a calm run is never stopped") {
  clothlab::World world = test::falling_particle("symplectic-euler");
  for (int s = 0; s < 1000; ++s)
    world.step(0.001);
  CHECK(world.steps == 1000);
}
