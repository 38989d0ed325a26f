// Cloth made of spring-dampers (lessons 02-04): the properties the whole engine must keep.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "clothlab/bodies/cloth.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/bending.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::Vec3;

namespace {

// A light cloth, 12 x 12 particles 4 cm apart, 0.1 kg in all, held by two corners of one edge.
// It starts flat and horizontal, so it falls and swings down into a hanging drape. (A cloth
// that starts hanging in a vertical plane would only stretch: every force, gravity included,
// stays in its plane.)
const char* kHangingCloth = R"(
[cloth]
rows = 12
cols = 12
spacing = 0.04
plane = "horizontal"
mass = 0.1
pins = "top-corners"
[springs]
ks = 60
kd = 0.02
[bending]
ks = 5
kd = 0.002
[gravity]
[integrator]
dt = 0.0005
duration = 1
)";

// Sets every velocity to a fixed pseudo-random kick (the same on every run) [m/s].
void kick(clothlab::World& world) {
  unsigned state = 12345u;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;  // a linear congruential generator
    return static_cast<double>(state >> 8) / static_cast<double>(1u << 24) - 0.5;
  };
  for (Index i = 0; i < world.particles.size(); ++i) {
    if (world.particles.inv_m[i] == 0.0) continue;
    world.particles.v.col(i) = Vec3(next(), next(), next());
  }
}

// Exercise ex02.1 exactly as lesson 02 writes it: e = e* / l, the two velocities along e, f_sd e.
Vec3 lecture_spring_damper_force(const Vec3& r1, const Vec3& r2, const Vec3& v1, const Vec3& v2,
                                 double ks, double kd, double l0) {
  const Vec3 e_star = r2 - r1;
  const double l = e_star.norm();
  if (l == 0.0) return Vec3::Zero();
  const Vec3 e = e_star / l;
  const double v1_e = e.dot(v1), v2_e = e.dot(v2);
  return (-ks * (l0 - l) - kd * (v1_e - v2_e)) * e;
}

}  // namespace

TEST_CASE("cloth: the reference spring kernel is the lecture's formula, to rounding") {
  // The reference answer to 2.1 divides once where the lecture's form divides three times, and
  // takes the damper's dot product with e* (solutions/02_spring_dampers.cpp): the same force,
  // rounded differently. Over springs of every length, stretch, stiffness and speed, the two
  // may differ by a few roundings of the largest term, and by no more.
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), exponent(-3.0, 3.0);
  // The draws are declarations, one after the other, never two arguments of one call (whose
  // order C++ leaves open): every compiler draws the same springs.
  const auto magnitude = [&] { return std::pow(10.0, exponent(rng)); };
  const auto vec = [&] {
    const double size = magnitude(), x = unit(rng), y = unit(rng), z = unit(rng);
    return Vec3(size * x, size * y, size * z);
  };
  constexpr double eps = std::numeric_limits<double>::epsilon();
  for (int k = 0; k < 10000; ++k) {
    const Vec3 r1 = vec(), r2 = r1 + vec(), v1 = vec(), v2 = vec();
    const double ks = magnitude(), kd = magnitude(), l = (r2 - r1).norm();
    const double l0 = l * (0.5 + 0.5 * (unit(rng) + 1.0));  // from half the length to 1.5 times
    const Vec3 reference = clothlab::spring_damper_force(r1, r2, v1, v2, ks, kd, l0);
    const Vec3 lecture = lecture_spring_damper_force(r1, r2, v1, v2, ks, kd, l0);
    const double scale = ks * (l + l0) + kd * (v1.norm() + v2.norm());
    CAPTURE(k);
    CAPTURE(reference.transpose());
    CAPTURE(lecture.transpose());
    REQUIRE((reference - lecture).norm() <= 16.0 * eps * scale);
  }
  // Coincident particles (l == 0) are checked in hard_cases.cpp.
}

TEST_CASE("cloth: a grid has the spring counts the lecture's pictures give") {
  // rows x cols particles: structural r(c-1) + c(r-1), shear 2(r-1)(c-1),
  // bending r(c-2) + c(r-2). For 12 x 12: 264, 242 and 240.
  clothlab::Scene scene = clothlab::parse_scene(kHangingCloth, "hanging.toml");
  const clothlab::SpringSet& springs = test::springs_of(scene.world, "springs");
  const clothlab::SpringSet& bending = test::springs_of(scene.world, "bending");
  CHECK(springs.size() == 264 + 242);
  CHECK(bending.size() == 240);
  CHECK(scene.world.triangles.size() == 2 * 11 * 11);
  // Rest lengths are the build-time distances: 4 cm, 4 cm * sqrt(2) and 8 cm.
  for (double l0 : bending.l0())
    CHECK(l0 == doctest::Approx(0.08));
}

TEST_CASE("cloth: internal forces conserve momentum for every integrator") {
  // Springs, dampers and bending act in equal and opposite pairs: with no pins and no gravity,
  // total momentum stays what the kick gave, to rounding.
  std::string text = kHangingCloth;
  text.replace(text.find("pins = \"top-corners\""), 20, "pins = \"none\"");
  text.replace(text.find("[gravity]"), 9, "");
  for (const char* method : {"symplectic-euler", "explicit-euler"}) {
    CAPTURE(method);
    std::string with_method = text;
    with_method.replace(with_method.find("dt = 0.0005"), 11,
                        std::string("dt = 0.0002\nmethod = \"") + method + "\"");
    clothlab::Scene scene = clothlab::parse_scene(with_method, "free.toml");
    kick(scene.world);
    const Vec3 p0 = scene.world.momentum();
    for (int s = 0; s < 500; ++s)
      scene.world.step(scene.dt);
    CHECK((scene.world.momentum() - p0).norm() < 1e-13);
    CHECK(scene.world.particles.x.allFinite());
  }
}

TEST_CASE("cloth: pinned particles stay bitwise fixed") {
  clothlab::Scene scene = clothlab::parse_scene(kHangingCloth, "hanging.toml");
  const clothlab::Matrix3X x0 = scene.world.particles.x;
  test::run_to_end(scene);
  const Index top_right = 11;
  for (Index i : {Index{0}, top_right}) {
    CAPTURE(i);
    CHECK(std::memcmp(scene.world.particles.x.col(i).data(), x0.col(i).data(),
                      3 * sizeof(double)) == 0);
    CHECK(scene.world.particles.v.col(i).isZero(0.0));
  }
  // ... while the rest of the cloth has swung down: the far edge falls by tens of centimetres.
  CHECK((scene.world.particles.x - x0).colwise().norm().maxCoeff() > 0.1);
}

TEST_CASE("cloth: a hanging cloth settles under gravity") {
  // The cloth swings down like a pendulum. The spring dampers calm its stretching, but a swing
  // about the pins stretches no spring: [damping] (f = -rate m v) calms that. With symplectic
  // Euler at the scene's dt the kinetic energy, about 1e-2 J at its peak, falls below 1e-6 J
  // and stays there.
  std::string text = kHangingCloth;
  text.replace(text.find("duration = 1"), 12, "duration = 30");
  text += "[damping]\nrate = 1.0\n";
  clothlab::Scene scene = clothlab::parse_scene(text, "settle.toml");
  double peak = 0.0;
  long calm_since = -1;
  for (long s = 0; s < scene.step_count(); ++s) {
    scene.world.step(scene.dt);
    const double ke = scene.world.kinetic_energy();
    peak = std::max(peak, ke);
    if (ke < 1e-6) {
      if (calm_since < 0) calm_since = s;
    } else {
      calm_since = -1;  // it moved again: not settled yet
    }
  }
  CAPTURE(scene.world.kinetic_energy());
  CHECK(peak > 1e-3);
  REQUIRE(calm_since >= 0);
  CHECK(calm_since < 2 * scene.step_count() / 3);  // settled by t = 20 s and stayed so
}

TEST_CASE("cloth: a zero-length spring between coincident particles stays finite") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0, 0, 0]
mass = 1
[[particle]]
position = [0, 0, 0]
mass = 1
[[spring]]
i = 0
j = 1
ks = 100
kd = 1
l0 = 0.5
[gravity]
[integrator]
dt = 0.001
duration = 0.1
)",
                                                "coincident.toml");
  test::run_to_end(scene);
  CHECK(scene.world.particles.x.allFinite());
}

TEST_CASE("cloth: a scene without [aerodynamics] never touches a triangle") {
  // Poison every triangle with an index far outside the particle arrays: reading one would
  // crash. The cloth still has springs, bending and gravity, and steps normally.
  clothlab::Scene scene = clothlab::parse_scene(kHangingCloth, "hanging.toml");
  REQUIRE(!scene.world.triangles.empty());
  const Index poison = std::numeric_limits<Index>::max() / 64;
  for (auto& t : scene.world.triangles)
    t = {poison, poison, poison};
  for (int s = 0; s < 100; ++s)
    scene.world.step(scene.dt);
  CHECK(scene.world.particles.x.allFinite());
  for (const auto& e : scene.world.force_effects)
    CHECK(e->name() != "aerodynamics");
}

TEST_CASE("cloth: air slows a falling sheet") {
  // A horizontal sheet dropped flat: with [aerodynamics] it must fall more slowly than without.
  const std::string sheet = R"(
[cloth]
rows = 6
cols = 6
spacing = 0.1
plane = "horizontal"
origin = [0, 10, 0]
mass = 0.05
[springs]
ks = 50
kd = 0.05
[gravity]
[integrator]
dt = 0.0005
duration = 1
)";
  clothlab::Scene still = clothlab::parse_scene(sheet, "vacuum.toml");
  clothlab::Scene airy = clothlab::parse_scene(sheet + "[aerodynamics]\n", "air.toml");
  for (long s = 0; s < still.step_count(); ++s) {
    still.world.step(still.dt);
    airy.world.step(airy.dt);
  }
  const double fall_vacuum = 10.0 - still.world.particles.x.row(1).mean();
  const double fall_air = 10.0 - airy.world.particles.x.row(1).mean();
  CHECK(fall_vacuum == doctest::Approx(4.9).epsilon(0.01));  // 1/2 g t^2, t = 1 s
  CHECK(fall_air < 0.5 * fall_vacuum);
  // Air pushes along the normal only: a flat sheet falling straight down is not pushed sideways.
  CHECK(std::abs(airy.world.momentum().x()) < 1e-9);
  CHECK(std::abs(airy.world.momentum().z()) < 1e-9);
}

TEST_CASE("springs: one effect owns the [[spring]] tables' springs and the body's, in that order") {
  // Particles 0 and 1 are 0.3 m apart, 1 and 2 are 0.5 m apart: the spring without l0 rests at
  // that distance, the one with l0 at its own. The rope of 3 particles adds 2 springs after them.
  clothlab::Scene scene = clothlab::parse_scene(R"(
[[particle]]
position = [0, 0, 0]
mass = 1
[[particle]]
position = [0.3, 0, 0]
mass = 1
[[particle]]
position = [0.3, 0.5, 0]
mass = 1
[[spring]]
i = 0
j = 1
ks = 100
l0 = 0.25
[[spring]]
i = 1
j = 2
ks = 50
[rope]
start = [0, 2, 0]
end = [1, 2, 0]
particles = 3
mass = 1
[springs]
ks = 10
[integrator]
dt = 0.001
duration = 0.01
)",
                                                "owner.toml");
  REQUIRE(!scene.world.force_effects.empty());
  CHECK(scene.world.force_effects.front()->name() == "springs");
  const clothlab::SpringDampers* effect = clothlab::find_spring_effect(scene.world, "springs");
  REQUIRE(effect != nullptr);
  const clothlab::SpringSet& s = effect->springs();
  REQUIRE(s.size() == 4);
  CHECK(s.l0(0) == 0.25);
  CHECK(s.l0(1) == doctest::Approx(0.5).epsilon(1e-15));
  CHECK(s.ks(2) == 10.0);
  CHECK(s.l0(2) == doctest::Approx(0.5).epsilon(1e-15));  // the rope's 1 m in 2 segments
  for (size_t k = 0; k < s.size(); ++k)
    CHECK(s.l_built(k) == s.l0(k));
}

TEST_CASE("springs: a rest length is given (l0 >= 0) or measured, never guessed from a sign") {
  clothlab::Matrix3X x(3, 2);
  x << 0.0, 3.0, 0.0, 4.0, 0.0, 0.0;
  clothlab::SpringSet s;
  s.add_at_rest(0, 1, 1.0, 0.0, x);  // |(3, 4, 0)| = 5 m
  s.add(0, 1, 1.0, 0.0, 0.0);        // no rest length: allowed (the scene reader warns)
  CHECK(s.l0(0) == 5.0);
  CHECK(s.l0(1) == 0.0);
  // A negative rest length is a mistake, not a request to measure one.
  CHECK_THROWS_AS(s.add(0, 1, 1.0, 0.0, -1.0), std::invalid_argument);
  CHECK_THROWS_AS(s.add(0, 1, 1.0, 0.0, std::numeric_limits<double>::quiet_NaN()),
                  std::invalid_argument);
  CHECK(s.size() == 2);
}
