// Every force effect against its own potential energy and its own Jacobians, by central
// differences: what a physicist checks first. For an effect with a potential energy U, the force
// is minus its gradient, f = -dU/dx; and the Jacobians the implicit integrator is handed are the
// derivatives of the force, df/dx and df/dv. An effect gets these checks by being listed in
// kForceTables below (one scene table that makes it); a scene table that is neither listed there
// nor in kNoForceTables fails the first test, so a new effect cannot be forgotten.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "clothlab/core/effect.hpp"
#include "scene/scene.hpp"
#include "scene/scene_tables.hpp"

using clothlab::Index;
using clothlab::Mat3;
using clothlab::Matrix3X;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

struct ForceTable {
  std::string_view table;  // the scene table, as written in a scene
  bool conservative;       // its force at rest is -grad U (else it stores no energy: U = 0)
};

// The tables that make force effects, each with the constants its checks run at.
const ForceTable kForceTables[] = {
    {"[springs]\nks = 40\nkd = 0.3\nshear_ks = 15\n", true},
    {"[[spring]]\ni = 0\nj = 8\nks = 25\nkd = 0.2\nl0 = 0.3\n", true},
    {"[bending]\nks = 3\nkd = 0.05\n", true},
    {"[gravity]\ng = [0.5, -9.8, 1.5]\n", true},
    {"[gravitation]\nG = 0.7\n", true},
    // The surface between the particles' heights: some are under, some not (none within h).
    {"[buoyancy]\nvolume = 2e-4\nsurface = -0.61\n", true},
    {"[damping]\nrate = 0.4\n", false},
    {"[aerodynamics]\nrho = 1.2\ncd = 1.1\nwind = [3, 0.5, -2]\n", false},
    {"[drag]\nrho = 1.2\ncd = 0.5\narea = 0.01\nwind = [1, 0, 2]\n", false},
};

// The tables that make no force effect: bodies, contacts and what else a scene sets.
const std::set<std::string_view> kNoForceTables = {
    "guard",        "particle",       "rope",       "cloth",  "solid",
    "strain_limit", "self_collision", "ground",     "sphere", "plane",
    "plasticity",   "tearing",        "integrator", "output", "engine"};

// A 3 x 3 cloth of 0.9 kg (0.1 kg a particle) in the vertical plane, top edge at y = 0, and the
// table under test. No pins: every particle's force counts.
clothlab::Scene scene_with(std::string_view table) {
  return clothlab::parse_scene(std::string("[cloth]\nrows = 3\ncols = 3\nspacing = 0.5\n"
                                           "origin = [0, 0, 0]\nplane = \"vertical\"\nmass = 0.9\n"
                                           "pins = \"none\"\n") +
                                   std::string(table) +
                                   "[integrator]\nmethod = \"implicit-euler\"\ndt = 0.001\n"
                                   "duration = 1\n",
                               "gradients.toml");
}

// A random state near the scene's start: the sheet stretched by 20 % (every spring longer than
// at rest) and moved by up to 2 cm, with velocities up to 1 m/s.
void random_state(const Matrix3X& x0, std::mt19937& random, Matrix3X& x, Matrix3X& v) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  x = 1.2 * x0;
  v.resize(3, x0.cols());
  for (Index i = 0; i < x.cols(); ++i) {
    for (int a = 0; a < 3; ++a) {
      x(a, i) += 0.02 * unit(random);
      v(a, i) = unit(random);
    }
  }
}

VectorXd force(const clothlab::ForceEffect& effect, const clothlab::Particles& p, const Matrix3X& x,
               const Matrix3X& v) {
  Matrix3X f = Matrix3X::Zero(3, x.cols());
  effect.add_forces(p, x, v, f);
  return Eigen::Map<const VectorXd>(f.data(), f.size());
}

// The Jacobians an effect hands the implicit integrator, as dense 3n x 3n matrices.
class DenseJacobians final : public clothlab::ForceJacobians {
 public:
  explicit DenseJacobians(Index n) : dfdx(MatrixXd::Zero(3 * n, 3 * n)), dfdv(dfdx) {}
  void add_pair(Index i, Index j, const Mat3& dx, const Mat3& dv) override {
    add(dfdx, i, j, dx);
    add(dfdv, i, j, dv);
  }
  void add_self(Index i, const Mat3& dx, const Mat3& dv) override {
    dfdx.block<3, 3>(3 * i, 3 * i) += dx;
    dfdv.block<3, 3>(3 * i, 3 * i) += dv;
  }
  MatrixXd dfdx, dfdv;

 private:
  static void add(MatrixXd& m, Index i, Index j, const Mat3& block) {
    m.block<3, 3>(3 * i, 3 * j) += block;
    m.block<3, 3>(3 * j, 3 * i) += block;
    m.block<3, 3>(3 * i, 3 * i) -= block;
    m.block<3, 3>(3 * j, 3 * j) -= block;
  }
};

constexpr double kStep = 1e-6;  // [m] or [m/s]: the central differences' step

// d(force)/d(x or v) by central differences, column by column.
MatrixXd force_differences(const clothlab::ForceEffect& effect, const clothlab::Particles& p,
                           const Matrix3X& x, const Matrix3X& v, bool by_velocity) {
  const Index n3 = x.size();
  MatrixXd jacobian(n3, n3);
  for (Index c = 0; c < n3; ++c) {
    Matrix3X plus_x = x, minus_x = x, plus_v = v, minus_v = v;
    (by_velocity ? plus_v : plus_x).data()[c] += kStep;
    (by_velocity ? minus_v : minus_x).data()[c] -= kStep;
    jacobian.col(c) =
        (force(effect, p, plus_x, plus_v) - force(effect, p, minus_x, minus_v)) / (2 * kStep);
  }
  return jacobian;
}

// Where an effect with a potential energy is smooth: buoyancy's force steps at the surface, so a
// difference across it is not a derivative.
bool smooth_at(const clothlab::ForceEffect& effect, const Matrix3X& x) {
  if (effect.name() != "buoyancy") return true;
  for (Index i = 0; i < x.cols(); ++i) {
    if (std::abs(x(1, i) + 0.61) < 1e3 * kStep) return false;
  }
  return true;
}

// Calls check(effect, world, random) on every effect of every listed table's scene, with the
// random numbers of `seed`.
template <class Check>
void for_each_listed_effect(unsigned seed, const Check& check) {
  std::mt19937 random(seed);
  for (const ForceTable& t : kForceTables) {
    CAPTURE(t.table);
    clothlab::Scene scene = scene_with(t.table);
    REQUIRE(!scene.world.force_effects.empty());
    for (const auto& effect : scene.world.force_effects) {
      CAPTURE(effect->name());
      check(*effect, scene.world, t, random);
    }
  }
}

}  // namespace

TEST_CASE("gradients: every scene table that makes a force effect is listed here") {
  std::set<std::string_view> listed = kNoForceTables;
  for (const ForceTable& t : kForceTables) {
    const auto start = t.table.find_first_not_of("[");
    listed.insert(t.table.substr(start, t.table.find(']') - start));
  }
  for (const clothlab::SceneTableKind& kind : clothlab::scene_table_kinds()) {
    INFO("table [", kind.name,
         "] is in neither list of tests/engine/energy_gradients.cpp: list it "
         "in kForceTables if it makes a force effect (it then gets the checks), else in "
         "kNoForceTables");
    CHECK(listed.count(kind.name) == 1);
  }
}

TEST_CASE("gradients: each effect's force is minus the gradient of its potential energy") {
  for_each_listed_effect(2026, [](const clothlab::ForceEffect& effect, const clothlab::World& world,
                                  const ForceTable& t, std::mt19937& random) {
    int checked = 0;
    for (int state = 0; state < 6; ++state) {
      Matrix3X x, v;
      random_state(world.particles.x, random, x, v);
      if (!smooth_at(effect, x)) continue;
      const Matrix3X rest = Matrix3X::Zero(3, x.cols());
      const VectorXd f = force(effect, world.particles, x, rest);
      VectorXd minus_gradient(x.size());
      for (Index c = 0; c < x.size(); ++c) {
        Matrix3X plus = x, minus = x;
        plus.data()[c] += kStep;
        minus.data()[c] -= kStep;
        minus_gradient[c] = -(effect.potential_energy(world.particles, plus) -
                              effect.potential_energy(world.particles, minus)) /
                            (2 * kStep);
      }
      const double scale = std::max(f.lpNorm<Eigen::Infinity>(), 1e-3);
      if (t.conservative) {
        INFO("force: ", f.transpose(), "\n-dU/dx: ", minus_gradient.transpose());
        CHECK((f - minus_gradient).lpNorm<Eigen::Infinity>() <= 1e-6 * scale);
        CHECK(f.lpNorm<Eigen::Infinity>() > 0.0);  // a force to compare, not 0 = 0
      } else {
        CHECK(minus_gradient.lpNorm<Eigen::Infinity>() == 0.0);  // it stores no energy
      }
      ++checked;
    }
    CHECK(checked >= 3);
  });
}

TEST_CASE("gradients: the Jacobians the implicit integrator uses are the force's derivatives") {
  // Exactly so where the springs are stretched and at rest, as here. Two approximations are made
  // on purpose elsewhere, and checked as such below: a compressed spring's Jacobian leaves out
  // its negative sideways stiffness (so the implicit system stays positive definite and the
  // method unconditionally stable), and a damper's force is differentiated in v only.
  for_each_listed_effect(1302, [](const clothlab::ForceEffect& effect, const clothlab::World& world,
                                  const ForceTable& /*t*/, std::mt19937& random) {
    Matrix3X x, v;
    random_state(world.particles.x, random, x, v);
    DenseJacobians jacobians(x.cols());
    const Matrix3X rest = Matrix3X::Zero(3, x.cols());
    if (!effect.add_jacobians(world.particles, x, rest, jacobians)) return;  // treated explicitly
    const MatrixXd by_x = force_differences(effect, world.particles, x, rest, false);
    const MatrixXd by_v = force_differences(effect, world.particles, x, v, true);
    const double scale = std::max(by_x.lpNorm<Eigen::Infinity>(), 1e-3);
    INFO("df/dx given:\n", jacobians.dfdx, "\nby differences:\n", by_x);
    CHECK((jacobians.dfdx - by_x).lpNorm<Eigen::Infinity>() <= 1e-6 * scale);
    const double scale_v = std::max(by_v.lpNorm<Eigen::Infinity>(), 1e-3);
    INFO("df/dv given:\n", jacobians.dfdv, "\nby differences:\n", by_v);
    CHECK((jacobians.dfdv - by_v).lpNorm<Eigen::Infinity>() <= 1e-6 * scale_v);
    CHECK(by_x.lpNorm<Eigen::Infinity>() + by_v.lpNorm<Eigen::Infinity>() > 0.0);
  });
}

TEST_CASE("gradients: a compressed spring's Jacobian is the definite part of the derivative") {
  // The sheet squeezed to 70 %: every spring shorter than at rest. The exact df/dx has a positive
  // (unstable) sideways part; the one given keeps only what makes -df/dx positive semidefinite.
  clothlab::Scene scene = scene_with(kForceTables[0].table);
  const clothlab::World& world = scene.world;
  const auto& springs = *world.force_effects.front();
  const Matrix3X x = 0.7 * world.particles.x;
  const Matrix3X rest = Matrix3X::Zero(3, x.cols());
  DenseJacobians jacobians(x.cols());
  REQUIRE(springs.add_jacobians(world.particles, x, rest, jacobians));
  const Eigen::SelfAdjointEigenSolver<MatrixXd> given(-jacobians.dfdx);
  CHECK(given.eigenvalues().minCoeff() >= -1e-9);
  const MatrixXd exact = force_differences(springs, world.particles, x, rest, false);
  const Eigen::SelfAdjointEigenSolver<MatrixXd> of_force(-0.5 * (exact + exact.transpose()));
  CHECK(of_force.eigenvalues().minCoeff() < -1.0);  // what was left out, and why
}
