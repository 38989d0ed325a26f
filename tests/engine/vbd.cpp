// Vertex block descent (lesson 14): method = "vbd", implicit Euler by one Newton step per vertex,
// swept colour by colour. First the vertex's step on cases worked by hand, then the integrator
// against implicit Euler's exact step, on a stiff cloth, with pins, tearing and colliders, and
// the colouring. Each test states the property it checks and why the number it compares with
// is right; each fails when the feature breaks (a wrong sign, the clamp left out, a singular
// block inverted, a torn spring still pulling, pins that move).
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "clothlab/core/guard.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/integrators/methods.hpp"
#include "clothlab/integrators/vbd.hpp"
#include "clothlab/integrators/vbd_vertex.hpp"
#include "implicit_solvers.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::Mat3;
using clothlab::Matrix3X;
using clothlab::Vbd;
using clothlab::Vec3;
using clothlab::VertexBlock;
using clothlab::VertexSpring;
using clothlab::World;

namespace {

constexpr double kG = 9.8;  // [m/s^2]
constexpr double kInfinity = std::numeric_limits<double>::infinity();

Vbd& use_vbd(World& world, int iterations) {
  auto integrator = std::make_unique<Vbd>();
  integrator->iterations = iterations;
  Vbd& ref = *integrator;
  world.integrator = std::move(integrator);
  return ref;
}

// test::patch(200 N/m, kd) stepped once by h [s] with 1, 2, 3, 5, 10 and 100 iterations: the
// `error` of the positions each step ends with must fall with the iterations up to 10, and be at
// most `rounding` at 100 (where it has stopped falling).
template <class Error>
void check_convergence(double kd, double h, double rounding, const char* what, const Error& error) {
  double last = kInfinity;
  for (int iterations : {1, 2, 3, 5, 10, 100}) {
    CAPTURE(iterations);
    World world = test::patch(200.0, kd);
    use_vbd(world, iterations);
    world.step(h);
    const double e = error(world.particles.x);
    MESSAGE(iterations << " iterations: " << std::string(what) << " " << e);
    if (iterations <= 10) CHECK(e < last);
    last = e;
  }
  CHECK(last <= rounding);
}

// A spring to an other end at x_j that has not moved in this step.
VertexSpring spring_to(const Vec3& x_j, double ks, double l0, double kd = 0.0) {
  return {x_j, x_j, ks, kd, l0};
}

// The vertex's block and step for a vertex that has not moved in this step (x_i = x_i,n).
VertexBlock block_at(const Vec3& x_i, const Vec3& y_i, double w_i, double h,
                     const std::vector<VertexSpring>& springs) {
  return clothlab::vbd_vertex_block(x_i, x_i, y_i, w_i, h, springs);
}
Vec3 step_at(const Vec3& x_i, const Vec3& y_i, double w_i, double h,
             const std::vector<VertexSpring>& springs) {
  return clothlab::vbd_vertex_step(x_i, x_i, y_i, w_i, h, springs);
}

double max_abs(const Mat3& a) {
  return a.cwiseAbs().maxCoeff();
}

// Every spring of `springs` joins two vertices of different colours in `graph`.
bool colouring_is_valid(const clothlab::VbdGraph& graph, const clothlab::SpringSet& springs) {
  for (size_t k = 0; k < springs.size(); ++k) {
    if (graph.colour[static_cast<size_t>(springs.i(k))] ==
        graph.colour[static_cast<size_t>(springs.j(k))])
      return false;
  }
  return true;
}

// The scene of `bodies` ([cloth], [solid], their springs) stepped once by VBD, and the graph
// the integrator built from every spring family it found; the test case fails (CHECK) if a
// spring of any family joins two vertices of one colour.
struct Coloured {
  clothlab::Scene scene;
  const clothlab::VbdGraph& graph;
};
Coloured coloured(const std::string& bodies) {
  clothlab::Scene scene = clothlab::parse_scene(
      bodies + "[integrator]\nmethod = \"vbd\"\ndt = 0.01\nduration = 1\n", "colouring.toml");
  scene.world.step(scene.dt);
  const clothlab::VbdGraph& graph = dynamic_cast<const Vbd&>(*scene.world.integrator).graph();
  for (const auto& effect : scene.world.force_effects) {
    if (const auto* family = dynamic_cast<const clothlab::SpringDampers*>(effect.get())) {
      CAPTURE(family->name());
      CHECK(colouring_is_valid(graph, family->springs()));
    }
  }
  return {std::move(scene), graph};
}

// A 64 x 64 cloth 2 cm apart, 1 kg in all, ks = 1000 N/m, hanging in its plane from its top
// corners, stepped 20 times by VBD at 1/60 s with one iteration from `initial_guess`.
clothlab::Scene hanging_cloth(const std::string& initial_guess) {
  return clothlab::parse_scene(
      "[cloth]\nrows = 64\ncols = 64\nspacing = 0.02\norigin = [0.0, 1.0, 0.0]\n"
      "plane = \"vertical\"\ndensity = 0.6301197\npins = \"top-corners\"\n"
      "[springs]\nks = 1000.0\nkd = 0.01\n[gravity]\ng = [0.0, -9.8, 0.0]\n"
      "[integrator]\nmethod = \"vbd\"\ndt = 0.016666666666666666\niterations = 1\n"
      "initial_guess = \"" +
          initial_guess + "\"\nduration = 0.3333333333333333\n",
      "hanging.toml");
}

}  // namespace

// ---- One vertex's Newton step, worked by hand ------------------------------------------------

TEST_CASE("vbd vertex: at rest where inertia carries it, a vertex does not move") {
  // At y, with both springs at their rest lengths and nothing moved yet: every force term is
  // zero, exactly. The block is still the inertia m/h^2 = 1 / (2 kg^-1 * 1e-4 s^2) = 5000 N/m
  // on the diagonal plus each spring's stiffness along it (across: ks (1 - l0/l) = 0) and the
  // damper's kd/h along it: 100 + 0.3/0.01 = 130 N/m along x, 50 + 30 = 80 N/m along y.
  const std::vector<VertexSpring> springs = {spring_to(Vec3(1, 0, 0), 100.0, 1.0, 0.3),
                                             spring_to(Vec3(0, -2, 0), 50.0, 2.0, 0.3)};
  const VertexBlock block = block_at(Vec3::Zero(), Vec3::Zero(), 2.0, 0.01, springs);
  CHECK(block.f == Vec3::Zero());
  CHECK(max_abs(block.H - Vec3(5130.0, 5080.0, 5000.0).asDiagonal().toDenseMatrix()) < 1e-9);
  CHECK(step_at(Vec3::Zero(), Vec3::Zero(), 2.0, 0.01, springs) == Vec3::Zero());
}

TEST_CASE("vbd vertex: one stretched spring pulls the vertex back and resists its turning") {
  // The other end at the origin, the vertex at (1.5, 0, 0): l = 1.5 m, l0 = 1 m, ks = 100 N/m,
  // u = (1, 0, 0). m = 1 kg, h = 0.1 s: inertia m/h^2 = 100 N/m, toward y = (1.5, 0.3, 0).
  //   f = -ks (l - l0) u + m/h^2 (y - x) = (-50, 0, 0) + (0, 30, 0)
  //   H = 100 I + ks (u u^T + (1 - l0/l)(I - u u^T)) = diag(200, 100 + 100/3, 100 + 100/3)
  //   dx = H^-1 f = (-0.25, 30 / 133.33 = 0.225, 0).
  // Along x this is the exact minimiser of 50 (x - 1.5)^2 + 50 (x - 1)^2, x = 1.25 m.
  const std::vector<VertexSpring> springs = {spring_to(Vec3::Zero(), 100.0, 1.0)};
  const Vec3 x(1.5, 0.0, 0.0), y(1.5, 0.3, 0.0);
  const VertexBlock block = block_at(x, y, 1.0, 0.1, springs);
  CHECK((block.f - Vec3(-50.0, 30.0, 0.0)).norm() < 1e-12);
  const double across = 100.0 + 100.0 / 3.0;
  CHECK(max_abs(block.H - Vec3(200.0, across, across).asDiagonal().toDenseMatrix()) < 1e-12);
  CHECK((step_at(x, y, 1.0, 0.1, springs) - Vec3(-0.25, 0.225, 0.0)).norm() < 1e-14);
}

TEST_CASE("vbd vertex: two springs at a right angle add their forces and stiffnesses") {
  // The vertex at the origin between ends at (2, 0, 0) and (0, 2, 0), each spring l0 = 1 m,
  // ks = 10 N/m, stretched by 1 m: each pulls with 10 N toward its end, f = (10, 10, 0). Each
  // adds ks along itself and ks (1 - 1/2) = 5 N/m across: diag(10, 5, 5) + diag(5, 10, 5);
  // with m = 1 kg, h = 1 s the inertia adds 1: H = diag(16, 16, 11), dx = (0.625, 0.625, 0).
  const std::vector<VertexSpring> springs = {spring_to(Vec3(2, 0, 0), 10.0, 1.0),
                                             spring_to(Vec3(0, 2, 0), 10.0, 1.0)};
  const VertexBlock block = block_at(Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, springs);
  CHECK((block.f - Vec3(10.0, 10.0, 0.0)).norm() < 1e-14);
  CHECK(max_abs(block.H - Vec3(16.0, 16.0, 11.0).asDiagonal().toDenseMatrix()) < 1e-14);
  CHECK((step_at(Vec3::Zero(), Vec3::Zero(), 1.0, 1.0, springs) - Vec3(0.625, 0.625, 0.0)).norm() <
        1e-14);
}

TEST_CASE("vbd vertex: a compressed spring's Hessian is made definite by the clamp") {
  // The vertex at (0.5, 0, 0), the other end at the origin, l0 = 1 m, ks = 400 N/m: compressed
  // to half. Across the spring the full Hessian is ks (1 - l0/l) = -400 N/m: with the inertia
  // m/h^2 = 100 N/m (1 kg, 0.1 s), H would be diag(500, -300, -300), indefinite, and the step
  // toward y = (0.5, 0.2, 0) would be 20 / -300 m, away from y. Clamped: H = diag(500, 100, 100).
  //   f = -ks (l - l0) u + 100 (y - x) = (200, 0, 0) + (0, 20, 0),   dx = (0.4, 0.2, 0):
  // along x the minimiser of 50 (x - 0.5)^2 + 200 (x - 1)^2, x = 0.9 m; across, y itself.
  const std::vector<VertexSpring> springs = {spring_to(Vec3::Zero(), 400.0, 1.0)};
  const Vec3 x(0.5, 0.0, 0.0), y(0.5, 0.2, 0.0);
  const VertexBlock block = block_at(x, y, 1.0, 0.1, springs);
  CHECK((block.f - Vec3(200.0, 20.0, 0.0)).norm() < 1e-12);
  CHECK(max_abs(block.H - Vec3(500.0, 100.0, 100.0).asDiagonal().toDenseMatrix()) < 1e-12);
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(block.H);
  CHECK(eigen.eigenvalues().minCoeff() == doctest::Approx(100.0));
  CHECK((step_at(x, y, 1.0, 0.1, springs) - Vec3(0.4, 0.2, 0.0)).norm() < 1e-14);
}

TEST_CASE("vbd vertex: the damper acts on the pair's relative motion over the step") {
  // A pure damper (ks = 0, kd = 2 N s/m) at its rest length l0 = 1 m along x; m = 1 kg,
  // h = 0.1 s (inertia 100 N/m), y = x. The vertex moved 0.1 m along x this step, away from
  // an end that stayed: D = kd u u^T, f = -(1/h) D (dx_i - dx_j) = (-2, 0, 0) N and
  // H = 100 I + D/h = diag(120, 100, 100): dx = (-1/60, 0, 0) m.
  const Vec3 x(1.0, 0.0, 0.0), start(0.9, 0.0, 0.0);
  const std::vector<VertexSpring> still = {spring_to(Vec3::Zero(), 0.0, 1.0, 2.0)};
  const VertexBlock block = clothlab::vbd_vertex_block(x, start, x, 1.0, 0.1, still);
  CHECK((block.f - Vec3(-2.0, 0.0, 0.0)).norm() < 1e-12);
  CHECK(max_abs(block.H - Vec3(120.0, 100.0, 100.0).asDiagonal().toDenseMatrix()) < 1e-12);
  CHECK((clothlab::vbd_vertex_step(x, start, x, 1.0, 0.1, still) - Vec3(-1.0 / 60.0, 0, 0)).norm() <
        1e-14);
  // The other end moved with it: no relative motion, no damping. (A damper on the vertex's own
  // displacement would slow a cloth that falls as one piece.)
  const std::vector<VertexSpring> along = {{Vec3::Zero(), Vec3(-0.1, 0, 0), 0.0, 2.0, 1.0}};
  CHECK(clothlab::vbd_vertex_block(x, start, x, 1.0, 0.1, along).f.norm() < 1e-13);
}

TEST_CASE("vbd vertex: the force and Hessian are G_i's derivatives (finite differences)") {
  // A vertex at x_i on three springs, all stretched, in general directions, with y_i elsewhere:
  // f must be -grad G_i and H must be -df/dx_i, each compared with central differences. With
  // every spring stretched the clamp is idle and H is exact. The dampers are left out here: H
  // holds their D / h with D taken as constant over the step (Rayleigh damping, as the paper
  // does), not D's own change with x_i, so it is not f's exact derivative with kd > 0; the damper
  // case above checks its terms by hand.
  const double h = 1.0 / 60.0, w = 4096.0;  // a 1/4096 kg vertex at a game's frame
  const Vec3 x_start(0.01, -0.02, 0.005), y(0.003, 0.004, -0.002);
  const std::vector<Vec3> ends = {{0.03, 0.01, -0.01}, {-0.02, -0.015, 0.02}, {0.0, 0.04, 0.03}};
  std::vector<VertexSpring> springs;
  for (size_t k = 0; k < ends.size(); ++k) {
    const double l0 = 0.6 * (x_start - ends[k]).norm();  // stretched by 1/0.6
    springs.push_back({ends[k], ends[k], 1000.0 * double(k + 1), 0.0, l0});
  }
  const auto energy = [&](const Vec3& x) {  // G_i without the dampers
    double g = (x - y).squaredNorm() / (2.0 * w * h * h);
    for (const VertexSpring& s : springs) {
      const double stretch = (x - s.x_j).norm() - s.l0;
      g += 0.5 * s.ks * stretch * stretch;
    }
    return g;
  };
  const Vec3 x = x_start + Vec3(0.002, 0.001, -0.003);  // the vertex has moved in this step
  const VertexBlock block = clothlab::vbd_vertex_block(x, x_start, y, w, h, springs);
  const double e = 1e-7;
  Vec3 grad;
  Mat3 df;
  for (int a = 0; a < 3; ++a) {
    const Vec3 step = e * Vec3::Unit(a);
    grad(a) = (energy(x + step) - energy(x - step)) / (2.0 * e);
    df.col(a) = (clothlab::vbd_vertex_block(x + step, x_start, y, w, h, springs).f -
                 clothlab::vbd_vertex_block(x - step, x_start, y, w, h, springs).f) /
                (2.0 * e);
  }
  CAPTURE(block.f.transpose());
  CAPTURE(grad.transpose());
  CHECK((block.f + grad).norm() <= 1e-6 * grad.norm());
  CAPTURE(block.H);
  CAPTURE(df);
  CHECK(max_abs(block.H + df) <= 1e-6 * max_abs(block.H));
}

TEST_CASE("vbd vertex: a pinned vertex never moves") {
  // w = 0: whatever pulls at it, the step is zero.
  const std::vector<VertexSpring> springs = {spring_to(Vec3(3, 0, 0), 1000.0, 1.0)};
  CHECK(step_at(Vec3::Zero(), Vec3(0, -1, 0), 0.0, 0.01, springs) == Vec3::Zero());
}

TEST_CASE("vbd vertex: a singular block is skipped, a stiff but definite one is not") {
  // Massless (w infinite: no inertia term) on one compressed spring along (1, 2, 3)/sqrt(14):
  // the clamp leaves H = ks u u^T, of rank 1. There is no Newton step: dx = 0, not NaN.
  const Vec3 u = Vec3(1.0, 2.0, 3.0).normalized();
  const std::vector<VertexSpring> compressed = {spring_to(-0.5 * u, 100.0, 1.0)};
  const VertexBlock singular = block_at(Vec3::Zero(), Vec3::Zero(), kInfinity, 0.01, compressed);
  CHECK(singular.f.norm() == doctest::Approx(50.0));  // the force is there: ks (l0 - l)
  CHECK(max_abs(singular.H - 100.0 * u * u.transpose()) < 1e-12);
  CHECK(step_at(Vec3::Zero(), Vec3::Zero(), kInfinity, 0.01, compressed) == Vec3::Zero());
  // Massless with its one spring's ends coincident: no direction, H = 0.
  const std::vector<VertexSpring> coincident = {spring_to(Vec3::Zero(), 100.0, 1.0)};
  CHECK(step_at(Vec3::Zero(), Vec3::Zero(), kInfinity, 0.01, coincident) == Vec3::Zero());
  // A vertex of a stiff rope: 1 g between two springs of ks = 1e6 N/m at their rest lengths
  // along x, h = 1/60 s. H = diag(2e6 + 3.6, 3.6, 3.6) N/m: det / (trace / 3)^3 is about 9e-11,
  // far above rounding. Moved 1 mm sideways by inertia (y), the springs hold nothing across
  // (ks (1 - l0/l) = 0), so the step takes it to y: dx = (0, 1 mm, 0).
  const std::vector<VertexSpring> rope = {spring_to(Vec3(-1, 0, 0), 1e6, 1.0),
                                          spring_to(Vec3(1, 0, 0), 1e6, 1.0)};
  const double h = 1.0 / 60.0;
  const VertexBlock stiff = block_at(Vec3::Zero(), Vec3(0, 1e-3, 0), 1000.0, h, rope);
  const double scale = stiff.H.trace() / 3.0;
  const double ratio = stiff.H.determinant() / (scale * scale * scale);
  MESSAGE("stiff rope vertex: det(H) / (trace(H) / 3)^3 = " << ratio);
  CHECK(ratio > 100.0 * clothlab::kSingularBlock);
  CHECK((step_at(Vec3::Zero(), Vec3(0, 1e-3, 0), 1000.0, h, rope) - Vec3(0, 1e-3, 0)).norm() <
        1e-15);
}

// ---- The integrator ----------------------------------------------------------------------------

TEST_CASE("vbd: a hanging mass settles at the spring's static stretch m g / ks") {
  // test::check_hanging_mass: one free vertex on one spring from a pinned anchor. Along the
  // spring's axis G is a quadratic in the vertex's height, so one Newton step is its exact
  // minimiser, and the damper along the spring is lecture 02's.
  for (int iterations : {1, 10}) {
    CAPTURE(iterations);
    test::check_hanging_mass([&](World& world) { use_vbd(world, iterations); });
  }
}

TEST_CASE("vbd: on one spring along its axis, one iteration is implicit Euler's energy decay") {
  // test::check_spring_energy_decay: one vertex on one spring along its axis, so one Newton step
  // is the exact implicit Euler step.
  for (int iterations : {1, 10}) {
    CAPTURE(iterations);
    test::check_spring_energy_decay([&](World& world) { use_vbd(world, iterations); });
  }
}

TEST_CASE("vbd: with more iterations the step converges to the exact implicit Euler step") {
  // The 3 x 3 patch of implicit_solvers.hpp (pulled out of place, moving, one corner pinned, ks =
  // 200 N/m, no dampers) stepped once by h = 20 ms, against the minimiser of G found by Newton's
  // method on the whole system. VBD's sweeps descend G vertex by vertex: the difference must
  // fall with the iterations and reach rounding.
  const double h = 0.02;
  // Measured: 5.5e-3 m after 1 iteration, 1.7e-8 m after 5, rounding (3e-15 m) after 10.
  const Matrix3X exact = test::newton_implicit_euler(test::patch(200.0, 0.0), h);
  check_convergence(0.0, h, 1e-12, "largest difference [m]",
                    [&](const Matrix3X& x) { return (x - exact).cwiseAbs().maxCoeff(); });
}

TEST_CASE("vbd: with dampers the iterations settle where implicit Euler's forces balance") {
  // The same patch with kd = 0.5 N s/m. The dampers are not an energy's gradient, so there is
  // no minimiser to compare with; instead the residual of implicit Euler's equations at the new
  // positions, with v = (x - x_n)/h and the Rayleigh damper of vbd_vertex.hpp on each spring,
  //   r_i = m_i (x_i - y_i)/h^2 - sum_springs [-ks (l - l0) u - (1/h) D (dx_i - dx_j)],
  // y_i = x_i,n + h v_i,n + h^2 g, must fall with the iterations to rounding (on forces of
  // about m g = 5 N, 1e-9 N).
  const double h = 0.02;
  const World start = test::patch(200.0, 0.5);
  const clothlab::SpringSet& s = test::springs_of(start);
  const auto residual = [&](const Matrix3X& x) {
    const clothlab::Particles& p = start.particles;
    Matrix3X r(3, p.size());
    for (Index i = 0; i < p.size(); ++i) {
      const Vec3 y = p.x.col(i) + h * p.v.col(i) + h * h * Vec3(0.0, -kG, 0.0);
      r.col(i) = p.m[i] * (x.col(i) - y) / (h * h);
    }
    for (size_t k = 0; k < s.size(); ++k) {
      const Index i = s.i(k), j = s.j(k);
      const Vec3 d = x.col(i) - x.col(j);
      const double l = d.norm();
      const Vec3 u = d / l;
      const Mat3 along = u * u.transpose();
      const Mat3 D =
          s.kd(k) * (along + std::max(0.0, 1.0 - s.l0(k) / l) * (Mat3::Identity() - along));
      const Vec3 moved = (x.col(i) - p.x.col(i)) - (x.col(j) - p.x.col(j));
      const Vec3 f = -s.ks(k) * (l - s.l0(k)) * u - D * moved / h;  // on i; -f on j
      r.col(i) -= f;
      r.col(j) += f;
    }
    r.col(0).setZero();  // the pinned corner is no unknown
    return r.cwiseAbs().maxCoeff();
  };
  // Measured: 10.8 N after 1 iteration, 4.8e-5 N after 5, 2e-11 N after 10.
  check_convergence(0.5, h, 1e-9, "largest residual [N]", residual);
}

TEST_CASE(
    "vbd: a stiff cloth is stable at 1/60 s with one iteration, where symplectic Euler is not") {
  // test::stiff_sheet: 1 g a particle, ks = 5000 N/m, dt = 1/60 s, so dt w ~ 75. Symplectic Euler
  // is stopped by the guard; VBD with one iteration a step runs the 2 s, ends with less kinetic
  // energy than the sheet's fall could give it (m g 0.64 m = 0.63 J), and its pinned corners
  // are where they started, to the bit.
  clothlab::Scene euler =
      clothlab::parse_scene(test::stiff_sheet("symplectic-euler"), "stiff.toml");
  CHECK_THROWS_AS(test::run_to_end(euler), clothlab::SimulationError);
  clothlab::Scene vbd =
      clothlab::parse_scene(test::stiff_sheet("vbd") + "iterations = 1\n", "stiff.toml");
  const Matrix3X x0 = vbd.world.particles.x;
  CHECK_NOTHROW(test::run_to_end(vbd));
  MESSAGE("kinetic energy after 2 s: " << vbd.world.kinetic_energy() << " J");
  CHECK(vbd.world.kinetic_energy() < 0.63);
  int pinned = 0;
  for (Index i = 0; i < vbd.world.particles.size(); ++i) {
    if (vbd.world.particles.inv_m[i] != 0.0) continue;
    ++pinned;
    CHECK(vbd.world.particles.x.col(i) == x0.col(i));
  }
  CHECK(pinned == 2);
}

TEST_CASE("vbd: scenes read iterations and run with bending, pins and colliders") {
  const std::string text = test::drape("method = \"vbd\"\niterations = 3\n");
  clothlab::Scene scene = clothlab::parse_scene(text, "drape.toml");
  auto* vbd = dynamic_cast<Vbd*>(scene.world.integrator.get());
  REQUIRE(vbd != nullptr);
  CHECK(vbd->iterations == 3);
  test::run_to_end(scene);
  // The sphere and the ground apply after each step (world.cpp): no particle ends inside the
  // sphere or under the ground, beyond the colliders' own tolerance of a millimetre.
  for (Index i = 0; i < scene.world.particles.size(); ++i) {
    const Vec3 x = scene.world.particles.x.col(i);
    CHECK((x - Vec3(0.0, 0.5, 0.0)).norm() >= 0.3 - 1e-3);
    CHECK(x.y() >= -1e-3);
  }
  // Both spring families, springs and bending, are in the vertices' blocks: each spring is
  // listed at both its ends.
  const size_t springs =
      test::springs_of(scene.world).size() + test::springs_of(scene.world, "bending").size();
  CHECK(vbd->graph().other.size() == 2 * springs);
  // The default: 10 iterations.
  clothlab::Scene plain = clothlab::parse_scene(
      "[[particle]]\nposition = [0, 0, 0]\nmass = 1\n[integrator]\nmethod = \"vbd\"\n"
      "dt = 0.01\nduration = 1\n",
      "defaults.toml");
  auto* defaults = dynamic_cast<Vbd*>(plain.world.integrator.get());
  REQUIRE(defaults != nullptr);
  CHECK(defaults->iterations == 10);
}

TEST_CASE(
    "vbd: a hanging cloth stepped with few iterations keeps its energy from the adaptive guess") {
  // The cloth hangs already; implicit Euler barely moves it in 20 steps (its energy, 3.63 J,
  // falls to 3.58 J with the sweeps converged). m/h^2 = 0.88 N/m per vertex against ks =
  // 1000 N/m: a sweep carries the pins' pull a vertex or two, so from y (every vertex in free
  // fall) one iteration leaves the cloth below the top rows falling and the springs between
  // stretching: its energy grows some 80-fold (vbd.hpp). The adaptive guess starts each vertex
  // where its last step's acceleration along gravity carries it: a hanging vertex, which did not
  // accelerate, is not dropped, and the energy does not grow.
  clothlab::Scene inertia = hanging_cloth("inertia");
  clothlab::Scene adaptive = hanging_cloth("adaptive");
  REQUIRE(dynamic_cast<Vbd&>(*adaptive.world.integrator).initial_guess ==
          clothlab::VbdInitialGuess::adaptive);
  const double e0 = inertia.world.kinetic_energy() + inertia.world.potential_energy();
  test::run_to_end(inertia);
  test::run_to_end(adaptive);
  const double e_inertia = inertia.world.kinetic_energy() + inertia.world.potential_energy();
  const double e_adaptive = adaptive.world.kinetic_energy() + adaptive.world.potential_energy();
  MESSAGE("energy " << e0 << " J -> " << e_inertia << " J (inertia), " << e_adaptive
                    << " J (adaptive)");
  CHECK(e_inertia > 10.0 * e0);  // the method's limit the adaptive guess is for (measured: 80x)
  CHECK(e_adaptive <= e0);
  CHECK(e_adaptive > e0 - 0.1);  // and it is not frozen either: implicit Euler loses 0.05 J
  // The key belongs to vbd alone, and takes one of its two values.
  CHECK_THROWS_WITH_AS(clothlab::parse_scene("[integrator]\nmethod = \"xpbd\"\ndt = 0.01\n"
                                             "duration = 1\ninitial_guess = \"adaptive\"\n",
                                             "x.toml"),
                       doctest::Contains("expected no initial_guess here"), std::exception);
  CHECK_THROWS_AS(clothlab::parse_scene("[integrator]\nmethod = \"vbd\"\ndt = 0.01\n"
                                        "duration = 1\ninitial_guess = \"y\"\n",
                                        "y.toml"),
                  std::exception);
}

TEST_CASE("vbd: a spring torn between steps pulls no more; a new rest length is felt at once") {
  // One free particle on a spring from a pinned anchor, no gravity, stretched 0.1 m and at rest.
  SUBCASE("torn") {
    // One step with the spring moves it toward the anchor. Then the spring is removed (as
    // tearing removes it): the particle must coast at the velocity it has, unchanged.
    World world = test::anchored_spring(1.0, 100.0, 0.0, 0.1, 0.0);
    Vbd& vbd = use_vbd(world, 2);
    world.step(0.01);
    const Vec3 v = world.particles.v.col(1);
    REQUIRE(v.x() < 0.0);
    test::springs_of(world).erase({0});
    world.step(0.01);
    CHECK((Vec3(world.particles.v.col(1)) - v).norm() <= 1e-12 * v.norm());  // v = (x - x_n)/h
    CHECK(vbd.graph_builds == 2);
    CHECK(vbd.graph().other.empty());
  }
  SUBCASE("a new rest length") {
    // At rest at its rest length, the spring is given l0 = 0.5 m (as plasticity changes it,
    // with no new version of the set): the next step must pull the particle in.
    World world = test::anchored_spring(1.0, 100.0, 0.0, 0.0, 0.0);
    use_vbd(world, 2);
    world.step(0.01);
    REQUIRE(world.particles.v.col(1).norm() == 0.0);
    test::springs_of(world).set_l0(0, 0.5);
    world.step(0.01);
    CHECK(world.particles.v(0, 1) < 0.0);
  }
}

TEST_CASE("vbd: a storm blows the sheet and tears it; the pins stay put") {
  // The storm sheet of tearing.cpp (wind along +z, aerodynamics as an external force), stepped
  // by VBD: the pins (inv_m = 0) never move, the wind carries the sheet along +z, and the springs
  // past the tearing strain are removed between steps; the graph is built again after each tear.
  clothlab::Scene scene = clothlab::parse_scene(
      test::storm("[tearing]\nstrain = 0.3\n") + "method = \"vbd\"\niterations = 2\n",
      "storm.toml");
  const size_t springs_before = test::springs_of(scene.world).size();
  const Matrix3X x0 = scene.world.particles.x;
  for (long s = 0; s < 2000; ++s)
    scene.world.step(scene.dt);
  const auto& vbd = dynamic_cast<const Vbd&>(*scene.world.integrator);
  for (Index i = 0; i < scene.world.particles.size(); ++i) {
    if (scene.world.particles.inv_m[i] == 0.0) CHECK(scene.world.particles.x.col(i) == x0.col(i));
  }
  CHECK((scene.world.particles.x.row(2) - x0.row(2)).mean() > 0.05);
  const size_t springs_after = test::springs_of(scene.world).size();
  CHECK(springs_after < springs_before);
  CHECK(vbd.graph_builds > 1);
  CHECK(vbd.graph().other.size() == 2 * springs_after);
}

TEST_CASE("vbd: the fast path takes no whole step and no force sum, with the same result") {
  test::check_fast_path_declines(test::storm() + "method = \"vbd\"\niterations = 2\n");
}

TEST_CASE("vbd: the game loop drives a scene the same for any split into frames") {
  test::check_frames_do_not_matter(test::storm() + "method = \"vbd\"\niterations = 2\n");
  // The adaptive guess keeps the last step's velocities: a frame's split must not lose them.
  test::check_frames_do_not_matter(
      test::storm() + "method = \"vbd\"\niterations = 2\ninitial_guess = \"adaptive\"\n");
}

// ---- The colouring ---------------------------------------------------------------------------

TEST_CASE("vbd colouring: a cloth grid takes four colours, a 2 x 2 pattern") {
  // Structural and shear springs join each vertex to its 8 neighbours. Greedy in index order
  // (row by row): row 0 alternates 0, 1; in row 1 the first vertex sees 0 and 1 above it and
  // takes 2, the next sees 2, 0, 1, 0 and takes 3, and so on: (r, c) gets 2 (r mod 2) + c mod 2.
  // Four is also the least any colouring can do: the four vertices of a cell all share springs.
  const Coloured grid =
      coloured("[cloth]\nrows = 8\ncols = 9\nspacing = 0.1\nmass = 0.5\n[springs]\nks = 100\n");
  CHECK(grid.graph.colours() == 4);
  for (Index r = 0; r < 8; ++r) {
    for (Index c = 0; c < 9; ++c)
      CHECK(grid.graph.colour[static_cast<size_t>(grid.scene.cloth->at(r, c))] ==
            2 * (r % 2) + c % 2);
  }
  // The sweep's order: every vertex once, colour by colour.
  const clothlab::VbdGraph& g = grid.graph;
  REQUIRE(g.order.size() == 72);
  for (int q = 0; q < g.colours(); ++q) {
    for (size_t c = g.colour_start[static_cast<size_t>(q)];
         c < g.colour_start[static_cast<size_t>(q) + 1]; ++c)
      CHECK(g.colour[static_cast<size_t>(g.order[c])] == q);
  }
}

TEST_CASE("vbd colouring: valid with bending springs, on a lattice and on random springs") {
  // Bending springs join vertices two apart as well: 12 neighbours inside the grid, so greedy
  // needs at most 13 colours; whatever it takes, no spring of either family may join two
  // vertices of one colour (coloured() checks it).
  const Coloured bending = coloured(
      "[cloth]\nrows = 10\ncols = 10\nspacing = 0.1\nmass = 0.5\n[springs]\nks = 100\n"
      "[bending]\nks = 10\n");
  MESSAGE("a 10 x 10 grid with bending springs: " << bending.graph.colours() << " colours");
  CHECK(bending.graph.colours() <= 13);
  CHECK(bending.graph.other.size() ==
        2 * (test::springs_of(bending.scene.world).size() +
             test::springs_of(bending.scene.world, "bending").size()));
  // A 3 x 4 x 5 lattice (solid.hpp: edges, face and body diagonals).
  const Coloured lattice = coloured(
      "[solid]\nparticles = [3, 4, 5]\nsize = [0.2, 0.3, 0.4]\nmass = 1\n[springs]\nks = 100\n");
  MESSAGE("a 3 x 4 x 5 lattice: " << lattice.graph.colours() << " colours");

  // 300 springs between random pairs of 60 vertices (a fixed seed, some pairs repeated).
  clothlab::SpringSet random;
  unsigned state = 12345;
  const auto next = [&] {
    state = state * 1103515245u + 12345u;
    return static_cast<Index>((state >> 16) % 60);
  };
  for (int k = 0; k < 300; ++k) {
    const Index a = next(), b = next();
    if (a != b) random.add(a, b, 1.0, 0.0, 1.0);
  }
  clothlab::VbdGraph any;
  any.build(60, {&random});
  CHECK(colouring_is_valid(any, random));
  // Greedy's bound: no vertex takes a colour above its count of springs.
  for (Index i = 0; i < 60; ++i) {
    const auto at = static_cast<size_t>(i);
    CHECK(static_cast<size_t>(any.colour[at]) <= any.start[at + 1] - any.start[at]);
  }
}

TEST_CASE("vbd: a cloth scrambled at random recovers its shape") {
  // The paper's demonstration, on a mass-spring cloth: a 10 x 10 cloth (5 cm apart, 1 g a particle,
  // ks = 100 N/m, kd = 0.01 N s/m, no gravity, no pins) with every particle thrown to a random
  // point of a 10 cm box. Nothing but the springs acts: VBD must pull it back to a sheet whose
  // springs are near their rest lengths.
  clothlab::Scene scene = clothlab::parse_scene(
      "[cloth]\nrows = 10\ncols = 10\nspacing = 0.05\nmass = 0.1\npins = \"none\"\n"
      "[springs]\nks = 100\nkd = 0.01\n[integrator]\nmethod = \"vbd\"\niterations = 10\n"
      "dt = 0.016666666666666666\nduration = 5\n",
      "scrambled.toml");
  clothlab::Particles& p = scene.world.particles;
  unsigned state = 2024;
  for (Index i = 0; i < p.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      state = state * 1103515245u + 12345u;
      p.x(a, i) = 0.1 * static_cast<double>((state >> 8) % 10000) / 10000.0;
    }
  }
  const clothlab::SpringSet& s = test::springs_of(scene.world);
  const auto worst_strain = [&] {
    double worst = 0.0;
    for (size_t k = 0; k < s.size(); ++k)
      worst = std::max(worst, std::abs((p.x.col(s.i(k)) - p.x.col(s.j(k))).norm() / s.l0(k) - 1.0));
    return worst;
  };
  const double before = worst_strain();
  REQUIRE(before > 1.0);  // some spring at more than twice its rest length, or squeezed to 0
  test::run_to_end(scene);
  // Measured: the worst spring 171 % off its rest length at the start, 0.50 % after 5 s.
  const double after = worst_strain();
  MESSAGE("worst strain " << before << " -> " << after);
  CHECK(after < 0.01);
}
