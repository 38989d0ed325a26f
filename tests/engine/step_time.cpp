// The time a post-step effect is told (core/step_time.hpp, the substep contract in world.hpp).
// A step of dt that XPBD splits into n substeps of h = dt / n applies the contacts with fixed
// solids after every substep, substeps 0 to n-2 in the integrator and n-1 in World::step, and
// every other post-step effect once after the step. Each application is told the span it closes.
// These tests fail when an effect is given the step where a substep is meant, or the reverse:
// a contact told dt on the last substep, a moving pin placed at the step's end after a substep.
#include <doctest/doctest.h>

#include <memory>
#include <vector>

#include "clothlab/after_step/moving_pins.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/xpbd.hpp"

using clothlab::StepTime;
using clothlab::Vec3;
using clothlab::World;

namespace {

// A post-step effect that records the time of each application; `substeps` says whether it is
// a contact that applies each substep (PostStepEffect::each_substep).
class RecordTimes final : public clothlab::PostStepEffect {
 public:
  explicit RecordTimes(bool substeps) : substeps_(substeps) {}
  std::vector<StepTime> seen;
  std::string_view name() const override { return "record"; }
  void apply(World& /*world*/, const StepTime& time) override { seen.push_back(time); }
  bool each_substep() const override { return substeps_; }

 private:
  bool substeps_;
};

}  // namespace

TEST_CASE("step time: with XPBD a contact closes each substep, the others close the whole step") {
  // One free particle, no forces; XPBD with n = 4 substeps; two steps of dt = 10 ms from
  // t = 1 s. The contact must see 4 applications a step, substep k of 4 with h = dt / 4 = 2.5 ms,
  // ending at t + (k + 1) h, the last at t + dt; the other effect one a step, h = dt.
  constexpr double dt = 0.01, t0 = 1.0;
  constexpr int n = 4;
  World world;
  world.particles.add(Vec3::Zero(), Vec3(0.0, 1.0, 0.0), 1.0);
  world.t = t0;
  auto xpbd = std::make_unique<clothlab::Xpbd>();
  xpbd->substeps = n;
  world.integrator = std::move(xpbd);
  auto contact_effect = std::make_unique<RecordTimes>(true);
  auto whole_effect = std::make_unique<RecordTimes>(false);
  RecordTimes& contact = *contact_effect;
  RecordTimes& whole = *whole_effect;
  world.post_step_effects.push_back(std::move(contact_effect));
  world.post_step_effects.push_back(std::move(whole_effect));
  world.step(dt);
  world.step(dt);

  REQUIRE(contact.seen.size() == 2 * n);
  for (size_t a = 0; a < contact.seen.size(); ++a) {
    CAPTURE(a);
    const StepTime& s = contact.seen[a];
    const int step = static_cast<int>(a) / n, k = static_cast<int>(a) % n;
    CHECK(s.t == doctest::Approx(t0 + step * dt).epsilon(1e-15));
    CHECK(s.dt == dt);
    CHECK(s.h == doctest::Approx(dt / n).epsilon(1e-15));
    CHECK(s.substep == k);
    CHECK(s.substeps == n);
    CHECK(s.last() == (k == n - 1));
    CHECK(s.end() == doctest::Approx(s.t + (k + 1) * dt / n).epsilon(1e-15));
  }
  CHECK(contact.seen[n - 1].end() == t0 + dt);  // the last substep ends with the step, exactly
  REQUIRE(whole.seen.size() == 2);
  for (const StepTime& s : whole.seen) {
    CHECK(s.dt == dt);
    CHECK(s.h == dt);
    CHECK(s.substep == 0);
    CHECK(s.substeps == 1);
    CHECK(s.end() == s.t + dt);
  }
  CHECK(whole.seen[1].t == doctest::Approx(t0 + dt).epsilon(1e-15));
}

TEST_CASE("step time: a method that takes the step whole tells every effect substep 0 of 1") {
  constexpr double dt = 0.02;
  for (std::string_view method : clothlab::method_names()) {
    if (method == "xpbd") continue;
    CAPTURE(method);
    World world;
    world.particles.add(Vec3::Zero(), Vec3::Zero(), 1.0);
    world.integrator = clothlab::make_integrator(method);
    auto effect = std::make_unique<RecordTimes>(true);
    RecordTimes& contact = *effect;
    world.post_step_effects.push_back(std::move(effect));
    world.step(dt);
    REQUIRE(contact.seen.size() == 1);
    CHECK(contact.seen[0].h == dt);
    CHECK(contact.seen[0].substeps == 1);
    CHECK(contact.seen[0].end() == dt);
  }
}

TEST_CASE("step time: a moving pin applied on a substep is placed where its path is then") {
  // A pin on a circle of period 1 s about the y axis through the origin, from x0 = (1, 0, 0).
  // Told it closes substep 1 of 4 of the step [0.2 s, 0.2 s + 40 ms], it must stand where the
  // path is at 0.2 + 2 * 10 ms = 0.22 s, not at the step's end 0.24 s (a quarter of a turn is
  // 0.25 s, so the two places are 0.02 * 2 pi = 0.126 rad, 13 cm, apart).
  clothlab::PinPath path;
  path.particles = {0};
  path.x0 = {Vec3(1.0, 0.0, 0.0)};
  path.centre = Vec3::Zero();
  path.axis = Vec3::UnitY();
  path.period = 1.0;
  clothlab::MovingPins pins({path});
  World world;
  world.particles.add(path.x0[0], Vec3::Zero(), 1.0);
  clothlab::pin(world.particles, 0);
  world.t = 0.2;
  pins.apply(world, StepTime::of_substep(world.t, 0.04, 1, 4));
  const Vec3 at_substep = path.position(0, 0.22), at_step_end = path.position(0, 0.24);
  REQUIRE((at_substep - at_step_end).norm() > 0.1);
  CHECK((world.particles.x.col(0) - at_substep).norm() < 1e-12);
  CHECK((world.particles.v.col(0) - path.velocity(0, 0.22)).norm() < 1e-12);
  // After a whole step it stands at the step's end.
  pins.apply(world, StepTime::whole(world.t, 0.04));
  CHECK((world.particles.x.col(0) - at_step_end).norm() < 1e-12);
}
