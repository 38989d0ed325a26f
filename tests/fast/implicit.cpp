// Implicit Euler in the engine room (engine/fast/implicit.cpp) against the lecture's
// ImplicitEuler: the same solution to within a bound derived below, every step taken by the
// engine room (no silent fallback), the same bits on 1 to 4 threads, and a visible decline for
// a scene whose Jacobians it does not know.
//
// The bound. Both paths solve A dv = b, A = M - h D - h^2 K (a pinned particle's rows: the
// identity), b = h (f0 + h K v), and stop once the residual |b - A dv| <= tol |b|. -K and -D are
// positive semidefinite (spring_damper.hpp), so every eigenvalue of A is at least
// a_min = min(smallest mass, 1), and |dv - dv*| <= |A^-1| |b - A dv| <= tol |b| / a_min for
// either path's dv against the exact dv*. So the two steps' velocities differ by at most
// 2 tol |b| / a_min, and their positions (x' = x + h v') by h times that. The stopping test runs
// on the residual the iteration updates, which drifts from the true one by rounding, far below
// tol |b| at the tolerances here; the check allows 10 % for it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>
#include <string>

#include "clothlab/core/step_timer.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "fast/engine.hpp"
#include "scene/scene.hpp"

using clothlab::Index;
using clothlab::Mat3;
using clothlab::Matrix3X;
using clothlab::Vec3;

namespace {

// A stiff cloth hanging from its top corners, with every effect the engine room's step knows
// (springs, bending, damping) and some that enter through f0 alone (gravity, wind, drag), the
// ground after each step.
std::string stiff_cloth(double tolerance, Index rows = 24, Index cols = 20) {
  std::ostringstream tol;
  tol << tolerance;
  return "[cloth]\nrows = " + std::to_string(rows) + "\ncols = " + std::to_string(cols) +
         R"(
spacing = 0.02
mass = 0.5
pins = "top-corners"
[springs]
ks = 3000
kd = 0.05
shear_ks = 800
shear_kd = 0.02
[bending]
ks = 20
kd = 0.002
[damping]
rate = 0.2
[gravity]
[aerodynamics]
wind = [3, 0, 2]
[drag]
area = 0.0004
[ground]
y = -0.3
[integrator]
method = "implicit-euler"
dt = 0.004
duration = 1.0
tolerance = )" +
         tol.str() + "\nmax_iterations = 2000\n";
}

const clothlab::ImplicitEuler& implicit_of(const clothlab::World& world) {
  return dynamic_cast<const clothlab::ImplicitEuler&>(*world.integrator);
}

clothlab::fast::FastEngine& engine_of(const clothlab::World& world) {
  auto* engine = dynamic_cast<clothlab::fast::FastEngine*>(world.backend.get());
  REQUIRE(engine != nullptr);
  return *engine;
}

// |b| for the step from the world's state: b = h (f0 + h K v), 0 on pinned particles, K v
// summed spring by spring from the lecture's Jacobian (damping adds nothing to K).
double rhs_norm(const clothlab::World& world, double h) {
  const clothlab::Particles& p = world.particles;
  Matrix3X f(3, p.size());
  world.compute_forces(p.x, p.v, f);
  Matrix3X kv = Matrix3X::Zero(3, p.size());
  for (const auto& effect : world.force_effects) {
    const auto* springs = dynamic_cast<const clothlab::SpringDampers*>(effect.get());
    if (!springs) continue;
    const clothlab::SpringSet& s = springs->springs();
    for (size_t k = 0; k < s.size(); ++k) {
      const Mat3 dfdx = clothlab::spring_damper_jacobian(p.x.col(s.i(k)), p.x.col(s.j(k)), s.ks(k),
                                                         s.kd(k), s.l0(k))
                            .dfdx;
      const Vec3 share = dfdx * (p.v.col(s.j(k)) - p.v.col(s.i(k)));
      kv.col(s.i(k)) += share;
      kv.col(s.j(k)) -= share;
    }
  }
  Matrix3X b = h * (f + h * kv);
  for (Index i = 0; i < p.size(); ++i) {
    if (p.inv_m[i] == 0.0) b.col(i).setZero();
  }
  return b.norm();
}

// The smallest eigenvalue A can have: the smallest free mass, or 1 (a pinned row).
double a_min(const clothlab::World& world) {
  double least = 1.0;
  for (Index i = 0; i < world.particles.size(); ++i) {
    if (world.particles.inv_m[i] != 0.0) least = std::min(least, world.particles.m[i]);
  }
  return least;
}

// Steps a readable world `before` steps, then takes one step from that state on the lecture's
// code and one in the engine room (on `threads` threads, with `preconditioner`), and checks
// the two against the bound.
void one_step_within_bound(const std::string& text, int before, int threads,
                           clothlab::fast::FastEngine::Preconditioner preconditioner,
                           const std::function<void(clothlab::World&)>& edit = {}) {
  clothlab::Scene readable = clothlab::parse_scene(text, "readable.toml");
  clothlab::Scene fast = clothlab::parse_scene(text, "fast.toml");
  readable.world.backend.reset();
  fast.world.backend.reset();  // the same readable steps up to `before`: the same bits
  for (int s = 0; s < before; ++s) {
    readable.world.step(readable.dt);
    fast.world.step(fast.dt);
  }
  if (edit) {
    edit(readable.world);
    edit(fast.world);
  }
  REQUIRE((readable.world.particles.x.array() == fast.world.particles.x.array()).all());
  fast.world.backend = clothlab::fast::make_fast_engine();
  engine_of(fast.world).implicit_preconditioner = preconditioner;
  fast.world.threads = threads;
  const double tol = implicit_of(readable.world).tolerance;
  const double bound =
      1.1 * 2.0 * tol * rhs_norm(readable.world, readable.dt) / a_min(readable.world);
  const Matrix3X v0 = readable.world.particles.v;
  readable.world.step(readable.dt);
  fast.world.step(fast.dt);
  CHECK(implicit_of(readable.world).backend_steps == 0);
  CHECK(implicit_of(fast.world).backend_steps == 1);  // the engine room took it
  const double dv_size = (readable.world.particles.v - v0).norm();
  const double dv_apart = (readable.world.particles.v - fast.world.particles.v).norm();
  const double dx_apart = (readable.world.particles.x - fast.world.particles.x).norm();
  CAPTURE(before);
  CAPTURE(tol);
  CAPTURE(bound);
  CAPTURE(dv_size);
  CAPTURE(dv_apart);
  CHECK(dv_size > 1000 * bound);  // the step changed v by far more than the bound
  CHECK(dv_apart <= bound);
  CHECK(dx_apart <= readable.dt * bound * 1.0000001);
  // The engine room leaves pinned particles where they are, exactly.
  for (Index i = 0; i < fast.world.particles.size(); ++i) {
    if (fast.world.particles.inv_m[i] == 0.0) CHECK(fast.world.particles.v.col(i).isZero(0.0));
  }
}

// A pull of every particle towards the origin, with its Jacobian: an effect the engine room
// does not know.
class Tether final : public clothlab::ForceEffect {
 public:
  std::string_view name() const override { return "tether"; }
  void add_forces(const clothlab::Particles& /*p*/, const Matrix3X& x, const Matrix3X& /*v*/,
                  Matrix3X& f) const override {
    f -= 2.0 * x;
  }
  bool add_jacobians(const clothlab::Particles& p, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                     clothlab::ForceJacobians& jacobians) const override {
    for (Index i = 0; i < p.size(); ++i)
      jacobians.add_self(i, -2.0 * Mat3::Identity(), Mat3::Zero());
    return true;
  }
};

}  // namespace

TEST_CASE("implicit Euler in the engine room: the readable step's solution within the bound") {
  using P = clothlab::fast::FastEngine::Preconditioner;
  for (double tol : {1e-6, 1e-10}) {
    for (int before : {0, 40}) {
      for (P preconditioner : {P::block_jacobi, P::diagonal}) {
        CAPTURE(static_cast<int>(preconditioner));
        one_step_within_bound(stiff_cloth(tol), before, 1, preconditioner);
      }
    }
  }
  // Springs removed between steps (as tearing does): the engine room plans again.
  one_step_within_bound(stiff_cloth(1e-8), 30, 2, P::block_jacobi, [](clothlab::World& world) {
    clothlab::SpringSet& s = clothlab::find_spring_effect(world, "springs")->springs();
    s.erase({0, 5, 17, 40, 41, 42, 300});
  });
}

TEST_CASE("implicit Euler in the engine room: every step taken, the same bits on 1-4 threads") {
  const std::string text = stiff_cloth(1e-6, 40, 36);
  const int steps = 60;
  Matrix3X x1, v1;
  long iterations1 = 0;
  for (int threads = 1; threads <= 4; ++threads) {
    CAPTURE(threads);
    clothlab::Scene scene = clothlab::parse_scene(text, "threads.toml");
    scene.world.threads = threads;
    // On 3 threads the run is timed as --stats times it: the stopwatch's wrapper around the
    // backend must pass the step on, not decline it.
    clothlab::StepTimer timer;
    if (threads == 3) timer.attach(scene.world);
    for (int s = 0; s < steps; ++s)
      scene.world.step(scene.dt);
    const clothlab::ImplicitEuler& implicit = implicit_of(scene.world);
    CHECK(implicit.backend_steps == steps);                    // no silent fallback
    if (threads == 3) CHECK(timer.times.backend_steps > 0.0);  // and timed as the backend's
    CHECK(implicit.stats().solves == steps);
    CHECK(implicit.stats().unconverged == 0);
    CHECK(implicit.stats().iterations > steps);  // it iterated
    if (threads == 1) {
      x1 = scene.world.particles.x;
      v1 = scene.world.particles.v;
      iterations1 = implicit.stats().iterations;
      CHECK((x1 - clothlab::parse_scene(text, "t").world.particles.x).cwiseAbs().maxCoeff() >
            1e-3);  // the cloth moved
      continue;
    }
    CHECK(implicit.stats().iterations == iterations1);
    CHECK((scene.world.particles.x.array() == x1.array()).all());
    CHECK((scene.world.particles.v.array() == v1.array()).all());
  }
}

TEST_CASE("implicit Euler in the engine room: declines a scene with Jacobians it does not know") {
  const std::string text = stiff_cloth(1e-6);
  clothlab::Scene fast = clothlab::parse_scene(text, "fast.toml");
  clothlab::Scene readable = clothlab::parse_scene(text, "readable.toml");
  readable.world.backend.reset();
  for (clothlab::Scene* scene : {&fast, &readable})
    scene->world.force_effects.push_back(std::make_unique<Tether>());
  for (int s = 0; s < 10; ++s) {
    fast.world.step(fast.dt);
    readable.world.step(readable.dt);
  }
  // The lecture's code took every step, with the tether's Jacobian: the readable bits.
  CHECK(implicit_of(fast.world).backend_steps == 0);
  CHECK(implicit_of(fast.world).stats().solves == 10);
  CHECK((fast.world.particles.x.array() == readable.world.particles.x.array()).all());
}
