// Stability limits of the integrators (lesson 08), measured on the engine's own integrators.
//
// The test problem is the damped oscillator of one spring: particle 0 pinned at the origin,
// particle 1 of mass m joined to it by a spring (ks, kd, l0 = 1) and moving along x, so that
//   x'' = -w^2 x - c x',   w = sqrt(ks / m),   c = kd / m = 2 zeta w,   y = dt w.
// On it one step of any method here is a fixed matrix M(y, zeta) on the method's state, and
// errors grow without bound exactly when M has an eigenvalue of modulus above 1. The tests
// write M out from each method's formulas (euler.hpp, runge_kutta.hpp, verlet.hpp,
// implicit_euler.hpp), check that one engine step is M, find the limit y* from M's eigenvalues,
// and then find the largest stable dt of the engine itself by bisection, which must land within
// 2% of y*. Where a closed form exists, y* must also equal it:
//
//   explicit Euler     unstable at every dt when undamped; up to critical damping y < 2 zeta,
//                      i.e. dt < kd / ks; overdamped y < 2 / (zeta + sqrt(zeta^2 - 1)), much
//                      less than kd / ks (at zeta = 2: y < 0.536, where kd / ks gives y < 4)
//   symplectic Euler   y^2 + 4 zeta y < 4, i.e. dt^2 ks + 2 dt kd < 4 m
//   midpoint           unstable at every dt when undamped; damped: from M only
//   RK4                undamped y < 2 sqrt(2); damped: from M only
//   velocity Verlet    undamped y < 2; damped: see verlet_limit() below (not the Euler formula)
//   position Verlet    y^2 + 8 zeta y < 4, i.e. dt^2 ks + 4 dt kd < 4 m (not the Euler formula)
//   implicit Euler     stable at every dt
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/methods.hpp"
#include "test_util.hpp"

using clothlab::Vec3;
using clothlab::World;

namespace {

const double kInfinity = std::numeric_limits<double>::infinity();
const double kZetas[] = {0.0, 0.1, 0.5, 1.0, 2.0};

// The oscillator's mass [kg] and spring [N/m]: w = 10 rad/s. kd follows from zeta.
const double kMass = 0.5, kStiffness = 50.0;
const double kOmega = std::sqrt(kStiffness / kMass);

double damper_for(double zeta) {
  return 2.0 * zeta * std::sqrt(kStiffness * kMass);  // kd = 2 zeta sqrt(ks m) [N s/m]
}

// test::spring_pair with the named integrator, the implicit one solving to 1e-13: particle 1
// (mass m1 [kg]) starts at displacement x0 [m] with velocity v0 [m/s]; with m0 = 0 particle 0
// is the pinned anchor, otherwise a free mass m0, and the stretch obeys the oscillator above
// with the reduced mass m0 m1 / (m0 + m1) in place of m.
World spring_pair(const std::string& method, double m0, double m1, double ks, double kd, double x0,
                  double v0) {
  World world = test::spring_pair(m0, m1, ks, kd, x0, v0);
  world.integrator = clothlab::make_integrator(method);
  REQUIRE(world.integrator != nullptr);
  if (auto* implicit = dynamic_cast<clothlab::ImplicitEuler*>(world.integrator.get()))
    implicit->tolerance = 1e-13;
  return world;
}

World oscillator(const std::string& method, double zeta, double x0, double v0) {
  return spring_pair(method, 0.0, kMass, kStiffness, damper_for(zeta), x0, v0);
}

double energy(const World& world) {
  return world.kinetic_energy() + world.potential_energy();
}

// ---- The step matrices ----------------------------------------------------------------------

// One step of `method`, of dt [s], on x'' = -w^2 x - c x', written out as the engine's
// method does it. The state is (x, v), except for position Verlet: (x_n, x_n-1, v_n), because
// it keeps the previous position and reports v_n = (x_n - x_n-1) / dt + dt/2 a_n-1, where
// a_n-1 itself depended on v_n-1; that third number makes its damped limit differ from the
// others'.
Eigen::MatrixXd step_matrix(const std::string& method, double dt, double w, double c) {
  const auto a = [&](double x, double v) { return -w * w * x - c * v; };
  const double h = dt;
  std::function<Eigen::VectorXd(const Eigen::VectorXd&)> step;
  int n = 2;
  if (method == "explicit-euler") {
    step = [&](const Eigen::VectorXd& s) {
      return Eigen::Vector2d(s[0] + h * s[1], s[1] + h * a(s[0], s[1]));
    };
  } else if (method == "symplectic-euler") {
    step = [&](const Eigen::VectorXd& s) {
      const double v = s[1] + h * a(s[0], s[1]);
      return Eigen::Vector2d(s[0] + h * v, v);
    };
  } else if (method == "midpoint") {
    step = [&](const Eigen::VectorXd& s) {
      const double x2 = s[0] + h / 2 * s[1], v2 = s[1] + h / 2 * a(s[0], s[1]);
      return Eigen::Vector2d(s[0] + h * v2, s[1] + h * a(x2, v2));
    };
  } else if (method == "rk4") {
    step = [&](const Eigen::VectorXd& s) {
      const double x1 = s[0], v1 = s[1], a1 = a(x1, v1);
      const double x2 = s[0] + h / 2 * v1, v2 = s[1] + h / 2 * a1, a2 = a(x2, v2);
      const double x3 = s[0] + h / 2 * v2, v3 = s[1] + h / 2 * a2, a3 = a(x3, v3);
      const double x4 = s[0] + h * v3, v4 = s[1] + h * a3, a4 = a(x4, v4);
      return Eigen::Vector2d(s[0] + h / 6 * (v1 + 2 * v2 + 2 * v3 + v4),
                             s[1] + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4));
    };
  } else if (method == "velocity-verlet") {
    step = [&](const Eigen::VectorXd& s) {
      const double a0 = a(s[0], s[1]);
      const double v_predicted = s[1] + h * a0, v_half = s[1] + h / 2 * a0;
      const double x = s[0] + h * v_half;
      return Eigen::Vector2d(x, v_half + h / 2 * a(x, v_predicted));
    };
  } else if (method == "position-verlet") {
    n = 3;
    step = [&](const Eigen::VectorXd& s) {
      const double a0 = a(s[0], s[2]);
      const double x = 2 * s[0] - s[1] + h * h * a0;
      return Eigen::Vector3d(x, s[0], (x - s[0]) / h + h / 2 * a0);
    };
  } else if (method == "implicit-euler") {
    // (I - h A) s' = s with A = [[0, 1], [-w^2, -c]]: exact here, the spring is linear.
    step = [&](const Eigen::VectorXd& s) {
      Eigen::Matrix2d implicit;
      implicit << 1.0, -h, h * w * w, 1.0 + h * c;
      return Eigen::Vector2d(implicit.inverse() * Eigen::Vector2d(s[0], s[1]));
    };
  }
  REQUIRE(step);
  Eigen::MatrixXd m(n, n);
  for (int k = 0; k < n; ++k)
    m.col(k) = step(Eigen::VectorXd::Unit(n, k));
  return m;
}

double spectral_radius(const Eigen::MatrixXd& m) {
  return Eigen::EigenSolver<Eigen::MatrixXd>(m, false).eigenvalues().cwiseAbs().maxCoeff();
}

bool matrix_stable(const std::string& method, double y, double zeta) {
  // 1e-12 above 1 is rounding: a symplectic matrix has |eigenvalue| = 1 exactly.
  return spectral_radius(step_matrix(method, y, 1.0, 2.0 * zeta)) <= 1.0 + 1e-12;
}

// The largest stable y = dt w from the eigenvalues: the first y, going up from 0, at which the
// spectral radius leaves 1 (found within 1%, then bisected to rounding). Infinity if the
// method is stable up to y = 1e4.
double matrix_limit(const std::string& method, double zeta) {
  double y = 1e-2;
  REQUIRE(matrix_stable(method, y, zeta));
  while (y < 1e4 && matrix_stable(method, 1.01 * y, zeta))
    y *= 1.01;
  if (y >= 1e4) return kInfinity;
  double lo = y, hi = 1.01 * y;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (matrix_stable(method, mid, zeta))
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

// Velocity Verlet's exact limit. Its second acceleration is taken at the predicted velocity
// v + h a, so on the oscillator (units w = 1, h = y, c = 2 zeta) its matrix has
//   det = 1 - c h + c^2 h^2 / 2 - c h^3 / 4,   trace = 2 - c h - h^2 + c^2 h^2 / 2 + c h^3 / 4,
// and a real 2x2 matrix is stable when |det| < 1 and |trace| < 1 + det (Jury). Worked through:
//   1 + det - trace = h^2 (2 - c h) / 2 > 0        ->  zeta y < 1
//   1 + det + trace = 4 - 2 c h - h^2 + c^2 h^2    ->  y^2 (1 - 4 zeta^2) + 4 zeta y < 4
//   1 - det = c h (4 - 2 c h + h^2) / 4 > 0        ->  follows from zeta y < 1
// (and 1 + det > 0 holds at these limits). So y < 2 (sqrt(1 - 3 zeta^2) - zeta) / (1 - 4 zeta^2)
// below zeta = 1/2 and y < 1 / zeta from zeta = 1/2 on: not dt^2 ks + 2 dt kd < 4 m, which is
// the limit of symplectic Euler (and of velocity Verlet with the damper at the old velocity).
double verlet_limit(double zeta) {
  if (zeta < 0.5)
    return 2.0 * (std::sqrt(1.0 - 3.0 * zeta * zeta) - zeta) / (1.0 - 4.0 * zeta * zeta);
  return 1.0 / zeta;
}

// The closed forms of the header comment, where there is one (NaN where there is none).
double closed_form_limit(const std::string& method, double zeta) {
  if (method == "explicit-euler") {
    if (zeta == 0.0) return 0.0;
    // |1 + y lambda| < 1 for lambda = -zeta +- i sqrt(1 - zeta^2): 1 - 2 zeta y + y^2 < 1.
    if (zeta < 1.0) return 2.0 * zeta;
    return 2.0 / (zeta + std::sqrt(zeta * zeta - 1.0));  // the faster real root reaches -2
  }
  if (method == "symplectic-euler") return std::sqrt(4.0 * zeta * zeta + 4.0) - 2.0 * zeta;
  if (method == "midpoint" && zeta == 0.0) return 0.0;
  if (method == "rk4" && zeta == 0.0) return 2.0 * std::sqrt(2.0);
  if (method == "velocity-verlet") return verlet_limit(zeta);
  if (method == "position-verlet") return std::sqrt(16.0 * zeta * zeta + 4.0) - 4.0 * zeta;
  if (method == "implicit-euler") return kInfinity;
  return std::nan("");
}

// ---- The engine's own limit ----------------------------------------------------------------

// Whether `world`'s integrator keeps the energy bounded over `steps` steps of dt [s].
// "Bounded" is not "energy below twice its start": near its limit symplectic Euler's energy
// swings between Q / (1 + y/2) and Q / (1 - y/2) around its conserved Q (39 times at y = 1.9)
// while staying bounded forever. Instead: the largest energy of the second half of the run must
// not exceed twice that of the first half. An eigenvalue of modulus rho multiplies the energy
// by rho^steps from one half to the next, so this catches rho > 1 + 0.7 / steps, while a
// bounded motion (or a decaying one, or a transient that is over by mid-run) passes. A run
// whose energy passes 1e6 times its start is stopped early (from a 1e-4 m start the amplitude
// is then 0.1 m, far from the anchor, where the spring force stays linear).
//
// The steps call the integrator directly rather than World::step, whose guard stops a run once
// its energy has risen far above its start (guard.hpp). That is a verdict on a scene, not on a
// method: a stable step can pass through such a rise before it decays (critically damped near
// the limit, the amplitude grows like n rho^n with rho close to 1).
const int kSteps = 10000;

bool stays_bounded(World& world, double dt, int steps = kSteps) {
  const double e0 = energy(world);
  double first = e0, second = 0.0;
  for (int s = 1; s <= steps; ++s) {
    world.integrator->advance(world, dt);
    const double e = energy(world);
    if (!std::isfinite(e) || e > 1e6 * e0) return false;
    double& window = s <= steps / 2 ? first : second;
    window = std::max(window, e);
  }
  return second <= 2.0 * first;
}

// The oscillator of this file, started at x = 1e-4 m, v = 0.7e-4 w, at y = dt w.
bool engine_stable(const std::string& method, double zeta, double y, int steps = kSteps) {
  World world = oscillator(method, zeta, 1e-4, 0.7 * kOmega * 1e-4);
  return stays_bounded(world, y / kOmega, steps);
}

// The largest y at which engine_stable holds, by doubling from y = 0.05 and then bisecting to
// 0.2%.
double engine_limit(const std::string& method, double zeta) {
  double lo = 0.05;
  REQUIRE(engine_stable(method, zeta, lo));
  while (engine_stable(method, zeta, 2.0 * lo))
    lo *= 2.0;
  double hi = 2.0 * lo;
  while (hi / lo > 1.002) {
    const double mid = std::sqrt(lo * hi);
    if (engine_stable(method, zeta, mid))
      lo = mid;
    else
      hi = mid;
  }
  return std::sqrt(lo * hi);
}

const std::vector<std::string> kExplicit = {
    "explicit-euler", "symplectic-euler", "midpoint", "rk4", "velocity-verlet", "position-verlet"};

bool unstable_at_every_dt(const std::string& method, double zeta) {
  return zeta == 0.0 && (method == "explicit-euler" || method == "midpoint");
}

}  // namespace

TEST_CASE("stability: one engine step is the step matrix the limits come from") {
  // The engine's step on the oscillator, from two independent states, against M times them.
  for (const char* method : {"explicit-euler", "symplectic-euler", "midpoint", "rk4",
                             "velocity-verlet", "implicit-euler"}) {
    for (double zeta : kZetas) {
      for (double y : {0.3, 1.5}) {
        CAPTURE(method);
        CAPTURE(zeta);
        CAPTURE(y);
        const double dt = y / kOmega;
        const Eigen::MatrixXd m = step_matrix(method, dt, kOmega, damper_for(zeta) / kMass);
        for (const Eigen::Vector2d& start :
             {Eigen::Vector2d(0.1, 0.0), Eigen::Vector2d(0.0, 0.5)}) {
          World world = oscillator(method, zeta, start[0], start[1]);
          world.step(dt);
          const Eigen::Vector2d expected = m * start;
          CHECK(world.particles.x(0, 1) - 1.0 ==
                doctest::Approx(expected[0]).epsilon(1e-12).scale(0.1));
          CHECK(world.particles.v(0, 1) == doctest::Approx(expected[1]).epsilon(1e-12).scale(1.0));
        }
      }
    }
  }
  // Position Verlet starts with x_-1 = x - dt v + dt^2/2 a (verlet.hpp) and then applies its
  // 3x3 matrix to (x_n, x_n-1, v_n). At y = 1.2 it is unstable for zeta >= 0.5 (a factor of up
  // to 6 per step), so it starts small enough to stay clear of the anchor for 5 steps.
  for (double zeta : kZetas) {
    CAPTURE(zeta);
    const double dt = 1.2 / kOmega, c = damper_for(zeta) / kMass;
    const Eigen::MatrixXd m = step_matrix("position-verlet", dt, kOmega, c);
    const double x0 = 1e-4, v0 = 4e-4, a0 = -kOmega * kOmega * x0 - c * v0;
    Eigen::Vector3d s(x0, x0 - dt * v0 + 0.5 * dt * dt * a0, v0);
    World world = oscillator("position-verlet", zeta, x0, v0);
    for (int k = 0; k < 5; ++k) {
      CAPTURE(k);
      world.step(dt);
      s = m * s;
      // Positions near 1 m round to 1e-16 m, 1e-12 of this amplitude: compare to 1e-9.
      CHECK(world.particles.x(0, 1) - 1.0 == doctest::Approx(s[0]).epsilon(1e-9).scale(x0));
      CHECK(world.particles.v(0, 1) == doctest::Approx(s[2]).epsilon(1e-9).scale(v0));
    }
  }
}

TEST_CASE("stability: the eigenvalue limits equal their closed forms") {
  for (const std::string& method : kExplicit) {
    for (double zeta : kZetas) {
      CAPTURE(method);
      CAPTURE(zeta);
      if (unstable_at_every_dt(method, zeta)) {
        // Explicit Euler's |R(iy)|^2 = 1 + y^2 and midpoint's 1 + y^4/4 exceed 1 at every y.
        for (double y : {0.01, 0.1, 0.5, 1.0, 3.0})
          CHECK(spectral_radius(step_matrix(method, y, 1.0, 0.0)) > 1.0);
        continue;
      }
      const double closed = closed_form_limit(method, zeta);
      const double limit = matrix_limit(method, zeta);
      CHECK(std::isfinite(limit));
      if (!std::isnan(closed)) CHECK(limit == doctest::Approx(closed).epsilon(1e-9));
    }
  }
  // The formula dt^2 ks + 2 dt kd < 4 m holds for symplectic Euler only. Velocity Verlet
  // (damper at the predicted velocity) and position Verlet (damper at the lagging velocity
  // estimate) have their own limits, further apart as zeta grows: at zeta = 0.5, y < 2 and
  // y < 0.83 against Euler's 1.24.
  CHECK(matrix_limit("velocity-verlet", 0.5) == doctest::Approx(2.0).epsilon(1e-9));
  CHECK(matrix_limit("position-verlet", 0.5) ==
        doctest::Approx(2.0 * std::sqrt(2.0) - 2.0).epsilon(1e-9));
  CHECK(matrix_limit("symplectic-euler", 0.5) ==
        doctest::Approx(std::sqrt(5.0) - 1.0).epsilon(1e-9));
  CHECK(matrix_limit("implicit-euler", 0.0) == kInfinity);
  CHECK(matrix_limit("implicit-euler", 2.0) == kInfinity);
}

TEST_CASE("stability: the engine's largest stable dt is the eigenvalue limit, within 2%") {
  for (const std::string& method : kExplicit) {
    for (double zeta : kZetas) {
      if (unstable_at_every_dt(method, zeta)) continue;
      CAPTURE(method);
      CAPTURE(zeta);
      // The closed form where there is one (the previous test shows it is the eigenvalue
      // limit), otherwise the eigenvalue limit.
      const double formula = closed_form_limit(method, zeta);
      const double expected = std::isnan(formula) ? matrix_limit(method, zeta) : formula;
      const double measured = engine_limit(method, zeta);
      CHECK(measured == doctest::Approx(expected).epsilon(0.02));
    }
  }
}

TEST_CASE("stability: at 0.95 of the limit a method is stable, at 1.05 it is not") {
  for (const std::string& method : kExplicit) {
    for (double zeta : kZetas) {
      if (unstable_at_every_dt(method, zeta)) continue;
      CAPTURE(method);
      CAPTURE(zeta);
      const double limit = matrix_limit(method, zeta);
      CHECK(engine_stable(method, zeta, 0.95 * limit));
      CHECK_FALSE(engine_stable(method, zeta, 1.05 * limit));
    }
  }
}

TEST_CASE("stability: undamped explicit Euler and midpoint gain energy at every dt") {
  // Per step the energy is multiplied by |R(iy)|^2 > 1 (integrators.cpp checks one step):
  // explicit Euler 1 + y^2, midpoint 1 + y^4/4. However small the step, the energy grows
  // every step and geometrically, by exactly that factor to the power of the steps.
  struct Case {
    const char* method;
    double y;
    double factor;  // per step
    int steps;      // enough for the energy to grow e times from one half of the run to the
                    // next, so that engine_stable calls it unstable
  };
  const Case cases[] = {{"explicit-euler", 0.01, 1.0 + 1e-4, 20000},
                        {"explicit-euler", 0.1, 1.01, 200},
                        {"midpoint", 0.1, 1.0 + 2.5e-5, 80000},
                        {"midpoint", 0.5, 1.0 + 0.015625, 200}};
  for (const Case& c : cases) {
    const std::string method = c.method;
    CAPTURE(method);
    CAPTURE(c.y);
    World world = oscillator(c.method, 0.0, 0.1, 0.0);
    const double e0 = energy(world);
    double e = e0;
    bool rising = true;
    for (int s = 0; s < c.steps; ++s) {
      world.step(c.y / kOmega);
      rising = rising && energy(world) > e;
      e = energy(world);
    }
    CHECK(rising);
    CHECK(e > 2.0 * e0);
    CHECK(e / e0 == doctest::Approx(std::pow(c.factor, c.steps)).epsilon(1e-9));
    CHECK_FALSE(engine_stable(c.method, 0.0, c.y, c.steps));
  }
}

TEST_CASE("stability: implicit Euler is stable at 100 times the explicit limit") {
  // (I - h A)^-1 has both eigenvalues inside the unit circle for every h > 0, and in the energy
  // norm it is a contraction (A is dissipative there), so the energy never rises, whatever
  // dt and zeta. Checked up to y = 200, 100 times the symplectic methods' undamped y < 2.
  for (double zeta : kZetas) {
    for (double y : {2.0, 20.0, 200.0}) {
      CAPTURE(zeta);
      CAPTURE(y);
      World world = oscillator("implicit-euler", zeta, 0.1, 0.5);
      const double e0 = energy(world);
      double e = e0;
      bool never_rises = true;
      for (int s = 0; s < 200; ++s) {
        world.step(y / kOmega);
        // Once the energy is down to rounding (positions near 1 m round to 1e-16 m), it is
        // noise: allow 1e-20 of the start.
        never_rises = never_rises && energy(world) <= e * (1.0 + 1e-12) + 1e-20 * e0;
        e = energy(world);
      }
      CHECK(never_rises);
      CHECK(world.particles.x.allFinite());
      CHECK(e < 1e-3 * e0);
      CHECK(spectral_radius(step_matrix("implicit-euler", y, 1.0, 2.0 * zeta)) < 1.0);
    }
  }
  // Undamped, each step multiplies the energy by 1 / (1 + y^2) exactly.
  World world = oscillator("implicit-euler", 0.0, 0.1, 0.5);
  const double e0 = energy(world);
  world.step(20.0 / kOmega);
  CHECK(energy(world) / e0 == doctest::Approx(1.0 / 401.0).epsilon(1e-12));
}

TEST_CASE("stability: heavy damping under symplectic Euler stays finite, its energy falling") {
  // zeta = 2: the limit is y* = sqrt(20) - 4 = 0.472. The energy never rises in a step, from
  // any state, while the step matrix M is a contraction in the energy norm. With w = 1 and the
  // state (w x, v), whose squared length is the energy over m/2, symplectic Euler has
  // det(I - M^T M) = -y^3 (4 zeta^2 y + y - 4 zeta), >= 0 up to y = 4 zeta / (1 + 4 zeta^2)
  // = 8/17 = 0.4706, 99.7% of y*. Below that, every step loses energy; in the sliver between
  // 8/17 and y* the method is still stable but one step from the right state gains a little,
  // before the damping wins.
  const double zeta = 2.0;
  const double limit = std::sqrt(20.0) - 4.0;
  const double monotone = 8.0 / 17.0;
  const double starts[][2] = {{0.1, 0.0}, {0.0, 1.0}, {0.05, -0.5}, {-0.08, 0.3}};
  for (double fraction : {0.1, 0.5, 0.9, 0.99}) {
    for (const auto& start : starts) {
      CAPTURE(fraction);
      CAPTURE(start[0]);
      CAPTURE(start[1]);
      World world = oscillator("symplectic-euler", zeta, start[0], start[1]);
      const double e0 = energy(world);
      double e = e0;
      bool falling = true;
      for (int s = 0; s < 2000; ++s) {
        world.step(fraction * limit / kOmega);
        falling = falling && energy(world) <= e * (1.0 + 1e-12) + 1e-20 * e0;
        e = energy(world);
      }
      CHECK(falling);
      CHECK(world.particles.x.allFinite());
      CHECK(world.particles.v.allFinite());
      CHECK(e < 1e-6 * e0);
    }
  }
  // Between 8/17 and y*: the state that gains most (the top right singular vector of M in
  // the coordinates (w x, v), where the energy is m/2 |.|^2) gains energy in one step.
  const double y = 0.5 * (monotone + limit);
  const Eigen::MatrixXd m = step_matrix("symplectic-euler", y, 1.0, 2.0 * zeta);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(m, Eigen::ComputeFullV);
  REQUIRE(svd.singularValues()[0] > 1.0);
  const Eigen::Vector2d worst = 0.01 * svd.matrixV().col(0);  // (w x, v) with w = 1
  World world = oscillator("symplectic-euler", zeta, worst[0] / kOmega, worst[1]);
  const double e0 = energy(world);
  world.step(y / kOmega);
  CHECK(energy(world) > e0);
  CHECK(energy(world) / e0 == doctest::Approx(std::pow(svd.singularValues()[0], 2)).epsilon(1e-9));
  CHECK(engine_stable("symplectic-euler", zeta, y));
}

TEST_CASE("stability: a free pair's limit uses the reduced mass") {
  // Two free particles m0, m1 on a spring: their separation oscillates with the reduced mass
  // mu = m0 m1 / (m0 + m1), w = sqrt(ks / mu). For symplectic Euler the limit is then
  // dt^2 ks + 2 dt kd < 4 mu. With m0 = 1 kg and m1 = 3 kg, mu = 0.75 kg: the heavier mass
  // alone would promise a dt twice as large.
  const double m0 = 1.0, m1 = 3.0, ks = 30.0, mu = m0 * m1 / (m0 + m1);
  for (double kd : {0.0, 1.5}) {
    CAPTURE(kd);
    // The positive root of dt^2 ks + 2 dt kd - 4 mu = 0 [s].
    const double limit = (-kd + std::sqrt(kd * kd + 4.0 * ks * mu)) / ks;
    const auto stable = [&](double dt) {
      World world = spring_pair("symplectic-euler", m0, m1, ks, kd, 1e-4, 3e-4);
      return stays_bounded(world, dt);
    };
    CHECK(stable(0.95 * limit));
    CHECK_FALSE(stable(1.05 * limit));
    // With m1 in place of mu the limit would be about twice as large, and wrong.
    const double heavy = (-kd + std::sqrt(kd * kd + 4.0 * ks * m1)) / ks;
    CHECK(heavy > 1.9 * limit);
    CHECK_FALSE(stable(0.5 * (limit + heavy)));
  }
}
