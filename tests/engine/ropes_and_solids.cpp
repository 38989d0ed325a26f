// Ropes, soft solids and strain limiting (lesson 09): what must hold for any scene.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "clothlab/after_step/strain_limiting.hpp"
#include "clothlab/bodies/solid.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::IndexPair;
using clothlab::Vec3;

namespace {

clothlab::StrainLimiting* limiter_of(clothlab::World& world) {
  return test::find_post_step_effect<clothlab::StrainLimiting>(world);
}

// The sum over the springs of how far each is past 1.1 l0, relative to l0.
double total_excess(const clothlab::World& world) {
  const clothlab::SpringSet& s = test::springs_of(world);
  double sum = 0.0;
  for (size_t k = 0; k < s.size(); ++k) {
    const double l = (world.particles.x.col(s.j(k)) - world.particles.x.col(s.i(k))).norm();
    sum += std::max(0.0, l / s.l0(k) - 1.1);
  }
  return sum;
}

// The largest l / l0 - 1 over the springs.
double max_strain(const clothlab::World& world) {
  const clothlab::SpringSet& s = test::springs_of(world);
  double worst = -1.0;
  for (size_t k = 0; k < s.size(); ++k) {
    const double l = (world.particles.x.col(s.j(k)) - world.particles.x.col(s.i(k))).norm();
    worst = std::max(worst, l / s.l0(k) - 1.0);
  }
  return worst;
}

// A 6 x 6 cloth pinned at one corner, with a strain limit of 10 %.
std::string limited_cloth(int iterations, const std::string& pins = "[0]") {
  return R"(
[cloth]
rows = 6
cols = 6
spacing = 0.1
mass = 0.36
pins = )" +
         pins + R"(
[springs]
ks = 10
[strain_limit]
max_strain = 0.1
iterations = )" +
         std::to_string(iterations) +
         R"(
[integrator]
dt = 0.001
duration = 1
)";
}

// Stretches every particle away from particle 0 by 1.6 and adds a reproducible jitter of up to
// 2 cm (a linear congruential generator, the same on every machine), keeping pins in place.
void stretch(clothlab::Particles& p) {
  std::uint64_t state = 12345;
  auto jitter = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5) * 0.04;  // [m]
  };
  const Vec3 origin = p.x.col(0);
  for (Index i = 0; i < p.size(); ++i) {
    if (p.inv_m[i] == 0.0) continue;
    const Vec3 moved = origin + 1.6 * (p.x.col(i) - origin);
    p.x.col(i) = moved + Vec3(jitter(), jitter(), jitter());
  }
}

}  // namespace

TEST_CASE("strain limiting: enough sweeps bring every spring of a stretched cloth within limit") {
  clothlab::Scene scene = clothlab::parse_scene(limited_cloth(2000), "limited.toml");
  clothlab::World& w = scene.world;
  stretch(w.particles);
  REQUIRE(max_strain(w) > 0.5);  // badly stretched: 60 % and more
  const Vec3 pinned = w.particles.x.col(0);
  clothlab::StrainLimiting* limiter = limiter_of(w);
  REQUIRE(limiter != nullptr);
  limiter->apply(w, clothlab::StepTime::whole(w.t, scene.dt));
  CAPTURE(limiter->last_sweeps());
  // Every spring at most 10 % long, up to the tolerance the sweeps stop at (1e-9 of l0; a few
  // times that after the last sweep's corrections).
  CHECK(max_strain(w) <= 0.1 + 1e-8);
  CHECK(limiter->last_sweeps() < 2000);  // it stopped because nothing was left to correct
  // The pinned particle did not move, bit for bit, and is still at rest.
  CHECK(w.particles.x.col(0) == pinned);
  CHECK(w.particles.v.col(0) == Vec3::Zero());
}

TEST_CASE("strain limiting: a few sweeps reduce the total excess and stop at the bound") {
  // With iterations = 3 the loop ends after three sweeps, converged or not. A sweep shortens
  // each spring in turn and may lengthen a neighbour it has already visited, so the single worst
  // spring can get worse for a while; what the sweeps reduce is the stretch past the limit
  // summed over all springs.
  clothlab::Scene scene = clothlab::parse_scene(limited_cloth(3), "three.toml");
  clothlab::World& w = scene.world;
  stretch(w.particles);
  const double before = total_excess(w);
  limiter_of(w)->apply(w, clothlab::StepTime::whole(w.t, scene.dt));
  CHECK(limiter_of(w)->last_sweeps() == 3);
  CAPTURE(before);
  CHECK(total_excess(w) < 0.5 * before);
}

TEST_CASE("strain limiting: pins stay bitwise fixed through a whole run") {
  clothlab::Scene scene = clothlab::load_scene_file(std::string(CLOTHLAB_SOURCE_DIR) +
                                                    "/lessons/09-ropes-and-solids/taut-cloth.toml");
  clothlab::World& w = scene.world;
  const Index right = scene.cloth->at(0, scene.cloth->cols - 1);
  const Vec3 left_pin = w.particles.x.col(0), right_pin = w.particles.x.col(right);
  for (int n = 0; n < 500; ++n)
    w.step(scene.dt);
  CHECK(w.particles.x.col(0) == left_pin);
  CHECK(w.particles.x.col(right) == right_pin);
  CHECK(w.particles.v.col(0) == Vec3::Zero());
  CHECK(w.particles.v.col(right) == Vec3::Zero());
}

TEST_CASE("strain limiting: a correction between two free particles keeps momentum") {
  // Masses 1 and 3 kg, 2 m apart on a spring of l0 = 1 m with a 10 % limit: the correction is
  // C = 2 - 1.1 = 0.9 m, split 3/4 : 1/4 by inverse mass. Momentum and centre of mass stay.
  clothlab::World w;
  w.particles.add(Vec3(0.0, 0.0, 0.0), Vec3(1.0, -2.0, 0.5), 1.0);
  w.particles.add(Vec3(1.2, 1.6, 0.0), Vec3(-0.3, 0.4, 2.0), 3.0);
  clothlab::SpringSet s;
  s.add(0, 1, 10.0, 0.0, 1.0);
  w.force_effects.push_back(std::make_unique<clothlab::SpringDampers>("springs", s));
  clothlab::StrainLimiting limiter(*clothlab::find_spring_effect(w, "springs"), {0.1, 1.0}, 10);
  const Vec3 momentum = w.momentum();
  const Vec3 centre = w.particles.x * w.particles.m / 4.0;
  const double dt = 0.01;  // [s]
  limiter.apply(w, clothlab::StepTime::whole(w.t, dt));
  const Vec3 dr0 = w.particles.x.col(0) - Vec3(0.0, 0.0, 0.0);
  CHECK((w.particles.x.col(1) - w.particles.x.col(0)).norm() == doctest::Approx(1.1));
  CHECK((w.momentum() - momentum).norm() <= 1e-12);
  CHECK((w.particles.x * w.particles.m / 4.0 - centre).norm() <= 1e-12);
  // Particle 0 (the lighter) moved 3/4 of 0.9 m along e = (0.6, 0.8, 0), and its velocity
  // changed by that move over dt.
  CHECK((dr0 - 0.675 * Vec3(0.6, 0.8, 0.0)).norm() <= 1e-12);
  CHECK((w.particles.v.col(0) - (Vec3(1.0, -2.0, 0.5) + dr0 / dt)).norm() <= 1e-9);
}

TEST_CASE("strain limiting: nothing moves when no spring is past its limit") {
  // The cloth as built: every spring at its rest length. One sweep finds nothing and stops.
  clothlab::Scene scene = clothlab::parse_scene(limited_cloth(10, "\"top-corners\""), "rest.toml");
  clothlab::World& w = scene.world;
  w.particles.v.setConstant(0.25);  // any velocity: the effect must not touch it either
  const clothlab::Matrix3X x = w.particles.x, v = w.particles.v;
  limiter_of(w)->apply(w, clothlab::StepTime::whole(w.t, scene.dt));
  CHECK(limiter_of(w)->last_sweeps() == 1);
  CHECK(w.particles.x == x);
  CHECK(w.particles.v == v);
}

TEST_CASE("strain limiting: only a scene naming [strain_limit] gets the effect") {
  const std::string base = R"(
[rope]
start = [0, 0, 0]
end = [1, 0, 0]
particles = 5
mass = 0.1
pins = "first"
[springs]
ks = 100
[integrator]
dt = 0.001
duration = 1
)";
  clothlab::Scene without = clothlab::parse_scene(base, "without.toml");
  clothlab::Scene with =
      clothlab::parse_scene(base + "[strain_limit]\nmax_strain = 0.05\n", "with.toml");
  CHECK(without.world.post_step_effects.empty());
  REQUIRE(with.world.post_step_effects.size() == 1);
  CHECK(with.world.post_step_effects[0]->name() == "strain_limit");
}

TEST_CASE("solid: spring counts per family") {
  // A single cell (2 x 2 x 2): 12 edges, 6 faces x 2 diagonals = 12, 4 body diagonals: 28, which
  // is every pair of its 8 corners, 8 * 7 / 2.
  CHECK(clothlab::solid_structural_pairs(2, 2, 2).size() == 12);
  CHECK(clothlab::solid_face_diagonal_pairs(2, 2, 2).size() == 12);
  CHECK(clothlab::solid_body_diagonal_pairs(2, 2, 2).size() == 4);
  // 3 x 4 x 5 particles (2 x 3 x 4 = 24 cells):
  //   structural: along x (nx-1) ny nz = 2*4*5 = 40, along y nx (ny-1) nz = 3*3*5 = 45, along z
  //               nx ny (nz-1) = 3*4*4 = 48: 133;
  //   face diagonals: 2 per face; x-y faces (nx-1)(ny-1) nz = 2*3*5 = 30, x-z faces
  //               (nx-1) ny (nz-1) = 2*4*4 = 32, y-z faces nx (ny-1)(nz-1) = 3*3*4 = 36: 2*98 =
  //               196;
  //   body diagonals: 4 per cell, 4 * 24 = 96.
  CHECK(clothlab::solid_structural_pairs(3, 4, 5).size() == 133);
  CHECK(clothlab::solid_face_diagonal_pairs(3, 4, 5).size() == 196);
  CHECK(clothlab::solid_body_diagonal_pairs(3, 4, 5).size() == 96);
}

TEST_CASE("solid: every spring once with the length of its family, and an outward surface") {
  // Spacings 0.1, 0.2, 0.3 m: a structural spring is one of them, a face diagonal the hypotenuse
  // of two, a body diagonal sqrt(0.01 + 0.04 + 0.09).
  clothlab::Particles p;
  const clothlab::SolidLattice g =
      clothlab::add_solid(p, {3, 4, 5, Vec3(1.0, 2.0, 3.0), Vec3(0.2, 0.6, 1.2), 2.4});
  CHECK(p.size() == 60);
  CHECK(p.m.sum() == doctest::Approx(2.4));
  const double hx = 0.1, hy = 0.2, hz = 0.3;
  std::set<IndexPair> seen;
  auto check_family = [&](const std::vector<IndexPair>& pairs, const std::set<long>& lengths) {
    for (const auto& [a, b] : pairs) {
      CHECK(seen.insert({std::min(a, b), std::max(a, b)}).second);  // not built twice
      const double l = (p.x.col(g.first + a) - p.x.col(g.first + b)).norm();
      CHECK(lengths.count(std::lround(l * l * 1e4)) == 1);  // l^2 in units of 1e-4 m^2
    }
  };
  check_family(clothlab::solid_structural_pairs(3, 4, 5), {100, 400, 900});
  check_family(clothlab::solid_face_diagonal_pairs(3, 4, 5), {500, 1000, 1300});
  check_family(clothlab::solid_body_diagonal_pairs(3, 4, 5), {1400});
  CHECK(std::lround(hx * hx * 1e4 + hy * hy * 1e4 + hz * hz * 1e4) == 1400);
  // Surface: two triangles per outside square, 2 [2*3 + 2*4 + 3*4] * 2 = 104, each with its
  // normal pointing away from the box's centre.
  const std::vector<clothlab::Triangle> surface = clothlab::solid_surface_triangles(g);
  CHECK(surface.size() == 104);
  const Vec3 centre = p.x.rowwise().mean();
  for (const clothlab::Triangle& t : surface) {
    const Vec3 a = p.x.col(t[0]), b = p.x.col(t[1]), c = p.x.col(t[2]);
    const Vec3 n = (b - a).cross(c - a);
    CHECK(n.norm() > 0.0);
    CHECK(n.dot((a + b + c) / 3.0 - centre) > 0.0);
  }
}

TEST_CASE("solid: a jelly cube dropped on the ground stays finite and comes to rest above it") {
  clothlab::Scene scene = clothlab::load_scene_file(std::filesystem::path(CLOTHLAB_SOURCE_DIR) /
                                                    "lessons/09-ropes-and-solids/jelly-cube.toml");
  clothlab::World& w = scene.world;
  REQUIRE(scene.solid);
  CHECK(test::springs_of(w).size() == 300 + 480 + 256);  // a 5 x 5 x 5 lattice, see the scene
  test::run_to_end(scene);
  const clothlab::Matrix3X& x = w.particles.x;
  CHECK(x.allFinite());
  CHECK(w.particles.v.allFinite());
  CHECK(x.row(1).minCoeff() >= -1e-9);  // nothing below the ground, y = 0
  // At rest: the kinetic energy has gone (it was 1 kg * 9.8 * 0.5 m = 4.9 J at impact).
  CHECK(w.kinetic_energy() < 1e-3);
  // Standing on its bottom face, squashed but not flat: its top is below 0.3 m, well above 0.
  CHECK(x.row(1).maxCoeff() < 0.3);
  CHECK(x.row(1).maxCoeff() > 0.2);
}
