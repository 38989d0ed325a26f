// The integrators of lesson 07 through the whole engine: order of accuracy, the energy each
// method gains or loses per step, what symplectic methods conserve instead of the energy, what
// a step costs in force evaluations, and what must hold for any method (momentum, pins).
//
// Most tests use the 1D linear oscillator: particle 0 pinned at the origin, particle 1 of mass m
// at (1 + x, 0, 0) joined to it by one spring (ks, kd, l0 = 1). It moves along x and never
// reaches the anchor, so l - l0 = x exactly and the spring force is exactly linear:
//   m x'' = -ks x - kd x',   w = sqrt(ks / m),   zeta = kd / (2 sqrt(ks m)).
// The implicit integrator's linearisation of the spring is exact along it, so every method
// acts on this system as a fixed 2x2 matrix on (x, v): its amplification matrix.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "clothlab/bodies/cloth.hpp"
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

// The named integrator; the implicit one solves to 1e-13, so its error is the method's alone.
std::unique_ptr<clothlab::Integrator> tight_integrator(const std::string& method) {
  std::unique_ptr<clothlab::Integrator> integrator = clothlab::make_integrator(method);
  REQUIRE(integrator != nullptr);
  if (auto* implicit = dynamic_cast<clothlab::ImplicitEuler*>(integrator.get())) {
    implicit->tolerance = 1e-13;
    implicit->max_iterations = 1000;
  }
  return integrator;
}

// The oscillator above: mass m [kg], spring ks [N/m], damper kd [N s/m], starting at
// displacement x0 [m] from rest with velocity v0 [m/s].
World oscillator(const std::string& method, double m, double ks, double kd, double x0, double v0) {
  World world = test::anchored_spring(m, ks, kd, x0, v0);
  world.integrator = tight_integrator(method);
  return world;
}

double displacement(const World& world) {
  return world.particles.x(0, 1) - 1.0;
}
double velocity(const World& world) {
  return world.particles.v(0, 1);
}
double energy(const World& world) {
  return world.kinetic_energy() + world.potential_energy();
}

// The exact damped oscillator (zeta < 1) from x0, v0: with s = zeta w, wd = w sqrt(1 - zeta^2),
//   x(t) = e^(-s t) (x0 cos wd t + (v0 + s x0) / wd sin wd t)
//   v(t) = e^(-s t) (v0 cos wd t - (w^2 x0 + s v0) / wd sin wd t)   (x' of the line above).
struct Exact {
  double x, v;
};
Exact damped_oscillator(double w, double zeta, double x0, double v0, double t) {
  const double s = zeta * w, wd = w * std::sqrt(1.0 - zeta * zeta);
  const double decay = std::exp(-s * t), c = std::cos(wd * t), sn = std::sin(wd * t);
  return {decay * (x0 * c + (v0 + s * x0) / wd * sn),
          decay * (v0 * c - (w * w * x0 + s * v0) / wd * sn)};
}

// Adds to `world` a rows x cols cloth `spacing` [m] apart, of `mass` [kg] in all, with
// structural springs of ks and shear springs of shear_ks [N/m], every one with the damper kd
// [N s/m], as the effect "springs". No pins, no other effect; returns the cloth's grid.
clothlab::ClothGrid add_spring_cloth(World& world, Index rows, Index cols, double spacing,
                                     double mass, double ks, double shear_ks, double kd) {
  clothlab::ClothSpec spec;
  spec.rows = rows;
  spec.cols = cols;
  spec.spacing = spacing;
  spec.mass = mass;
  const clothlab::ClothGrid grid = clothlab::add_cloth(world.particles, spec);
  clothlab::SpringSet springs;
  clothlab::add_spring_family(springs, clothlab::structural_pairs(rows, cols), grid.first, ks, kd,
                              world.particles.x);
  clothlab::add_spring_family(springs, clothlab::shear_pairs(rows, cols), grid.first, shear_ks, kd,
                              world.particles.x);
  world.force_effects.push_back(
      std::make_unique<clothlab::SpringDampers>("springs", std::move(springs)));
  return grid;
}

// A free square of cloth, rows x cols, structural and shear springs with dampers, no pins.
World free_cloth(const std::string& method, Index rows, Index cols) {
  // 20 cm apart, 0.1 kg a particle; ks = 40 N/m (shear 20 N/m), kd = 0.05 N s/m.
  World world;
  add_spring_cloth(world, rows, cols, 0.2, 0.1 * static_cast<double>(rows * cols), 40.0, 20.0,
                   0.05);
  world.integrator = tight_integrator(method);
  return world;
}

}  // namespace

TEST_CASE("integrators: convergence order on the damped oscillator, in position and velocity") {
  // m = 0.5 kg, ks = 50 N/m, kd = 1 N s/m: w = 10 rad/s, zeta = 1 / (2 sqrt(25)) = 0.1.
  // Error at t = 1 s against the exact solution, for dt, dt/2, dt/4. Halving dt divides an
  // error C dt^p by 2^p, so p = log2(e(dt) / e(dt/2)). Each dt range below is in the
  // asymptotic range of its method: dt w <= 0.004 for the first-order methods, <= 0.04 for the
  // second-order ones, <= 0.05 for RK4, where the next term of the error moves the measured p
  // by less than 0.04 (it shrinks with dt: RK4 gives 3.964 then 3.983). A wrong order is off
  // by 1, so +-0.05 separates them.
  const double m = 0.5, ks = 50.0, kd = 1.0, x0 = 0.2, v0 = 0.5, t_end = 1.0;
  const double w = std::sqrt(ks / m), zeta = kd / (2.0 * std::sqrt(ks * m));
  const Exact exact = damped_oscillator(w, zeta, x0, v0, t_end);
  struct Case {
    const char* method;
    double dt;     // the largest step [s]; then dt/2 and dt/4
    double order;  // expected p
  };
  const Case cases[] = {{"explicit-euler", 4e-4, 1.0},  {"symplectic-euler", 4e-4, 1.0},
                        {"midpoint", 2e-3, 2.0},        {"rk4", 5e-3, 4.0},
                        {"velocity-verlet", 4e-3, 2.0}, {"position-verlet", 4e-3, 2.0},
                        {"implicit-euler", 4e-4, 1.0}};
  for (const Case& c : cases) {
    const std::string method = c.method;
    CAPTURE(method);
    double ex[3], ev[3];
    for (int k = 0; k < 3; ++k) {
      const double dt = c.dt / (1 << k);
      const long n = std::lround(t_end / dt);
      World world = oscillator(c.method, m, ks, kd, x0, v0);
      for (long s = 0; s < n; ++s)
        world.step(dt);
      ex[k] = std::abs(displacement(world) - exact.x);
      ev[k] = std::abs(velocity(world) - exact.v);
    }
    for (int k = 0; k < 2; ++k) {
      CAPTURE(k);
      const double px = std::log2(ex[k] / ex[k + 1]), pv = std::log2(ev[k] / ev[k + 1]);
      CHECK(std::abs(px - c.order) < 0.05);
      CHECK(std::abs(pv - c.order) < 0.05);
    }
  }
}

TEST_CASE("integrators: one step multiplies the undamped oscillator's energy by |R(i y)|^2") {
  // With u = w x, the undamped oscillator is (u, v)' = w J (u, v), J = [[0, 1], [-1, 0]],
  // J^2 = -I, and E = m/2 (u^2 + v^2) is the squared length of (u, v). A one-step method maps
  // (u, v) to R(y J) (u, v), y = dt w, with R a polynomial (or rational function): R(yJ) =
  // Re R(iy) I + Im R(iy) J, a rotation times |R(iy)|, so every state's energy is multiplied by
  //   |R(iy)|^2 = (Re R)^2 + (Im R)^2, whatever the state:
  //   explicit Euler   R = 1 + z                        |R|^2 = 1 + y^2
  //   midpoint         R = 1 + z + z^2/2                |R|^2 = 1 + y^4/4
  //   RK4              R = 1 + z + ... + z^4/24         |R|^2 = 1 - y^6/72 + y^8/576
  //   implicit Euler   R = 1 / (1 - z)                  |R|^2 = 1 / (1 + y^2)
  // (implicit Euler solves this linear system exactly, to the solver's 1e-13).
  const double m = 0.5, ks = 50.0, w = std::sqrt(ks / m);
  struct Case {
    const char* method;
    double (*factor)(double y);
  };
  const Case cases[] = {
      {"explicit-euler", [](double y) { return 1.0 + y * y; }},
      {"midpoint", [](double y) { return 1.0 + std::pow(y, 4) / 4.0; }},
      {"rk4", [](double y) { return 1.0 - std::pow(y, 6) / 72.0 + std::pow(y, 8) / 576.0; }},
      {"implicit-euler", [](double y) { return 1.0 / (1.0 + y * y); }}};
  const double states[][2] = {{0.2, 0.0}, {0.0, 1.5}, {-0.1, 0.8}, {0.05, -2.0}};  // x [m], v [m/s]
  for (const Case& c : cases) {
    for (double y : {0.05, 0.3, 1.0}) {
      for (const auto& state : states) {
        const std::string method = c.method;
        CAPTURE(method);
        CAPTURE(y);
        CAPTURE(state[0]);
        CAPTURE(state[1]);
        World world = oscillator(c.method, m, ks, 0.0, state[0], state[1]);
        const double e0 = energy(world);
        world.step(y / w);
        CHECK(energy(world) / e0 == doctest::Approx(c.factor(y)).epsilon(1e-12));
      }
    }
  }
}

TEST_CASE("integrators: symplectic Euler and velocity Verlet conserve a modified energy") {
  // Undamped, a = -w^2 x, h = dt, evaluated at the state (x_n, v_n) the engine holds after
  // each step.
  //
  // Symplectic Euler (euler.hpp: velocity first, then position with the new velocity):
  //   v' = v - h w^2 x,   x' = x + h v'.
  // Q = v^2 + w^2 x^2 - h w^2 x v is conserved: w^2 x'^2 - h w^2 x' v' = w^2 x' (x' - h v')
  // = w^2 x' x = w^2 x^2 + h w^2 x v', so Q' = v'^2 + h w^2 x v' + w^2 x^2, and
  // v'^2 + h w^2 x v' = v' (v' + h w^2 x) = v' v = v^2 - h w^2 x v: Q' = Q. This is the
  // invariant as given, with x and v taken at the same step n.
  //
  // Velocity Verlet (verlet.hpp; with no damper the predicted velocity plays no part):
  //   x' = x + h v - h^2 w^2 x / 2,   v' = v - h w^2 (x + x') / 2.
  // From the first, (x' - x)(1 - h^2 w^2 / 4) = h (v + v') / 2; times the second, times w^2:
  //   w^2 (1 - h^2 w^2 / 4)(x'^2 - x^2) = -(v'^2 - v^2),
  // so Q = v^2 + w^2 x^2 (1 - h^2 w^2 / 4) is conserved.
  //
  // Both hold exactly in exact arithmetic. In doubles Q drifts by rounding only: a position
  // near 1 m rounds to 1.1e-16 m, 1e-15 of a 0.1 m swing, so even if every one of 5000 steps
  // rounded the same way Q would drift by less than about 1e-11. The true energy, for contrast,
  // swings by O(h w) (Euler) and O((h w)^2) (Verlet) every period.
  const double m = 0.5, ks = 50.0, w = std::sqrt(ks / m);
  for (double y : {0.1, 1.0, 1.9}) {
    const double h = y / w;
    CAPTURE(y);
    World euler = oscillator("symplectic-euler", m, ks, 0.0, 0.1, 0.7);
    World verlet = oscillator("velocity-verlet", m, ks, 0.0, 0.1, 0.7);
    const auto q_euler = [&](const World& world) {
      const double x = displacement(world), v = velocity(world);
      return v * v + w * w * x * x - h * w * w * x * v;
    };
    const auto q_verlet = [&](const World& world) {
      const double x = displacement(world), v = velocity(world);
      return v * v + w * w * x * x * (1.0 - h * h * w * w / 4.0);
    };
    const double q0_euler = q_euler(euler), q0_verlet = q_verlet(verlet);
    const double e0_euler = energy(euler), e0_verlet = energy(verlet);
    double drift_euler = 0.0, drift_verlet = 0.0, swing_euler = 0.0, swing_verlet = 0.0;
    for (int s = 0; s < 5000; ++s) {
      euler.step(h);
      verlet.step(h);
      drift_euler = std::max(drift_euler, std::abs(q_euler(euler) / q0_euler - 1.0));
      drift_verlet = std::max(drift_verlet, std::abs(q_verlet(verlet) / q0_verlet - 1.0));
      swing_euler = std::max(swing_euler, std::abs(energy(euler) / e0_euler - 1.0));
      swing_verlet = std::max(swing_verlet, std::abs(energy(verlet) / e0_verlet - 1.0));
    }
    CHECK(drift_euler < 1e-11);
    CHECK(drift_verlet < 1e-11);
    CHECK(swing_euler > 0.01 * y);  // the energy itself is not conserved
    CHECK(swing_verlet > 0.001 * y * y);
  }
}

TEST_CASE("integrators: force evaluations per step") {
  // What a step costs: Euler and position Verlet evaluate forces once, midpoint and velocity
  // Verlet twice (verlet.hpp: a second time at the new positions), RK4 four times, implicit
  // Euler once (plus its Jacobians and a linear solve, which compute_forces does not count).
  const std::map<std::string, int> evaluations = {
      {"explicit-euler", 1},  {"symplectic-euler", 1}, {"midpoint", 2},      {"rk4", 4},
      {"velocity-verlet", 2}, {"position-verlet", 1},  {"implicit-euler", 1}};
  for (const std::string& method : test::all_integrators()) {
    CAPTURE(method);
    const int expected = evaluations.at(method);  // every method must be listed above
    World world = free_cloth(method, 3, 3);
    world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0.0, -9.8, 0.0)));
    CHECK(world.integrator->force_evaluations_per_step() == expected);
    CHECK(world.force_evaluations == 0);
    for (int s = 0; s < 10; ++s)
      world.step(1e-3);
    CHECK(world.force_evaluations == 10L * expected);
    CHECK(world.force_evaluations == 10L * world.integrator->force_evaluations_per_step());
  }
}

TEST_CASE("integrators: internal forces conserve momentum under every method") {
  // Springs and their dampers push equal and opposite (f2 = -f1), so sum f = 0 at every state
  // any stage evaluates, and every method here updates sum m v by dt times a weighted sum of
  // such total forces: momentum stays what it was, up to rounding. Implicit Euler's solve
  // keeps it too: the columns of dt D + dt^2 K sum to zero, so sum (A dv) = sum m dv, and
  // sum b = 0; what remains is the solver's residual, here 1e-13 relative.
  // Rounding allows 1e-13 of sum m |v|, except for position Verlet: its velocity is the
  // difference quotient (x' - x) / dt, whose rounding is 1.1e-16 |x| / dt ~ 1e-13 m/s per
  // particle at dt = 5e-4 s, whatever the momentum; it is allowed 2e-12.
  for (const std::string& method : test::all_integrators()) {
    CAPTURE(method);
    World world = free_cloth(method, 3, 3);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> speed(-1.0, 1.0);
    clothlab::Particles& p = world.particles;
    for (Index i = 0; i < p.size(); ++i)
      p.v.col(i) = Vec3(speed(random), speed(random), speed(random));
    // The scale rounding is measured against: sum m |v| [kg m/s].
    const double scale = p.m.dot(p.v.colwise().norm().transpose());
    const Vec3 p0 = world.momentum();
    double drift = 0.0;
    for (int s = 0; s < 2000; ++s) {
      world.step(5e-4);
      drift = std::max(drift, (world.momentum() - p0).norm() / scale);
    }
    CHECK(drift < (method == "position-verlet" ? 2e-12 : 1e-13));
    // The cloth did deform: the springs were working.
    CHECK(world.potential_energy() > 1e-4);
  }
}

TEST_CASE("integrators: position Verlet follows a state set between steps, not its history") {
  // Position Verlet keeps x_prev. When something else moves a particle (here the test, as a
  // collision would), x_prev must be rebuilt from the new x and v; otherwise the next step
  // uses x - x_prev as the velocity and jumps. A fresh integrator started at the new state
  // rebuilds x_prev the same way (verlet.hpp), so the two runs must agree bit for bit. The
  // pinned anchor has x_prev = x either way.
  const double m = 0.5, ks = 50.0, kd = 0.3, dt = 2e-3;
  struct Change {
    const char* what;
    bool set_x;
    double x;  // the new displacement of particle 1 [m]
    bool set_v;
    double v;  // its new velocity [m/s]
  };
  const Change changes[] = {{"position and velocity", true, -0.15, true, 0.9},
                            {"position only", true, 0.3, false, 0.0},
                            {"velocity only", false, 0.0, true, -1.2},
                            {"nothing (the history is kept)", false, 0.0, false, 0.0}};
  for (const Change& change : changes) {
    CAPTURE(change.what);
    World moved = oscillator("position-verlet", m, ks, kd, 0.2, 0.0);
    for (int s = 0; s < 100; ++s)
      moved.step(dt);
    if (change.set_x) moved.particles.x(0, 1) = 1.0 + change.x;
    if (change.set_v) moved.particles.v(0, 1) = change.v;
    World fresh = oscillator("position-verlet", m, ks, kd, 0.0, 0.0);
    fresh.particles.x = moved.particles.x;
    fresh.particles.v = moved.particles.v;
    bool same = true;
    for (int s = 0; s < 50; ++s) {
      moved.step(dt);
      fresh.step(dt);
      same =
          same && moved.particles.x == fresh.particles.x && moved.particles.v == fresh.particles.v;
    }
    if (change.set_x || change.set_v) {
      CHECK(same);
    } else {
      // Untouched, the run keeps its own x_prev, which differs from the rebuilt one by the
      // O(dt^3) error of x - dt v + dt^2/2 a: the test above would notice a restart.
      CHECK_FALSE(same);
      CHECK(displacement(moved) == doctest::Approx(displacement(fresh)).epsilon(1e-4));
    }
  }
  // A new dt also restarts: x_prev belongs to the old step.
  World changed = oscillator("position-verlet", m, ks, kd, 0.2, 0.0);
  for (int s = 0; s < 100; ++s)
    changed.step(dt);
  World fresh = oscillator("position-verlet", m, ks, kd, 0.0, 0.0);
  fresh.particles.x = changed.particles.x;
  fresh.particles.v = changed.particles.v;
  for (int s = 0; s < 50; ++s) {
    changed.step(dt / 3.0);
    fresh.step(dt / 3.0);
  }
  CHECK(changed.particles.x == fresh.particles.x);
  CHECK(changed.particles.v == fresh.particles.v);
}

TEST_CASE("integrators: pinned particles stay exactly where they are under every method") {
  // A pinned particle has 1/m = 0 and v = 0: every method gives it a = 0 at every stage, so
  // its position is updated by exact zeros (position Verlet: 2x - x_prev with x_prev = x,
  // exact in floating point). It must not move by even one bit, however hard its springs,
  // gravity and damping pull on it.
  for (const std::string& method : test::all_integrators()) {
    CAPTURE(method);
    // 4 x 4 particles 10 cm apart, 0.4 kg; ks = 60 N/m (shear 30 N/m), kd = 0.02 N s/m.
    World world;
    const clothlab::ClothGrid grid = add_spring_cloth(world, 4, 4, 0.1, 0.4, 60.0, 30.0, 0.02);
    world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0.0, -9.8, 0.0)));
    world.force_effects.push_back(std::make_unique<clothlab::Damping>(0.5));
    world.integrator = clothlab::make_integrator(method);
    const Index pins[] = {grid.at(0, 0), grid.at(0, 3)};
    for (Index i : pins)
      clothlab::pin(world.particles, i);
    const clothlab::Matrix3X x0 = world.particles.x;
    for (int s = 0; s < 500; ++s)
      world.step(1e-3);
    for (Index i : pins) {
      CAPTURE(i);
      CHECK(world.particles.x.col(i) == x0.col(i));
      CHECK(world.particles.v.col(i) == Vec3::Zero());
    }
    // The rest of the cloth did fall.
    CHECK(world.particles.x(1, grid.at(3, 0)) < x0(1, grid.at(3, 0)) - 0.01);
  }
}

TEST_CASE("integrators: implicit Euler leaves a pinned particle's dv at zero") {
  // A pinned particle's row of A = M - dt D - dt^2 K is the identity and its b is 0, and its
  // column holds nothing else, so conjugate gradients never give it a nonzero dv, even with
  // a stiff spring pulling on it with 1e4 N/m at a large step.
  World world = oscillator("implicit-euler", 0.5, 1e4, 5.0, 0.3, 2.0);
  for (int s = 0; s < 200; ++s) {
    world.step(0.05);
    REQUIRE(world.particles.v.col(0) == Vec3::Zero());
    REQUIRE(world.particles.x.col(0) == Vec3::Zero());
  }
  // The free particle came to rest at the spring's rest length.
  CHECK(std::abs(displacement(world)) < 1e-9);
}

TEST_CASE("integrators: implicit Euler counts the solves that stop at max_iterations") {
  // A stiff 5 x 5 cloth (ks = 1e4 N/m on 0.1 kg particles, dt = 0.01 s: dt w of several) has
  // a linear system that conjugate gradients cannot solve to 1e-6 in one iteration. With
  // max_iterations = 1 every solve stops unconverged and is counted; the step goes on with the
  // dv it has, and the state stays finite.
  World world = free_cloth("implicit-euler", 5, 5);
  clothlab::SpringSet& s = clothlab::find_spring_effect(world, "springs")->springs();
  for (size_t k = 0; k < s.size(); ++k)
    s.set_ks(k, 1e4);
  world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0.0, -9.8, 0.0)));
  clothlab::pin(world.particles, 0);
  clothlab::pin(world.particles, 4);
  world.particles.x(2, 12) += 0.05;  // a dent in the middle: the springs are far from rest
  auto* implicit = dynamic_cast<clothlab::ImplicitEuler*>(world.integrator.get());
  REQUIRE(implicit != nullptr);
  implicit->tolerance = 1e-6;
  implicit->max_iterations = 1;
  const int n = 20;
  for (int step = 0; step < n; ++step)
    world.step(0.01);
  CHECK(implicit->stats().solves == n);
  CHECK(implicit->stats().unconverged == n);
  CHECK(implicit->stats().max_iterations == 1);
  CHECK(implicit->stats().iterations == n);
  CHECK(implicit->stats().worst_error > 1e-6);
  CHECK(world.particles.x.allFinite());
  CHECK(world.particles.v.allFinite());

  // The same run with room to converge: no solve is counted as unconverged.
  World converged = free_cloth("implicit-euler", 5, 5);
  auto* enough = dynamic_cast<clothlab::ImplicitEuler*>(converged.integrator.get());
  enough->tolerance = 1e-6;
  enough->max_iterations = 500;
  clothlab::SpringSet& s2 = clothlab::find_spring_effect(converged, "springs")->springs();
  for (size_t k = 0; k < s2.size(); ++k)
    s2.set_ks(k, 1e4);
  converged.particles.x(2, 12) += 0.05;
  for (int step = 0; step < n; ++step)
    converged.step(0.01);
  CHECK(enough->stats().solves == n);
  CHECK(enough->stats().unconverged == 0);
  CHECK(enough->stats().worst_error <= 1e-6);
  CHECK(enough->stats().max_iterations > 1);
}

namespace {

// A hanging cloth with pinned top corners, for the topology tests: the same world can be built
// twice and given another's state.
World hanging_cloth() {
  // 4 x 5 particles 10 cm apart, 0.5 kg; ks = 500 N/m (shear 200 N/m), kd = 0.5 N s/m.
  World world;
  const clothlab::ClothGrid grid = add_spring_cloth(world, 4, 5, 0.1, 0.5, 500.0, 200.0, 0.5);
  world.force_effects.push_back(std::make_unique<clothlab::UniformGravity>(Vec3(0.0, -9.8, 0.0)));
  clothlab::pin(world.particles, grid.at(0, 0));
  clothlab::pin(world.particles, grid.at(0, 4));
  world.integrator = tight_integrator("implicit-euler");
  return world;
}

// A world like `world` (a hanging_cloth) in its current state, with a new implicit integrator.
World fresh_copy(World& world) {
  World copy = hanging_cloth();
  copy.particles = world.particles;
  clothlab::find_spring_effect(copy, "springs")->springs() =
      clothlab::find_spring_effect(world, "springs")->springs();
  return copy;
}

double largest_difference(const World& a, const World& b) {
  return std::max((a.particles.x - b.particles.x).cwiseAbs().maxCoeff(),
                  (a.particles.v - b.particles.v).cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE("integrators: implicit Euler rebuilds its matrix when springs tear or pins change") {
  // The integrator keeps the sparsity pattern of A between steps. Tearing removes springs (and
  // so blocks of A); pinning a particle removes its row and column. After either, the next step
  // must be the one a freshly built integrator takes from the same state. Both solve to 1e-13
  // from different starting guesses, so they agree to about 1e-12, not bit for bit.
  const double dt = 0.01;
  World world = hanging_cloth();
  for (int s = 0; s < 30; ++s)
    world.step(dt);
  World as_before = fresh_copy(world);  // the state before the change, to show it mattered

  SUBCASE("springs torn") {
    clothlab::SpringSet& springs = clothlab::find_spring_effect(world, "springs")->springs();
    const size_t before = springs.size();
    springs.erase({1, 5, 20});
    REQUIRE(springs.size() == before - 3);
  }
  SUBCASE("a particle pinned") {
    clothlab::pin(world.particles, 7);
  }
  SUBCASE("a pin released") {
    world.particles.inv_m[0] = 1.0 / world.particles.m[0];
  }
  World fresh = fresh_copy(world);
  for (int s = 0; s < 5; ++s) {
    CAPTURE(s);
    world.step(dt);
    fresh.step(dt);
    as_before.step(dt);
    CHECK(largest_difference(world, fresh) < 1e-12);
  }
  CHECK(largest_difference(world, as_before) > 1e-6);
}

TEST_CASE("integrators: [integrator] tolerance and max_iterations reach the implicit solver") {
  const std::string particle = R"(
[[particle]]
position = [0, 0, 0]
mass = 1.0
)";
  clothlab::Scene scene = clothlab::parse_scene(particle + R"(
[integrator]
method = "implicit-euler"
tolerance = 1e-9
max_iterations = 50
dt = 0.01
duration = 1.0
)",
                                                "implicit.toml");
  const auto* implicit = dynamic_cast<const clothlab::ImplicitEuler*>(scene.world.integrator.get());
  REQUIRE(implicit != nullptr);
  CHECK(implicit->name() == "implicit-euler");
  CHECK(implicit->tolerance == 1e-9);
  CHECK(implicit->max_iterations == 50);

  // Without the keys, the defaults of implicit_euler.hpp.
  clothlab::Scene defaults = clothlab::parse_scene(
      particle + "[integrator]\nmethod = \"implicit-euler\"\ndt = 0.01\nduration = 1.0\n",
      "defaults.toml");
  const auto* by_default =
      dynamic_cast<const clothlab::ImplicitEuler*>(defaults.world.integrator.get());
  REQUIRE(by_default != nullptr);
  CHECK(by_default->tolerance == clothlab::ImplicitEuler().tolerance);
  CHECK(by_default->max_iterations == clothlab::ImplicitEuler().max_iterations);

  // Every method of integrator_names() is a scene's to choose.
  for (std::string_view name : clothlab::integrator_names()) {
    CAPTURE(name);
    clothlab::Scene chosen =
        clothlab::parse_scene(particle + "[integrator]\nmethod = \"" + std::string(name) +
                                  "\"\ndt = 0.01\nduration = 1.0\n",
                              "chosen.toml");
    REQUIRE(chosen.world.integrator != nullptr);
    CHECK(chosen.world.integrator->name() == name);
  }

  // A solver setting for a method without a solver is a mistake the reader names.
  CHECK_THROWS_AS(clothlab::parse_scene(particle + "[integrator]\nmethod = \"rk4\"\n"
                                                   "tolerance = 1e-9\ndt = 0.01\nduration = 1.0\n",
                                        "rk4.toml"),
                  clothlab::SceneError);
}
