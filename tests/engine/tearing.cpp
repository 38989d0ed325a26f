// Plasticity and tearing (lesson 06): what must hold for any scene.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>
#include <set>
#include <string>

#include "clothlab/after_step/plasticity.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;

TEST_CASE("plasticity: rest lengths stay positive and never pass the current length") {
  clothlab::Scene scene = clothlab::parse_scene(
      test::storm("[plasticity]\nyield_strain = 0.05\nmax_strain = 0.5\n"), "p.toml");
  clothlab::SpringSet& s = test::springs_of(scene.world);
  for (long step = 0; step < scene.step_count(); ++step) {
    scene.world.step(scene.dt);
    bool positive = true, finite = true, within = true;
    for (size_t k = 0; k < s.size(); ++k) {
      positive = positive && s.l0(k) > 0.0;
      finite = finite && std::isfinite(s.l0(k));
      within = within && s.l0(k) <= s.l_built(k) * 1.5 * (1 + 1e-12) &&
               s.l0(k) >= s.l_built(k) * 0.5 * (1 - 1e-12);
    }
    CAPTURE(step);
    REQUIRE(positive);
    REQUIRE(finite);
    REQUIRE(within);  // max_strain = 0.5 around the built length
  }
  // It did yield: some rest lengths grew.
  size_t grown = 0;
  for (size_t k = 0; k < s.size(); ++k)
    grown += s.l0(k) > s.l_built(k) * 1.01;
  CHECK(grown > 0);
}

TEST_CASE("plasticity: plastic flow never adds energy to a spring") {
  // Apply only the plastic update to a stretched state and compare the springs' energy.
  clothlab::Scene scene =
      clothlab::parse_scene(test::storm("[plasticity]\nyield_strain = 0.02\n"), "p.toml");
  for (int step = 0; step < 2000; ++step)
    scene.world.step(scene.dt);  // the storm stretches it
  clothlab::SpringDampers& springs = test::spring_effect(scene.world);
  const double before = springs.potential_energy(scene.world.particles, scene.world.particles.x);
  clothlab::Plasticity plasticity(springs, {0.02, 1e9, 0.9});  // flow all the way at once
  plasticity.apply(scene.world, clothlab::StepTime::whole(scene.world.t, scene.dt));
  const double after = springs.potential_energy(scene.world.particles, scene.world.particles.x);
  CHECK(after <= before);
  CHECK(after < before);  // and it did flow
}

TEST_CASE("plasticity: below the elastic limit nothing changes") {
  // A breeze instead of the storm: the sheet stretches by a few percent, far below 50 %.
  std::string breeze = test::storm("[plasticity]\nyield_strain = 0.5\n");
  breeze.replace(breeze.find("wind = [0, 0, 30]"), 17, "wind = [0, 0, 2]");
  clothlab::Scene scene = clothlab::parse_scene(breeze, "p.toml");
  const clothlab::SpringSet& s = test::springs_of(scene.world);
  for (int step = 0; step < 2000; ++step)
    scene.world.step(scene.dt);
  CHECK(std::memcmp(s.l0().data(), s.l_built().data(), s.size() * sizeof(double)) == 0);
}

TEST_CASE("tearing: springs only go, no index dangles, and torn triangles leave the air") {
  clothlab::Scene scene =
      clothlab::parse_scene(test::storm("[tearing]\nstrain = 0.25\n"), "t.toml");
  clothlab::SpringSet& s = test::springs_of(scene.world);
  const size_t springs_at_start = s.size();
  const Index n = scene.world.particles.size();
  size_t previous = s.size();
  for (long step = 0; step < scene.step_count(); ++step) {
    scene.world.step(scene.dt);
    REQUIRE(s.size() <= previous);
    previous = s.size();
  }
  CHECK(s.size() < springs_at_start);  // it tore
  for (size_t k = 0; k < s.size(); ++k) {
    CHECK(s.i(k) < n);
    CHECK(s.j(k) < n);
  }
  // Every remaining triangle keeps all three of its edges as springs (structural or shear).
  const auto ends = test::ends_of(s);
  const auto* aero = test::find_force_effect<clothlab::Aerodynamics>(scene.world);
  REQUIRE(aero != nullptr);
  CHECK(aero->triangles() == scene.world.triangles);
  CHECK(scene.world.triangles.size() < 2u * 11u * 11u);
  for (const auto& t : scene.world.triangles) {
    for (int a = 0; a < 3; ++a) {
      const Index p = t[a], q = t[(a + 1) % 3];
      CHECK(ends.count({std::min(p, q), std::max(p, q)}) == 1);
    }
  }
}

TEST_CASE("tearing: which springs tear does not depend on their order in the list") {
  // Two copies of the same stretched state, one with its spring list reversed: one tearing pass
  // must remove the same springs (by their end particles) from both.
  for (size_t max_tears : {size_t{0}, size_t{3}}) {
    CAPTURE(max_tears);
    clothlab::Scene a = clothlab::parse_scene(test::storm(), "a.toml");
    for (int step = 0; step < 3000; ++step)
      a.world.step(a.dt);
    clothlab::Scene b = clothlab::parse_scene(test::storm(), "b.toml");
    b.world.particles = a.world.particles;
    clothlab::SpringSet& sb = test::springs_of(b.world);
    sb.reverse();
    // As a scene makes it: the world's springs, its bending springs and its air's triangles.
    const auto tearing = [&](clothlab::World& w) {
      std::vector<clothlab::Aerodynamics*> aero;
      for (auto& effect : w.force_effects)
        if (auto* air = dynamic_cast<clothlab::Aerodynamics*>(effect.get())) aero.push_back(air);
      return clothlab::Tearing(test::spring_effect(w), clothlab::find_spring_effect(w, "bending"),
                               aero, 0.05, max_tears);
    };
    clothlab::Tearing ta = tearing(a.world), tb = tearing(b.world);
    ta.apply(a.world, clothlab::StepTime::whole(a.world.t, a.dt));
    tb.apply(b.world, clothlab::StepTime::whole(b.world.t, b.dt));
    CHECK(ta.torn() > 0);
    CHECK(ta.torn() == tb.torn());
    CHECK(test::ends_of(test::springs_of(a.world)) == test::ends_of(sb));
  }
}

TEST_CASE("tearing: a repeated run is bitwise identical") {
  clothlab::Scene a = clothlab::parse_scene(test::storm("[tearing]\nstrain = 0.25\n"), "t.toml");
  clothlab::Scene b = clothlab::parse_scene(test::storm("[tearing]\nstrain = 0.25\n"), "t.toml");
  for (long step = 0; step < a.step_count(); ++step) {
    a.world.step(a.dt);
    b.world.step(b.dt);
  }
  const auto& xa = a.world.particles.x;
  const auto& xb = b.world.particles.x;
  CHECK(std::memcmp(xa.data(), xb.data(), sizeof(double) * static_cast<size_t>(xa.size())) == 0);
  CHECK(test::springs_of(a.world).size() == test::springs_of(b.world).size());
}

TEST_CASE("tearing: bending springs that reach across a tear go with it") {
  // With [bending], every bending spring left must still have both of its halves as springs:
  // otherwise it would hold the two sides of a tear together.
  clothlab::Scene scene =
      clothlab::parse_scene(test::storm("[bending]\nks = 2\n[tearing]\nstrain = 0.25\n"), "b.toml");
  test::run_to_end(scene);
  const auto ends = test::ends_of(test::springs_of(scene.world));
  const clothlab::SpringSet& b = test::springs_of(scene.world, "bending");
  CHECK(b.size() < 2u * 12u * 10u);  // some went
  for (size_t k = 0; k < b.size(); ++k) {
    const Index a = std::min(b.i(k), b.j(k)), c = std::max(b.i(k), b.j(k));
    const Index m = (a + c) / 2;
    CHECK(ends.count({a, m}) == 1);
    CHECK(ends.count({m, c}) == 1);
  }
}
