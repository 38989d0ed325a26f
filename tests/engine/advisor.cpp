// The time-step advisor (stability.hpp) and the guard's energy-runaway check.
//
// The advisor's step matrices are a second, readable copy of each integrator written on one
// oscillator: the first cases check that they agree with the engine's integrators step for
// step, so the limits the advisor quotes are the engine's, not a textbook's.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "analysis/run_cost.hpp"
#include "analysis/stability.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/damping.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/methods.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::Vec3;
using clothlab::World;

namespace {

// A unit mass on a spring (ks = w^2, kd = beta, rest length 1 m) to a pinned anchor at the
// origin, displaced by x along the spring with velocity v: exactly the oscillator
// x'' = -w^2 x - beta x' while it stays on the positive x axis.
World oscillator(const std::string& method, double omega, double beta, double x, double v) {
  World world = test::anchored_spring(1.0, omega * omega, beta, x, v);
  world.integrator = clothlab::make_integrator(method);
  if (auto* implicit = dynamic_cast<clothlab::ImplicitEuler*>(world.integrator.get()))
    implicit->tolerance = 1e-15;
  return world;
}

double displacement(const World& world) {
  return world.particles.x(0, 1) - 1.0;
}

}  // namespace

TEST_CASE("advisor: each step matrix is the engine's integrator, step for step") {
  const double omega = 7.0, beta = 1.3, dt = 0.05;
  for (const std::string& method : test::all_integrators()) {
    CAPTURE(method);
    World world = oscillator(method, omega, beta, 0.2, -0.7);
    const Eigen::MatrixXd a = clothlab::oscillator_step_matrix(method, dt, omega, beta);
    if (method != "position-verlet") {
      // Ten steps, each compared with the matrix applied to the state before it.
      for (int s = 0; s < 10; ++s) {
        const Eigen::Vector2d before(displacement(world), world.particles.v(0, 1));
        world.step(dt);
        const Eigen::Vector2d expected = a * before;
        CHECK(displacement(world) == doctest::Approx(expected[0]).epsilon(1e-9));
        CHECK(world.particles.v(0, 1) == doctest::Approx(expected[1]).epsilon(1e-9));
      }
    } else {
      // The state is (x_n, x_n-1, a_n-1): take two steps to have a history, then compare.
      // a_n-1 is the acceleration at step n-1's start, -w^2 x - beta v there.
      double x_prev = displacement(world), v_prev = world.particles.v(0, 1);
      world.step(dt);
      for (int s = 0; s < 10; ++s) {
        const double a_prev = -omega * omega * x_prev - beta * v_prev;
        const Eigen::Vector3d before(displacement(world), x_prev, a_prev);
        x_prev = displacement(world);
        v_prev = world.particles.v(0, 1);
        world.step(dt);
        const Eigen::Vector3d expected = a * before;
        CHECK(displacement(world) == doctest::Approx(expected[0]).epsilon(1e-9));
      }
    }
  }
}

TEST_CASE("advisor: undamped limits are the textbook's y = dt w bounds") {
  const double omega = 10.0;
  // Symplectic Euler and both Verlets: y < 2. RK4: y < 2 sqrt 2.
  for (const char* method : {"symplectic-euler", "velocity-verlet", "position-verlet"}) {
    CAPTURE(method);
    CHECK(clothlab::oscillator_dt_limit(method, omega, 0.0) * omega ==
          doctest::Approx(2.0).epsilon(1e-6));
  }
  CHECK(clothlab::oscillator_dt_limit("rk4", omega, 0.0) * omega ==
        doctest::Approx(2.0 * std::sqrt(2.0)).epsilon(1e-6));
  // Explicit Euler and midpoint gain energy at every dt; implicit Euler never does.
  CHECK(clothlab::oscillator_dt_limit("explicit-euler", omega, 0.0) == 0.0);
  CHECK(clothlab::oscillator_dt_limit("midpoint", omega, 0.0) == 0.0);
  CHECK(std::isinf(clothlab::oscillator_dt_limit("implicit-euler", omega, 0.0)));
}

TEST_CASE("advisor: damped limits match dt^2 k + 2 dt c = 4 m and dt = c / k") {
  const double k = 100.0, m = 1.0;
  for (double c : {0.5, 2.0, 8.0}) {
    CAPTURE(c);
    // Symplectic Euler: the positive root of k dt^2 + 2 c dt - 4 m = 0. Damping SHRINKS it.
    const double symplectic = (-2.0 * c + std::sqrt(4.0 * c * c + 16.0 * k * m)) / (2.0 * k);
    CHECK(clothlab::oscillator_dt_limit("symplectic-euler", std::sqrt(k / m), c / m) ==
          doctest::Approx(symplectic).epsilon(1e-6));
    // Explicit Euler, underdamped: |1 + dt lambda|^2 = 1 - dt c/m + dt^2 k/m < 1, dt < c / k.
    CHECK(clothlab::oscillator_dt_limit("explicit-euler", std::sqrt(k / m), c / m) ==
          doctest::Approx(c / k).epsilon(1e-6));
  }
}

TEST_CASE("advisor: a spring damped far past critical has symplectic Euler's limit, not none") {
  // zeta up to 1e20: the slow mode loses less than rounding a step at the limit, the fast one
  // dies at once. The limit is still the positive root of k dt^2 + 2 c dt - 4 m = 0, about
  // 2 m / c, and the advice says so, without offering the method it has.
  const double k = 100.0, m = 1.0;
  for (double c : {1e4, 1e8, 1e12, 1e16, 1e20}) {
    CAPTURE(c);
    const double root = 4.0 * m / (c + std::sqrt(c * c + 4.0 * k * m));  // the same root, stably
    const double limit = clothlab::oscillator_dt_limit("symplectic-euler", std::sqrt(k / m), c / m);
    CHECK(limit == doctest::Approx(root).epsilon(1e-6));
    World world = test::anchored_spring(m, k, c, 0.01, 0.0);
    world.integrator = clothlab::make_integrator("symplectic-euler");
    const clothlab::TimeStepAdvice advice = clothlab::advise_time_step(world, 1e-3, 200);
    CAPTURE(advice.warning);
    CHECK(advice.dt_limit == doctest::Approx(root).epsilon(1e-6));
    CHECK(advice.warning.find("above the stability limit of symplectic-euler") !=
          std::string::npos);
    CHECK(advice.warning.find("\"symplectic-euler\", which keeps") == std::string::npos);
  }
  // Undamped explicit Euler and midpoint stay unstable at every dt.
  for (const char* method : {"explicit-euler", "midpoint"}) {
    CAPTURE(method);
    CHECK(clothlab::eigenvalue_dt_limit(method, 10.0, 0.0) == 0.0);
  }
}

TEST_CASE("advisor: Gershgorin's bound is exact for one spring and a free pair") {
  // One spring to a pinned anchor: w = sqrt(k / m).
  World anchored = oscillator("symplectic-euler", 12.0, 0.0, 0.0, 0.0);
  CHECK(clothlab::stiffness_bounds(anchored).omega_max == doctest::Approx(12.0));
  // A free pair of masses m: the reduced mass m/2 gives w = sqrt(2 k / m).
  World pair;
  pair.particles.add(Vec3::Zero(), Vec3::Zero(), 2.0);
  pair.particles.add(Vec3(1, 0, 0), Vec3::Zero(), 2.0);
  clothlab::SpringSet spring;
  spring.add_at_rest(0, 1, 50.0, 3.0, pair.particles.x);
  pair.force_effects.push_back(
      std::make_unique<clothlab::SpringDampers>("springs", std::move(spring)));
  pair.integrator = clothlab::make_integrator("symplectic-euler");
  const clothlab::StiffnessBounds b = clothlab::stiffness_bounds(pair);
  CHECK(b.omega_max == doctest::Approx(std::sqrt(2.0 * 50.0 / 2.0)));
  CHECK(b.beta_max == doctest::Approx(2.0 * 3.0 / 2.0));
  CHECK(b.beta_min == 0.0);  // no [damping]: some motion (the pair's drift) is undamped
  // Both rows are the same oscillator, the spring's own, with its damper: merged into one
  // group (two entries at most, if rounding set their ratios a hair apart).
  REQUIRE(!b.rows.empty());
  REQUIRE(b.rows.size() <= 2);
  for (const clothlab::RowOscillator& row : b.rows) {
    CHECK(row.omega == doctest::Approx(std::sqrt(2.0 * 50.0 / 2.0)));
    CHECK(row.beta == doctest::Approx(2.0 * 3.0 / 2.0));
  }
}

TEST_CASE("advisor: on a cloth the bound lies above the true highest frequency, within 2x") {
  const clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 6
cols = 5
spacing = 0.1
mass = 0.3
pins = "top-corners"
[springs]
ks = 200.0
shear_ks = 40.0
[integrator]
dt = 0.001
duration = 0.01
)",
                                                      "<cloth>");
  const World& world = scene.world;
  const clothlab::Particles& p = world.particles;
  // The true w_max^2: the largest eigenvalue of M^-1/2 K M^-1/2 for the free particles, with K
  // assembled densely from the springs' Jacobians.
  const Index n = p.size();
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  struct Dense final : clothlab::ForceJacobians {
    Eigen::MatrixXd& k;
    explicit Dense(Eigen::MatrixXd& m) : k(m) {}
    void add_pair(Index i, Index j, const clothlab::Mat3& dfdx, const clothlab::Mat3&) override {
      k.block<3, 3>(3 * i, 3 * j) += dfdx;
      k.block<3, 3>(3 * j, 3 * i) += dfdx;
      k.block<3, 3>(3 * i, 3 * i) -= dfdx;
      k.block<3, 3>(3 * j, 3 * j) -= dfdx;
    }
    void add_self(Index, const clothlab::Mat3&, const clothlab::Mat3&) override {}
  } dense(k);
  for (const auto& effect : world.force_effects)
    effect->add_jacobians(p, p.x, p.v, dense);
  for (Index i = 0; i < n; ++i) {
    for (Index j = 0; j < n; ++j) {
      const double scale = std::sqrt(p.inv_m[i] * p.inv_m[j]);  // 0 on a pinned row or column
      k.block<3, 3>(3 * i, 3 * j) *= scale;
    }
  }
  const double w_true = std::sqrt((-k).selfadjointView<Eigen::Lower>().eigenvalues().maxCoeff());
  const double w_bound = clothlab::stiffness_bounds(world).omega_max;
  CAPTURE(w_true);
  CAPTURE(w_bound);
  CHECK(w_bound >= w_true * (1.0 - 1e-12));
  CHECK(w_bound <= 2.0 * w_true);
}

TEST_CASE("advisor: it warns above the limit, not below, and its suggestion is stable") {
  const double omega = 10.0;  // symplectic Euler's limit: dt < 2 / w = 0.2 s
  World below = oscillator("symplectic-euler", omega, 0.0, 0.3, 0.0);
  CHECK(clothlab::advise_time_step(below, 0.19, 1000).warning.empty());
  World above = oscillator("symplectic-euler", omega, 0.0, 0.3, 0.0);
  const clothlab::TimeStepAdvice advice = clothlab::advise_time_step(above, 0.21, 1000);
  CHECK(advice.dt_limit == doctest::Approx(0.2).epsilon(1e-6));
  REQUIRE_FALSE(advice.warning.empty());
  CHECK(advice.warning.find("above the stability limit of symplectic-euler") != std::string::npos);
  CHECK(advice.warning.find("implicit-euler") != std::string::npos);
  // Run at the dt it suggests: the energy stays bounded.
  const auto at = advice.warning.find("Take dt <= ");
  REQUIRE(at != std::string::npos);
  const double suggested = std::stod(advice.warning.substr(at + 11));
  CHECK(suggested < 0.2);
  for (int s = 0; s < 2000; ++s)
    above.step(suggested);
  // Stable, not accurate: symplectic Euler keeps H = v^2 + w^2 x^2 - dt w^2 x v, not the
  // energy E = v^2 + w^2 x^2 (in units of m/2). Since |dt w^2 x v| <= (y / 2) E, E stays below
  // H / (1 - y / 2), 10 times its start at y = 1.8, but it never grows past that.
  const double y = suggested * omega;
  CHECK(above.kinetic_energy() + above.potential_energy() <=
        0.5 * 100.0 * 0.09 / (1.0 - y / 2.0) * (1.0 + 1e-9));
}

TEST_CASE("advisor: explicit Euler is flagged by the growth over the run") {
  World world = oscillator("explicit-euler", 10.0, 0.0, 0.3, 0.0);
  // Energy factor 1 + y^2 a step: y = 0.01 over 100 steps grows the amplitude by
  // (1 + 1e-4)^50 ~ 1.005 (fine); over 100 000 steps by e^5 ~ 150 (flagged).
  CHECK(clothlab::advise_time_step(world, 0.001, 100).warning.empty());
  const clothlab::TimeStepAdvice advice = clothlab::advise_time_step(world, 0.001, 100000);
  CHECK(advice.dt_limit == 0.0);
  CHECK(advice.growth == doctest::Approx(std::exp(0.5 * 100000 * std::log1p(1e-4))));
  CHECK(advice.warning.find("adds energy at every step") != std::string::npos);
}

TEST_CASE("guard: a slow energy runaway stops long before the speed bound") {
  // Explicit Euler on an undamped spring multiplies the energy by 1 + y^2 every step: with
  // y = 0.1 that is 1.01, and the energy passes 1 + 10^4 times its start (the default
  // max_energy_growth over the scene's energy scale, here the spring's 4.5 J) after
  // ln(10001) / ln(1.01) = 925.6 steps, at speeds of a few hundred m/s, far below the bound.
  // A zero-length spring keeps the force exactly linear however far the particle swings.
  World world;
  world.particles.add(Vec3::Zero(), Vec3::Zero(), 1.0);
  world.particles.inv_m[0] = 0.0;
  world.particles.add(Vec3(0.3, 0.0, 0.0), Vec3::Zero(), 1.0);
  clothlab::SpringSet spring;
  spring.add(0, 1, 100.0, 0.0, 0.0);
  world.force_effects.push_back(
      std::make_unique<clothlab::SpringDampers>("springs", std::move(spring)));
  world.integrator = clothlab::make_integrator("explicit-euler");
  long stopped_at = -1;
  std::string message;
  try {
    for (int s = 0; s < 5000; ++s)
      world.step(0.01);
  } catch (const clothlab::SimulationError& e) {
    stopped_at = e.step();
    message = e.what();
  }
  const double first_over = std::log(10001.0) / std::log(1.01);
  CHECK(stopped_at > first_over);
  CHECK(stopped_at <= first_over + 32);  // the energy is checked every 32 steps
  CHECK(message.find("ran away") != std::string::npos);
  CHECK(message.find("particle 1") != std::string::npos);
  CHECK(world.particles.v.cwiseAbs().maxCoeff() < 1e3);
}

TEST_CASE("guard: a falling or bouncing particle has its fall as energy scale") {
  // One particle alone has no size and no stored energy: the energy gravity releases as it
  // falls is the yardstick. Explicit Euler's free fall gains m g^2 dt^2 / 2 a step, which stays
  // a small fraction of what the fall released, so the run must not be stopped.
  World world;
  world.particles.add(Vec3(0.0, 100.0, 0.0), Vec3::Zero(), 1.0);
  world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0, -9.8, 0)));
  world.integrator = clothlab::make_integrator("explicit-euler");
  for (int s = 0; s < 2000; ++s)
    world.step(0.002);
  // The last check was at step 1984 (every 32 steps): m g (g t^2 / 2) at t = 3.968 s, less
  // explicit Euler's lag of g dt t / 2.
  const double t = 1984 * 0.002;
  CHECK(world.guard.energy_scale() ==
        doctest::Approx(9.8 * (0.5 * 9.8 * t * t - 0.5 * 9.8 * 0.002 * t)).epsilon(1e-9));
}

TEST_CASE("guard: a field added after the start releases energy from where the run started") {
  // The guard keeps each field's energy at the start; gravity switched on after the first step
  // has none kept, and its release is measured from the start's positions all the same.
  World world;
  world.particles.add(Vec3(0.0, 100.0, 0.0), Vec3::Zero(), 1.0);
  world.integrator = clothlab::make_integrator("explicit-euler");
  world.step(0.002);  // the start: nothing acts, nothing moves
  world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0, -9.8, 0)));
  for (int s = 1; s < 2000; ++s)
    world.step(0.002);
  // At the last check (step 1984) gravity has acted for n = 1983 steps: explicit Euler's drop
  // g dt^2 n (n - 1) / 2 from the start's 100 m, times m g.
  const double n = 1983, dt = 0.002;
  CHECK(world.guard.energy_scale() ==
        doctest::Approx(9.8 * 9.8 * dt * dt * n * (n - 1) / 2).epsilon(1e-9));
}

TEST_CASE("guard: the energy check leaves a damped, driven or falling scene alone") {
  // A flag in a strong wind under gravity for 4 s: energy grows (the wind does work) but stays
  // within the scene's energy scale.
  clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 8
cols = 8
spacing = 0.1
mass = 0.2
pins = "left-edge"
[springs]
ks = 300.0
kd = 0.5
[gravity]
[aerodynamics]
wind = [12.0, 0.0, 3.0]
[integrator]
method = "symplectic-euler"
dt = 0.001
duration = 4.0
)",
                                                "<flag>");
  test::run_to_end(scene);
  CHECK(scene.world.guard.energy_scale() > 0.0);
}

TEST_CASE("guard: max_energy_growth is read from [guard]") {
  const clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
[guard]
max_energy_growth = 5.0
[integrator]
dt = 0.01
duration = 1.0
)",
                                                      "<guard>");
  CHECK(scene.world.guard.max_energy_growth == 5.0);
}

namespace {

// The number in `text` after `prefix` (which must be there), as the reader of the text sees it.
double number_after(const std::string& text, const std::string& prefix) {
  const auto at = text.find(prefix);
  REQUIRE_MESSAGE(at != std::string::npos, "no \"" << prefix << "\" in: " << text);
  return std::stod(text.substr(at + prefix.size()));
}

// The largest stable dt [s] of `method` on (w, beta) found here, apart from the advisor: the
// spectral radius of the step matrix (checked against the engine's steps above) scanned up from
// y = 1e-3 in steps of 1 %, then bisected. Infinity above y = 1e3.
double scanned_limit(const std::string& method, double omega, double beta) {
  const auto stable = [&](double y) {
    return clothlab::spectral_radius(
               clothlab::oscillator_step_matrix(method, y / omega, omega, beta)) <= 1.0 + 1e-12;
  };
  double y = 1e-3;
  REQUIRE(stable(y));
  while (y < 1e3 && stable(1.01 * y))
    y *= 1.01;
  if (y >= 1e3) return std::numeric_limits<double>::infinity();
  double lo = y, hi = 1.01 * y;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return lo / omega;
}

double energy(const World& world) {
  return world.kinetic_energy() + world.potential_energy();
}

}  // namespace

TEST_CASE("advisor: a printed limit never exceeds the true one") {
  // The issue's case: symplectic Euler at w = 10 rad/s and zeta = 0.5 has the limit
  // (sqrt(5) - 1) / 10 = 0.1236 s, which rounds to 0.124 s to nearest, above the limit.
  CHECK(clothlab::describe_dt_limit((std::sqrt(5.0) - 1.0) / 10.0) == "dt <= 0.123 s");
  CHECK(clothlab::describe_dt_limit(0.0) == "none (unstable at every dt)");
  CHECK(clothlab::describe_dt_limit(std::numeric_limits<double>::infinity()) == "any");
  // Rounding down keeps three digits and never goes up, over many magnitudes.
  std::mt19937 random(8);
  std::uniform_real_distribution<double> exponent(-9.0, 3.0);
  for (int i = 0; i < 20000; ++i) {
    const double x = std::pow(10.0, exponent(random));
    const double printed = std::stod(clothlab::round_down(x));
    CAPTURE(x);
    CHECK(printed <= x);
    CHECK(printed > x * (1.0 - 1e-2));
  }
  // What the advisor prints, over springs from soft to stiff, light to heavy, with and without
  // dampers: the limit `clothlab validate` prints, the "about" of the warning, and the dt it
  // suggests are all at most the limit.
  for (const char* method : {"symplectic-euler", "explicit-euler", "rk4", "position-verlet"}) {
    for (double k : {1.0, 7.3, 50.0, 640.0, 2.0e4}) {
      for (double m : {3.4e-4, 0.02, 0.5, 1.7}) {
        for (double zeta : {0.0, 0.1, 0.5, 2.0}) {
          if (zeta == 0.0 && std::string(method) == "explicit-euler") continue;
          CAPTURE(method);
          CAPTURE(k);
          CAPTURE(m);
          CAPTURE(zeta);
          World world = test::anchored_spring(m, k, 2.0 * zeta * std::sqrt(k * m), 0.01, 0.0);
          world.integrator = clothlab::make_integrator(method);
          const double limit =
              clothlab::advise_time_step(world, 1e-9, 1).dt_limit;  // no warning at this dt
          REQUIRE(std::isfinite(limit));
          REQUIRE(limit > 0.0);
          CHECK(number_after(clothlab::describe_dt_limit(limit), "dt <= ") <= limit);
          const clothlab::TimeStepAdvice above =
              clothlab::advise_time_step(world, 2.0 * limit, 500);
          REQUIRE_FALSE(above.warning.empty());
          CHECK(number_after(above.warning, ", about ") <= limit);
          CHECK(number_after(above.warning, "Take dt <= ") <= limit);
        }
      }
    }
  }
}

TEST_CASE("advisor: with dampers every method gets its damped limit, and the engine agrees") {
  // One particle on a spring-damper, for several (w, zeta). The advisor's limit must be the
  // closed form where there is one (stability.cpp derives them) and the scan of the step
  // matrix's spectral radius above everywhere; then the engine's own run of the spring decays
  // at 0.99 of the limit and grows at 1.01 of it.
  const double m = 0.5;
  for (const std::string& method : test::all_integrators()) {
    for (double omega : {3.0, 40.0}) {
      for (double zeta : {0.05, 0.3, 0.7, 1.5}) {
        CAPTURE(method);
        CAPTURE(omega);
        CAPTURE(zeta);
        const double k = omega * omega * m, c = 2.0 * zeta * omega * m;
        World probe = test::anchored_spring(m, k, c, 1e-4, 0.0);
        probe.integrator = clothlab::make_integrator(method);
        const clothlab::TimeStepAdvice advice = clothlab::advise_time_step(probe, 1e-6, 1);
        const double limit = advice.dt_limit;
        CHECK(advice.warning.empty());
        if (method == "implicit-euler") {
          CHECK(std::isinf(limit));
          continue;
        }
        REQUIRE(std::isfinite(limit));
        CHECK(limit ==
              doctest::Approx(scanned_limit(method, omega, 2.0 * zeta * omega)).epsilon(1e-9));
        double y = std::nan("");  // the closed form of y = dt w, where there is one
        if (method == "explicit-euler")
          y = zeta < 1.0 ? 2.0 * zeta : 2.0 / (zeta + std::sqrt(zeta * zeta - 1.0));
        if (method == "symplectic-euler") y = std::sqrt(4.0 * zeta * zeta + 4.0) - 2.0 * zeta;
        if (method == "position-verlet") y = std::sqrt(16.0 * zeta * zeta + 4.0) - 4.0 * zeta;
        if (method == "velocity-verlet")
          y = zeta < 0.5
                  ? 2.0 * (std::sqrt(1.0 - 3.0 * zeta * zeta) - zeta) / (1.0 - 4.0 * zeta * zeta)
                  : 1.0 / zeta;
        if (!std::isnan(y)) CHECK(limit * omega == doctest::Approx(y).epsilon(1e-9));

        // N steps, enough for the growing mode's amplitude to grow 10 times at 1.01 of the
        // limit. Three times N: the start may hold little of the growing mode, but after N steps
        // it leads, and the highest energy of steps 2N to 3N is about 100 times that of steps N
        // to 2N (30 is asked: the energy swings within a period). The steps call the
        // integrator directly: the guard would stop a growing run, which is the point here.
        const double rho = clothlab::spectral_radius(
            clothlab::oscillator_step_matrix(method, 1.01 * limit, omega, c / m));
        REQUIRE(rho > 1.0);
        const int steps = static_cast<int>(std::ceil(std::log(10.0) / std::log(rho)));
        REQUIRE(steps < 1000000);
        for (const double fraction : {0.99, 1.01}) {
          CAPTURE(fraction);
          World world = test::anchored_spring(m, k, c, 1e-4, 0.7e-4 * omega);
          world.integrator = clothlab::make_integrator(method);
          const double e0 = energy(world);
          double second = 0.0, third = 0.0;  // the highest energy of steps N to 2N, 2N to 3N
          for (int s = 1; s <= 3 * steps; ++s) {
            world.integrator->advance(world, fraction * limit);
            if (s > steps) {
              double& peak = s <= 2 * steps ? second : third;
              peak = std::max(peak, energy(world));
            }
          }
          if (fraction < 1.0)
            CHECK(energy(world) < e0);
          else
            CHECK(third > 30.0 * second);
        }
      }
    }
  }
}

TEST_CASE("advisor: explicit Euler on a cloth with dampers is stable up to kd / ks") {
  // A cloth whose every spring has the same kd / ks: each particle's damping row is kd / ks
  // times its stiffness row, so every row's oscillator has beta = (kd / ks) w^2, and explicit
  // Euler's underdamped limit beta / w^2 = kd / ks is the same for every row (and for every
  // mode of the true cloth). The advisor must say so, not "unstable at every dt", and the cloth
  // must settle below it and blow up above it.
  const std::string text = R"(
[cloth]
rows = 6
cols = 5
spacing = 0.1
mass = 0.3
pins = "top-corners"
[springs]
ks = 200.0
kd = 0.4
[integrator]
method = "explicit-euler"
dt = 0.001
duration = 10.0
)";
  const double ratio = 0.4 / 200.0;  // kd / ks = 2 ms
  const clothlab::Scene scene = clothlab::parse_scene(text, "<damped cloth>");
  const clothlab::TimeStepAdvice advice =
      clothlab::advise_time_step(scene.world, scene.dt, scene.step_count());
  CHECK(advice.dt_limit == doctest::Approx(ratio).epsilon(1e-9));
  CHECK(advice.warning.empty());
  // Each free particle nudged by up to 1 mm, so that every mode starts with some energy.
  for (const double fraction : {0.95, 1.05}) {
    CAPTURE(fraction);
    clothlab::Scene run = clothlab::parse_scene(text, "<damped cloth>");
    World& world = run.world;
    std::mt19937 random(3);
    std::uniform_real_distribution<double> nudge(-1e-3, 1e-3);
    for (Index i = 0; i < world.particles.size(); ++i)
      if (world.particles.inv_m[i] != 0.0)
        world.particles.x.col(i) += Vec3(nudge(random), nudge(random), nudge(random));
    const double e0 = energy(world);
    for (int s = 0; s < 5000; ++s)
      world.integrator->advance(world, fraction * ratio);
    if (fraction < 1.0)
      CHECK(energy(world) < 1e-3 * e0);
    else
      CHECK(!(energy(world) < 1e3 * e0));  // grown a thousand times, or no longer finite
  }
}

namespace {

// A cloth of `rows` x `rows` particles stepped by `integrator` (TOML lines) with `extra` tables.
clothlab::Scene cost_scene(int rows, const std::string& integrator, const std::string& extra = "") {
  const std::string text = "[cloth]\nrows = " + std::to_string(rows) +
                           "\ncols = " + std::to_string(rows) +
                           "\nspacing = 0.01\nmass = 1\npins = \"top-corners\"\n"
                           "[springs]\nks = 1000\n[gravity]\n" +
                           extra + "[integrator]\n" + integrator;
  return clothlab::parse_scene(text, "<cost>");
}

}  // namespace

TEST_CASE(
    "advisor: a run that cannot finish or whose files will not fit is told before it starts") {
  // 100 x 100: 39402 springs. XPBD with 1000 substeps and 10 iterations projects 3.9e8
  // constraints a step, about 20 s at 51 ns each: hours for 1000 steps.
  const std::string xpbd =
      "method = \"xpbd\"\nsubsteps = 1000\niterations = 10\ndt = 0.01\nduration = 10\n";
  std::vector<std::string> warnings =
      clothlab::run_cost_warnings(cost_scene(100, xpbd), false, false, false);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("XPBD projects 3.94e+08 constraints a step (39402 springs x 1000 "
                         "substeps x 10 iterations): about 20 s a step and 5.6 h for the run's "
                         "1000 steps") == 0);
  // The same for each costly part, and only those the scene has.
  const std::string plain = "dt = 0.001\nduration = 100\n";
  warnings = clothlab::run_cost_warnings(
      cost_scene(100, plain, "[strain_limit]\nmax_strain = 0.1\niterations = 100\n"), false, false,
      false);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("[strain_limit] sweeps 39402 springs up to 100 times a step") == 0);
  warnings = clothlab::run_cost_warnings(
      cost_scene(100, plain, "[self_collision]\nthickness = 0.001\niterations = 100\n"), false,
      false, false);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("[self_collision] checks 10000 particles for pairs up to 100 times") == 0);
  warnings = clothlab::run_cost_warnings(
      cost_scene(100, "method = \"local-global\"\niterations = 50\n" + plain), false, false, false);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("the local/global solver takes 50 iterations a step") == 0);
  warnings = clothlab::run_cost_warnings(
      cost_scene(100, "method = \"vbd\"\niterations = 50\n" + plain), false, false, false);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("vertex block descent takes 50 iterations a step over 39402 springs") ==
        0);
  warnings = clothlab::run_cost_warnings(cost_scene(100, "method = \"implicit-euler\"\n" + plain),
                                         false, false, false);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("implicit Euler's solve takes up to 500 conjugate-gradient") == 0);

  // 300 x 300 particles at 52 bytes a row, a frame a step for 1000 steps: 1001 frames of 4.68 MB.
  const std::string every_step = "dt = 0.01\nduration = 10\n[output]\nfps = 100\n";
  warnings = clothlab::run_cost_warnings(cost_scene(300, every_step), false, false, false);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0] ==
        "the run will write about 4.68 GB (1001 frames of 4.68 MB), in CSV files; lower [output] "
        "fps, or choose format = \"npy\" (12 bytes a particle, not about 52)");
  CHECK(clothlab::run_cost_warnings(cost_scene(300, every_step), false, false, true).empty());

  // A lesson's scene: nothing to say.
  CHECK(clothlab::run_cost_warnings(cost_scene(20, "dt = 0.001\nduration = 2\n"), true, true, false)
            .empty());
}
