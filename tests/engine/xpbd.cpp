// XPBD (lesson 12): method = "xpbd", springs as compliant distance constraints with small steps.
// Each test states the property it checks and why the number it compares with is right; each
// fails when the feature breaks (a forgotten lambda, a wrong compliance, substeps ignored, the
// fast path taking the step).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/xpbd.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::Vec3;
using clothlab::World;
using clothlab::Xpbd;

namespace {

constexpr double kG = 9.8;  // [m/s^2]

// The XPBD integrator of a world, made here with the given substeps and iterations.
Xpbd& use_xpbd(World& world, int substeps, int iterations, bool keep_lambda = true) {
  auto xpbd = std::make_unique<Xpbd>();
  xpbd->substeps = substeps;
  xpbd->iterations = iterations;
  xpbd->keep_lambda = keep_lambda;
  Xpbd& ref = *xpbd;
  world.integrator = std::move(xpbd);
  return ref;
}

// A chain hanging from a pinned particle at the origin: `links` springs of ks [N/m], kd [N s/m]
// and l0 = 1 m down -y, each free particle of mass m [kg], under gravity, starting at rest at
// `stretch` [m] past l0 per link.
World hanging_chain(int links, double m, double ks, double kd, double stretch = 0.0) {
  World world;
  world.particles.add(Vec3::Zero(), Vec3::Zero(), m);
  clothlab::pin(world.particles, 0);
  clothlab::SpringSet springs;
  for (int k = 1; k <= links; ++k) {
    world.particles.add(Vec3(0.0, -k * (1.0 + stretch), 0.0), Vec3::Zero(), m);
    springs.add(k - 1, k, ks, kd, 1.0);
  }
  world.force_effects.push_back(
      std::make_unique<clothlab::SpringDampers>("springs", std::move(springs)));
  world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0.0, -kG, 0.0)));
  return world;
}

void run(World& world, double dt, long steps) {
  for (long s = 0; s < steps; ++s)
    world.step(dt);
}

// How far below its rest position (y = -links m) the bottom of the chain hangs [m].
double sag(const World& world, int links) {
  return -static_cast<double>(links) - world.particles.x(1, links);
}

}  // namespace

TEST_CASE("xpbd: a hanging mass settles at the spring's static stretch m g / ks") {
  // One substep, 1D along the constraint, v = 0 at rest, stretch s: the prediction adds
  // dt_s^2 g; the projection (w = 1/m, the anchor pinned) gives delta_lambda = -(s + dt_s^2 g) /
  // (w + alpha_tilde) and s' = (s + dt_s^2 g) alpha_tilde / (w + alpha_tilde). The fixed point
  // s' = s is s w = dt_s^2 g alpha_tilde = g / ks, s = m g / ks: exactly the spring's static
  // stretch, for any dt_s and iteration count. With m = 0.1 kg, ks = 100 N/m: 9.8 mm.
  const double m = 0.1, ks = 100.0, expected = m * kG / ks;
  SUBCASE("started at the stretch, it stays there (to rounding)") {
    World world = hanging_chain(1, m, ks, 0.0, expected);
    use_xpbd(world, 10, 1);
    run(world, 1.0 / 60.0, 120);
    CHECK(std::abs(sag(world, 1) - expected) <= 1e-12);
    CHECK(world.particles.v.col(1).norm() <= 1e-9);
  }
  SUBCASE("started at its rest length, it swings down and settles there") {
    // With kd = 0.5 N s/m the spring's damping ratio is kd / (2 sqrt(ks m)) = 0.079; the swing
    // of 9.8 mm decays as exp(-2.5 t) at least (XPBD damps a little more), below 1e-12 m by
    // t = 10 s: 1e-6 m (a 1e-4 share of the stretch) is a bound with room to spare, and a
    // stiffness off by 1 % (98 um) fails it.
    World world = hanging_chain(1, m, ks, 0.5);
    use_xpbd(world, 10, 1);
    run(world, 1.0 / 60.0, 600);
    CHECK(sag(world, 1) == doctest::Approx(expected).epsilon(1e-4));
  }
}

TEST_CASE("xpbd: the stiffness does not depend on the iteration count, unlike plain PBD") {
  // The hanging mass of the test above after 10 s (dt = 1/60 s, 10 substeps). XPBD: 9.8 mm
  // with 1 and with 10 iterations. Plain PBD (lambda forgotten, `keep_lambda = false`) repeats
  // the first iteration n times: s' = (s + dt_s^2 g) r^n with r = alpha_tilde / (w +
  // alpha_tilde) = 3600 / 3610, whose fixed point s = dt_s^2 g r^n / (1 - r^n) is 9.8 mm at
  // n = 1 and 0.969 mm at n = 10: ten iterations make the spring ten times stiffer.
  const double m = 0.1, ks = 100.0, expected = m * kG / ks;
  const auto settled = [&](int iterations, bool keep_lambda) {
    World world = hanging_chain(1, m, ks, 0.5);
    use_xpbd(world, 10, iterations, keep_lambda);
    run(world, 1.0 / 60.0, 600);
    return sag(world, 1);
  };
  CHECK(settled(1, true) == doctest::Approx(expected).epsilon(1e-4));
  CHECK(settled(10, true) == doctest::Approx(expected).epsilon(1e-4));
  const double r = 3600.0 / 3610.0, h = 1.0 / 600.0;
  const double pbd10 = h * h * kG * std::pow(r, 10) / (1.0 - std::pow(r, 10));
  CHECK(settled(10, false) == doctest::Approx(pbd10).epsilon(1e-3));
  CHECK(settled(10, false) < 0.2 * expected);

  // A chain of 4 links, where one iteration does not solve the constraints exactly: link k
  // from the top carries the (5 - k) masses below it, so the bottom hangs
  // (4 + 3 + 2 + 1) m g / ks = 98 mm below its rest position. With one iteration and with ten
  // it settles there within 1 % (measured: 98.14 mm and 97.97 mm), where plain PBD with ten
  // iterations hangs ten times higher (9.8 mm).
  const auto chain = [&](int iterations, bool keep_lambda) {
    World world = hanging_chain(4, m, ks, 0.5);
    use_xpbd(world, 10, iterations, keep_lambda);
    run(world, 1.0 / 60.0, 1200);
    return sag(world, 4);
  };
  const double chain_expected = 10.0 * m * kG / ks;
  const double one = chain(1, true), ten = chain(10, true), pbd = chain(10, false);
  MESSAGE("chain sag: xpbd 1 iteration " << one << " m, 10 iterations " << ten
                                         << " m, plain PBD 10 iterations " << pbd << " m");
  CHECK(one == doctest::Approx(chain_expected).epsilon(0.01));
  CHECK(ten == doctest::Approx(chain_expected).epsilon(0.01));
  CHECK(pbd < 0.5 * chain_expected);
}

TEST_CASE("xpbd: with more substeps a swinging spring pendulum approaches the force-based answer") {
  // A 1 kg bob on a spring of ks = 1000 N/m from a pinned anchor, released from rest at the
  // anchor's height 1 m away, swings under gravity for 1 s. The reference is RK4 at dt = 1e-4 s
  // (its error there is far below the differences measured). XPBD at dt = 1/60 s with 1, 4,
  // 16 and 64 substeps: the error falls with each (first order in dt_s, so about 4 times per
  // step of the table), and with 64 substeps the bob is within 1 cm of the reference.
  const auto pendulum = [](std::unique_ptr<clothlab::Integrator> integrator) {
    World world = test::anchored_spring(1.0, 1000.0, 0.0, 0.0, 0.0);
    world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0.0, -kG, 0.0)));
    world.integrator = std::move(integrator);
    return world;
  };
  World reference = pendulum(clothlab::make_integrator("rk4"));
  run(reference, 1e-4, 10000);
  const Vec3 x_ref = reference.particles.x.col(1);
  double last = std::numeric_limits<double>::infinity();
  for (int substeps : {1, 4, 16, 64}) {
    CAPTURE(substeps);
    World world = pendulum(std::make_unique<Xpbd>());
    dynamic_cast<Xpbd&>(*world.integrator).substeps = substeps;
    run(world, 1.0 / 60.0, 60);
    const double error = (world.particles.x.col(1) - x_ref).norm();
    MESSAGE("substeps " << substeps << ": error " << error << " m");
    CHECK(error < 0.6 * last);
    last = error;
  }
  CHECK(last < 0.01);
}

TEST_CASE("xpbd: a stiff cloth is stable at a step where explicit Euler blows up") {
  // A 10 x 10 sheet 5 cm apart, 0.1 kg, ks = 5000 N/m, at dt = 1/60 s: each particle weighs 1 g,
  // so its springs give w ~ sqrt(4 ks / m) ~ 4500 rad/s, and dt w ~ 75, far past any explicit
  // method's limit (about 2). Explicit Euler is stopped by the guard; XPBD with 10 substeps runs
  // the 2 s and ends with no more energy than gravity gave it.
  clothlab::Scene euler = clothlab::parse_scene(test::stiff_sheet("explicit-euler"), "stiff.toml");
  CHECK_THROWS_AS(test::run_to_end(euler), clothlab::SimulationError);
  clothlab::Scene xpbd = clothlab::parse_scene(test::stiff_sheet("xpbd"), "stiff.toml");
  const double e0 = xpbd.world.kinetic_energy() + xpbd.world.potential_energy();
  CHECK_NOTHROW(test::run_to_end(xpbd));
  // The sheet falls at most its own diagonal plus the springs' stretch: 0.64 m at the most; its
  // kinetic energy is then below m g 0.64 m = 0.63 J. A blown-up sheet has far more.
  CHECK(xpbd.world.kinetic_energy() < 0.63);
  CHECK(std::isfinite(e0));
}

TEST_CASE("xpbd: the energy of an undamped spring never grows") {
  // An undamped spring (ks = 100 N/m, 1 kg, w = 10 rad/s, pulled 0.1 m, no gravity) stepped 10 s
  // at dt = 10 ms with 4 substeps of h = 2.5 ms. On one constraint with a pinned anchor a substep
  // of XPBD is exactly a step of implicit Euler: x* = s + h v, s' = x* / (1 + (w h)^2) and
  // v' = (s' - s) / h are implicit Euler's s' = s + h v', v' = v - h w^2 s'. Its energy must never
  // grow, beyond rounding (1e-12 J), and it leaks as implicit Euler's does (lesson 08): by the
  // factor 1 / (1 + (w h)^2) a step, 0.5 J / 1.000625^4000 = 0.0411 J after 4000 substeps. A step
  // that added energy, or lost it all, fails.
  World world = test::anchored_spring(1.0, 100.0, 0.0, 0.1, 0.0);
  use_xpbd(world, 4, 1);
  const double e0 = world.kinetic_energy() + world.potential_energy();
  const double e = test::step_without_energy_growth(world, 0.01, 1000);
  const double implicit_euler = e0 * std::pow(1.0 + 0.025 * 0.025, -4000.0);
  MESSAGE("energy " << e0 << " J -> " << e << " J; implicit Euler's factor gives " << implicit_euler
                    << " J");
  CHECK(e == doctest::Approx(implicit_euler).epsilon(0.02));
}

TEST_CASE("xpbd: a spring's damper decays the motion as the damped oscillator's closed form") {
  // One particle (m = 1 kg) on a spring (ks = 100 N/m, kd = 2 N s/m) to a pinned anchor, pulled
  // 0.1 m and released: w = 10 rad/s, zeta = kd / (2 sqrt(ks m)) = 0.1, and
  //   x(t) = x0 exp(-zeta w t) (cos(wd t) + zeta w / wd sin(wd t)),   wd = w sqrt(1 - zeta^2).
  // XPBD's damping term (eq. 26, beta = kd) is implicit, like its spring, so the method is first
  // order: its error falls in proportion to the substep. Over 3 s (e^-3 of the swing left),
  // implicit Euler's own leak, a relative 1/2 w^2 h per second, bounds the error by about
  // 0.1 m x 1/2 w^2 h t e^-(zeta w t) at its worst (t = 1 s): 1.8e-4 m at h = 1e-4 s (measured:
  // 1.84e-4 m; checked with 40 % room), and ten times more at h = 1e-3 s (measured: 1.80e-3 m).
  // A damper ignored leaves the whole swing (an error near 0.1 m); one counted twice decays as
  // e^-2 t instead of e^-t and misses by more than 0.02 m.
  const double x0 = 0.1, w = 10.0, zeta = 0.1, wd = w * std::sqrt(1.0 - zeta * zeta);
  const auto exact = [&](double t) {
    return x0 * std::exp(-zeta * w * t) * (std::cos(wd * t) + zeta * w / wd * std::sin(wd * t));
  };
  const auto worst_error = [&](int substeps) {
    World world = test::anchored_spring(1.0, 100.0, 2.0, x0, 0.0);
    use_xpbd(world, substeps, 1);
    double worst = 0.0;
    for (int s = 1; s <= 300; ++s) {
      world.step(0.01);
      worst = std::max(worst, std::abs(world.particles.x(0, 1) - 1.0 - exact(0.01 * s)));
    }
    return worst;
  };
  const double fine = worst_error(100), coarse = worst_error(10);
  MESSAGE("largest distance from the closed form: " << coarse << " m at h = 1e-3 s, " << fine
                                                    << " m at h = 1e-4 s");
  CHECK(fine <= 2.5e-4);
  CHECK(coarse / fine == doctest::Approx(10.0).epsilon(0.2));  // first order
}

TEST_CASE(
    "xpbd: with a damper the energy never grows, at any kd; without one the step is the same") {
  // The damping term only takes energy out: each step, at 10 ms with 4 substeps, must end with
  // no more energy than it began with (to 1e-12 J), for a damper at 0.1 times critical and at
  // 100 times critical (kd = 2000 N s/m). The latter is where the damper as an explicit force
  // would blow up: it is stable only while kd w dt_s < 2, and here kd w dt_s = 2000 x 2.5e-3 = 5.
  for (const double kd : {2.0, 2000.0}) {
    CAPTURE(kd);
    World world = test::anchored_spring(1.0, 100.0, kd, 0.1, 0.0);
    use_xpbd(world, 4, 1);
    const double e0 = world.kinetic_energy() + world.potential_energy();
    const double e = test::step_without_energy_growth(world, 0.01, 500);
    // After 5 s the swing at 0.1 critical keeps exp(-2 zeta w t) = exp(-10) of its energy; the
    // overdamped spring creeps back as exp(-ks t / kd), keeping exp(-0.5) = 0.61 of it.
    CHECK(e < (kd == 2.0 ? 1e-4 : 0.7) * e0);
  }
  // kd = 0: a substep is exactly implicit Euler on the spring (the test above): from s = 0.1 m,
  // v = 0, s' = (s + h v) / (1 + (w h)^2), v' = (s' - s) / h, to rounding.
  World world = test::anchored_spring(1.0, 100.0, 0.0, 0.1, 0.0);
  use_xpbd(world, 4, 1);
  double s = 0.1, v = 0.0;
  const double h = 0.0025;
  for (int step = 0; step < 100; ++step) {
    world.step(0.01);
    for (int k = 0; k < 4; ++k) {
      const double next = (s + h * v) / (1.0 + 100.0 * h * h);
      v = (next - s) / h;
      s = next;
    }
  }
  CHECK(std::abs(world.particles.x(0, 1) - 1.0 - s) <= 1e-12);
  CHECK(std::abs(world.particles.v(0, 1) - v) <= 1e-9);
}

TEST_CASE("xpbd: scenes read substeps and iterations and run with pins and colliders") {
  const std::string text = test::drape("method = \"xpbd\"\nsubsteps = 8\niterations = 2\n");
  clothlab::Scene scene = clothlab::parse_scene(text, "drape.toml");
  auto* xpbd = dynamic_cast<Xpbd*>(scene.world.integrator.get());
  REQUIRE(xpbd != nullptr);
  CHECK(xpbd->substeps == 8);
  CHECK(xpbd->iterations == 2);
  test::run_to_end(scene);
  // The colliders run after each step (world.cpp) as for every method: no particle ends inside
  // the sphere or under the ground, beyond the colliders' own tolerance of a millimetre.
  for (Index i = 0; i < scene.world.particles.size(); ++i) {
    const Vec3 x = scene.world.particles.x.col(i);
    CHECK((x - Vec3(0.0, 0.5, 0.0)).norm() >= 0.3 - 1e-3);
    CHECK(x.y() >= -1e-3);
  }
  // The defaults: 10 substeps, 1 iteration.
  clothlab::Scene plain = clothlab::parse_scene(
      "[[particle]]\nposition = [0, 0, 0]\nmass = 1\n[integrator]\nmethod = \"xpbd\"\n"
      "dt = 0.01\nduration = 1\n",
      "defaults.toml");
  auto* defaults = dynamic_cast<Xpbd*>(plain.world.integrator.get());
  REQUIRE(defaults != nullptr);
  CHECK(defaults->substeps == 10);
  CHECK(defaults->iterations == 1);
}

TEST_CASE("xpbd: a particle meets the ground in the substep it reaches it and bounces from there") {
  // One particle, no gravity, 0.5 mm above the ground and falling at 1 m/s; one step of 10 ms in
  // 10 substeps of h = 1 ms; restitution e = 0.5. In substep 1 it would end 0.5 mm below: the
  // ground puts it on the surface moving up at e * 1 m/s, and the 9 substeps left carry it up
  // 9 h e = 4.5 mm. A ground applied once a step would find it 9.5 mm below at the step's end
  // and leave it on the surface (y = 0), having lost the rest of the step.
  constexpr double h = 0.001, e = 0.5;
  World world;
  world.particles.add(Vec3(0.0, 0.0005, 0.0), Vec3(0.0, -1.0, 0.0), 0.1);
  clothlab::ContactMaterial material;
  material.e = e;
  world.post_step_effects.push_back(
      std::make_unique<clothlab::Ground>(0.0, material, clothlab::Ground::Model::coulomb, 0.0));
  use_xpbd(world, 10, 1);
  world.step(10 * h);
  CHECK(world.particles.x(1, 0) == doctest::Approx(9 * h * e).epsilon(1e-12));
  CHECK(world.particles.v(1, 0) == doctest::Approx(e).epsilon(1e-12));
  CHECK(world.particles.x(0, 0) == 0.0);
  CHECK(world.particles.x(2, 0) == 0.0);
}

TEST_CASE("xpbd: a sheet dropped on a ball at one step a frame stays near its rest lengths") {
  // The drape (test::drape: 2000 N/m springs, an 8 x 8 sheet falling 0.2 m onto a ball of 0.3 m)
  // at steps of 1/60 s in 64 substeps. The ball meets the cloth in every substep, so no particle
  // goes more than a substep's travel (2 m/s x 0.26 ms, half a millimetre) into it before it is
  // pushed out, and the springs stay within a few per cent of their rest lengths (3.0 %). Met
  // once a step, the ball let the sheet fall 3 cm into it before shoving single particles out:
  // springs stretched by a third (33 %, measured with the contacts of a whole step).
  std::string text = test::drape("method = \"xpbd\"\nsubsteps = 64\n");
  text.replace(text.find("dt = 0.01"), 9, "dt = 0.016666666666666666");
  clothlab::Scene scene = clothlab::parse_scene(text, "drape.toml");
  const clothlab::SpringSet& springs = test::springs_of(scene.world);
  double worst = 0.0;  // the largest |l / l0 - 1| of any spring at the end of any step
  for (long s = 0; s < 60; ++s) {
    scene.world.step(scene.dt);
    const clothlab::Matrix3X& x = scene.world.particles.x;
    for (size_t k = 0; k < springs.size(); ++k) {
      const double l = (x.col(springs.i(k)) - x.col(springs.j(k))).norm();
      worst = std::max(worst, std::abs(l / springs.l0(k) - 1.0));
    }
  }
  MESSAGE("worst strain ", worst);
  CHECK(worst < 0.05);
}

TEST_CASE("xpbd: a pinned corner stays put and a storm tears the sheet") {
  // The storm sheet of tearing.cpp, stepped by XPBD: the pins (w = 0) never move, and springs
  // past the tearing strain are removed between steps; the integrator finds the springs left
  // at each step.
  clothlab::Scene scene = clothlab::parse_scene(
      test::storm("[tearing]\nstrain = 0.3\n") + "method = \"xpbd\"\nsubsteps = 4\n", "storm.toml");
  const size_t springs_before = test::springs_of(scene.world).size();
  const Vec3 pin = scene.world.particles.x.col(0);
  for (long s = 0; s < 2000; ++s)
    scene.world.step(scene.dt);
  CHECK(scene.world.particles.x.col(0) == pin);
  CHECK(test::springs_of(scene.world).size() < springs_before);
}

TEST_CASE("xpbd: the fast path takes no whole step and no force sum, with the same result") {
  // FastEngine takes whole steps for the Euler methods only; an XPBD step sums its external
  // forces effect by effect itself, and leaves only its projections to the backend (tests/fast/
  // checks those). With and without the backend: the same state, bit for bit, and the backend
  // took no step and no force sum.
  test::check_fast_path_declines(test::storm() + "method = \"xpbd\"\n");
}

TEST_CASE("xpbd: the game loop drives an XPBD scene the same for any split into frames") {
  test::check_frames_do_not_matter(test::storm() + "method = \"xpbd\"\nsubsteps = 4\n");
}
