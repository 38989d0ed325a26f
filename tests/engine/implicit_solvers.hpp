// implicit_solvers.hpp: what the tests of the methods that solve implicit Euler by iterations
// (lesson 13's local/global solver, lesson 14's vertex block descent) share: implicit Euler's
// exact step, found by Newton's method apart from the engine, the small patch of cloth they are
// compared with it on, and the checks on one spring that any such method must pass.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <utility>

#include "clothlab/forces/gravity.hpp"

#include "test_util.hpp"

namespace test {

constexpr double kPatchG = 9.8;  // gravity on the patch [m/s^2]

// A 3 x 3 patch of particles 1 m apart in the x-y plane joined by its row, column and diagonal
// springs (ks [N/m], kd [N s/m], rest length 1 m or sqrt 2), corner 0 pinned, the others pulled
// out of place and moving: a step of it is far from linear.
inline clothlab::World patch(double ks, double kd) {
  clothlab::World world;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const double wobble = 0.1 * std::sin(3.0 * r + 5.0 * c);
      world.particles.add(clothlab::Vec3(c + 0.4 * wobble, -r - wobble, 0.7 * wobble),
                          clothlab::Vec3(wobble, 2.0 * wobble, -wobble), 0.5 + 0.1 * (r + c));
    }
  }
  clothlab::pin(world.particles, 0);
  world.particles.v.col(0).setZero();
  clothlab::SpringSet springs;
  const auto at = [](int r, int c) { return static_cast<clothlab::Index>(3 * r + c); };
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (c + 1 < 3) springs.add(at(r, c), at(r, c + 1), ks, kd, 1.0);
      if (r + 1 < 3) springs.add(at(r, c), at(r + 1, c), ks, kd, 1.0);
      if (r + 1 < 3 && c + 1 < 3) springs.add(at(r, c), at(r + 1, c + 1), ks, kd, std::sqrt(2.0));
    }
  }
  world.force_effects.push_back(
      std::make_unique<clothlab::SpringDampers>("springs", std::move(springs)));
  world.force_effects.push_back(
      std::make_unique<clothlab::UniformGravity>(clothlab::Vec3(0.0, -kPatchG, 0.0)));
  return world;
}

// The exact implicit Euler step of `world` by Newton's method on g, written out here, apart
// from the engine: the minimiser of
//   g(x) = 1/(2 h^2) (x - y)^T M (x - y) + sum ks/2 (|x_i - x_j| - l0)^2
//          + 1/(2 h) sum kd |(x_i - x_j) - (x_i,n - x_j,n)|^2 - f_ext^T x
// over the free particles (the pinned ones move by h v), with y = x_n + h v_n and f_ext = m g.
// The Hessian is the full one, with the compressed spring's negative term across it; each
// Newton step is halved until g falls, so the iteration cannot run away.
inline clothlab::Matrix3X newton_implicit_euler(const clothlab::World& world, double h) {
  const clothlab::Particles& p = world.particles;
  const clothlab::SpringSet& s = test::springs_of(world);
  const clothlab::Index n = p.size();
  const clothlab::Matrix3X x_n = p.x;
  const clothlab::Matrix3X y = x_n + h * p.v;
  const auto g = [&](const clothlab::Matrix3X& x) {
    double value = 0.0;
    for (clothlab::Index i = 0; i < n; ++i) {
      value += p.m[i] / (2.0 * h * h) * (x.col(i) - y.col(i)).squaredNorm();
      value -= p.m[i] * clothlab::Vec3(0.0, -kPatchG, 0.0).dot(x.col(i));
    }
    for (size_t k = 0; k < s.size(); ++k) {
      const clothlab::Vec3 e = x.col(s.i(k)) - x.col(s.j(k));
      const clothlab::Vec3 e_n = x_n.col(s.i(k)) - x_n.col(s.j(k));
      value += 0.5 * s.ks(k) * std::pow(e.norm() - s.l0(k), 2);
      value += s.kd(k) / (2.0 * h) * (e - e_n).squaredNorm();
    }
    return value;
  };
  clothlab::Matrix3X x = y;
  for (clothlab::Index i = 0; i < n; ++i) {
    if (p.inv_m[i] != 0.0) x.col(i) += h * h * clothlab::Vec3(0.0, -kPatchG, 0.0);
  }
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (int it = 0; it < 100; ++it) {
    Eigen::VectorXd grad = Eigen::VectorXd::Zero(3 * n);
    Eigen::MatrixXd hess = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (clothlab::Index i = 0; i < n; ++i) {
      grad.segment<3>(3 * i) =
          p.m[i] / (h * h) * (x.col(i) - y.col(i)) - p.m[i] * clothlab::Vec3(0, -kPatchG, 0);
      hess.block<3, 3>(3 * i, 3 * i) += p.m[i] / (h * h) * I;
    }
    for (size_t k = 0; k < s.size(); ++k) {
      const clothlab::Index i = s.i(k), j = s.j(k);
      const clothlab::Vec3 e = x.col(i) - x.col(j);
      const clothlab::Vec3 e_n = x_n.col(i) - x_n.col(j);
      const double l = e.norm();
      const clothlab::Vec3 u = e / l;
      const clothlab::Vec3 gk = s.ks(k) * (l - s.l0(k)) * u + s.kd(k) / h * (e - e_n);
      const Eigen::Matrix3d hk =
          s.ks(k) * (u * u.transpose() + (1.0 - s.l0(k) / l) * (I - u * u.transpose())) +
          s.kd(k) / h * I;
      grad.segment<3>(3 * i) += gk;
      grad.segment<3>(3 * j) -= gk;
      hess.block<3, 3>(3 * i, 3 * i) += hk;
      hess.block<3, 3>(3 * j, 3 * j) += hk;
      hess.block<3, 3>(3 * i, 3 * j) -= hk;
      hess.block<3, 3>(3 * j, 3 * i) -= hk;
    }
    // Pinned particles are not unknowns: their rows and columns are the identity.
    for (clothlab::Index i = 0; i < n; ++i) {
      if (p.inv_m[i] != 0.0) continue;
      grad.segment<3>(3 * i).setZero();
      hess.middleRows(3 * i, 3).setZero();
      hess.middleCols(3 * i, 3).setZero();
      hess.block<3, 3>(3 * i, 3 * i) = I;
    }
    if (grad.norm() < 1e-13) break;
    const Eigen::VectorXd dx = hess.ldlt().solve(-grad);
    double step = 1.0;
    const double before = g(x);
    clothlab::Matrix3X trial = x + step * Eigen::Map<const clothlab::Matrix3X>(dx.data(), 3, n);
    while (g(trial) > before && step > 1e-8) {
      step *= 0.5;
      trial = x + step * Eigen::Map<const clothlab::Matrix3X>(dx.data(), 3, n);
    }
    x = trial;
  }
  return x;
}

// A mass of 0.1 kg on a spring (ks = 100 N/m, kd [N s/m], l0 = 1 m) below a pinned anchor at the
// origin, under gravity, stepped at 1/60 s by a method that solves implicit Euler (`use(world)`
// gives the world its integrator). At the static stretch s = m g / ks = 9.8 mm the forces
// balance and y = x_n, so x = x_n solves the step: started there with kd = 0, it stays, to
// rounding, for 2 s. Started at its rest length with kd = 0.5 N s/m (damping ratio 0.079),
// the damper and implicit Euler's own damping at h = 1/60 s (w h = 0.53) take the 9.8 mm swing
// below 1e-8 m within 10 s; a stiffness off by 1 % would be 98 um away.
template <class Use>
void check_hanging_mass(const Use& use) {
  const double m = 0.1, ks = 100.0, expected = m * kPatchG / ks;
  const auto hanging = [&](double kd, double stretch) {
    clothlab::World world = anchored_spring(m, ks, kd, 0.0, 0.0);
    world.particles.x.col(1) = clothlab::Vec3(0.0, -1.0 - stretch, 0.0);
    world.force_effects.push_back(
        std::make_unique<clothlab::UniformGravity>(clothlab::Vec3(0, -kPatchG, 0)));
    use(world);
    return world;
  };
  clothlab::World still = hanging(0.0, expected);
  for (int s = 0; s < 120; ++s)
    still.step(1.0 / 60.0);
  CHECK(std::abs(-1.0 - still.particles.x(1, 1) - expected) <= 1e-12);
  CHECK(still.particles.v.col(1).norm() <= 1e-9);
  clothlab::World swinging = hanging(0.5, 0.0);
  for (int s = 0; s < 600; ++s)
    swinging.step(1.0 / 60.0);
  CHECK(-1.0 - swinging.particles.x(1, 1) == doctest::Approx(expected).epsilon(1e-5));
}

// An undamped spring (ks = 100 N/m, 1 kg, pulled 0.1 m along itself, no gravity) at dt = 10 ms
// for 10 s, under a method that solves implicit Euler (`use(world)` gives it its integrator).
// Solved, a step is implicit Euler, which on a spring along its axis scales the energy by
// 1 / (1 + (w h)^2) < 1 (lesson 08): 0.5 J / 1.01^1000 = 2.386e-5 J after 1000 steps
// (w h = 0.1). Checked every step, against rounding (1e-12 J): the energy never grows.
template <class Use>
void check_spring_energy_decay(const Use& use) {
  clothlab::World world = anchored_spring(1.0, 100.0, 0.0, 0.1, 0.0);
  use(world);
  const double e = step_without_energy_growth(world, 0.01, 1000);
  MESSAGE("energy 0.5 J -> " << e << " J");
  CHECK(e == doctest::Approx(0.5 * std::pow(1.01, -1000.0)).epsilon(0.01));
}

}  // namespace test
