// What a scene can set moving: bodies that start with a velocity and a spin, pins that follow a
// path, wind that changes in time, and cloth masses by area. Each against its closed form.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <string_view>

#include "clothlab/after_step/moving_pins.hpp"
#include "clothlab/core/threads.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "scene/scene.hpp"
#include "test_util.hpp"

using clothlab::Index;
using clothlab::Vec3;

namespace {

constexpr double kPi = std::numbers::pi;

// The centre of mass of particles [first, first + count) [m].
Vec3 centre_of_mass(const clothlab::Particles& p, Index first, Index count) {
  Vec3 c = Vec3::Zero();
  double m = 0.0;
  for (Index i = first; i < first + count; ++i) {
    c += p.m[i] * p.x.col(i);
    m += p.m[i];
  }
  return c / m;
}

// Angular momentum about the centre of mass, L = sum m (r - c) x v [kg m^2/s].
Vec3 angular_momentum(const clothlab::Particles& p) {
  const Vec3 c = centre_of_mass(p, 0, p.size());
  Vec3 l = Vec3::Zero();
  for (Index i = 0; i < p.size(); ++i)
    l += p.m[i] * Vec3(p.x.col(i) - c).cross(Vec3(p.v.col(i)));
  return l;
}

// A free 3 x 4 x 5 lattice, 2 kg, 0.2 x 0.3 x 0.4 m, set moving and spinning; springs, nothing
// else acts on it.
const char* kSpinningSolid = R"(
[solid]
particles = [3, 4, 5]
size = [0.2, 0.3, 0.4]
corner = [1, 2, 3]
mass = 2
velocity = [1, -2, 0.5]
spin = [0.3, -0.7, 2]
[springs]
ks = 200
kd = 0.1
[integrator]
dt = 0.001
duration = 1
)";

// The mean square offset from the middle of n points evenly spread over a length a:
// offsets a (k / (n - 1) - 1/2), k = 0..n-1, give a^2 (n + 1) / (12 (n - 1)).
double mean_square_offset(double a, double n) {
  return a * a * (n + 1.0) / (12.0 * (n - 1.0));
}

}  // namespace

TEST_CASE("scene keys: a solid's velocity and spin give the closed-form momenta at t = 0") {
  const clothlab::Scene scene = clothlab::parse_scene(kSpinningSolid, "spin.toml");
  const clothlab::World& w = scene.world;
  const double mass = 2.0;
  // p = M v0: the spin adds sum m w x (r - c) = w x sum m (r - c) = 0.
  CHECK((w.momentum() - mass * Vec3(1, -2, 0.5)).norm() < 1e-12);
  // L = I w. The lattice is symmetric about its centre, so the inertia tensor is diagonal:
  // I_xx = M (<dy^2> + <dz^2>) and so on, with <d^2> the mean square offset along each axis.
  const double sx = mean_square_offset(0.2, 3), sy = mean_square_offset(0.3, 4),
               sz = mean_square_offset(0.4, 5);
  const Vec3 l_expected(mass * (sy + sz) * 0.3, mass * (sx + sz) * -0.7, mass * (sx + sy) * 2.0);
  CHECK((angular_momentum(w.particles) - l_expected).norm() < 1e-12);
  // Every particle: v = v0 + w x (r - c).
  const Vec3 c = centre_of_mass(w.particles, 0, w.particles.size());
  CHECK((c - Vec3(1.1, 2.15, 3.2)).norm() < 1e-12);
  for (Index i = 0; i < w.particles.size(); ++i) {
    const Vec3 v = Vec3(1, -2, 0.5) + Vec3(0.3, -0.7, 2).cross(Vec3(w.particles.x.col(i) - c));
    CHECK((Vec3(w.particles.v.col(i)) - v).norm() < 1e-12);
  }
}

TEST_CASE("scene keys: a free spinning solid keeps its momentum and angular momentum") {
  clothlab::Scene scene = clothlab::parse_scene(kSpinningSolid, "spin.toml");
  const Vec3 p0 = scene.world.momentum();
  const Vec3 l0 = angular_momentum(scene.world.particles);
  const Vec3 c0 = centre_of_mass(scene.world.particles, 0, scene.world.particles.size());
  test::run_to_end(scene);
  // Springs are equal and opposite along the line between their ends: no net force or torque.
  CHECK((scene.world.momentum() - p0).norm() < 1e-11);
  CHECK((angular_momentum(scene.world.particles) - l0).norm() < 1e-11);
  // The centre of mass went on at v0 for 1 s, and the solid turned: it was not at rest.
  const Vec3 c1 = centre_of_mass(scene.world.particles, 0, scene.world.particles.size());
  CHECK((c1 - c0 - Vec3(1, -2, 0.5) * scene.world.t).norm() < 1e-9);
  CHECK(scene.world.kinetic_energy() > 0.5 * 2.0 * p0.squaredNorm() / 4.0);
}

TEST_CASE("scene keys: a cloth and a rope start at their velocity and their pins at rest") {
  const clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 3
cols = 4
spacing = 0.1
mass = 1.2
velocity = [0, 0, 2]
pins = "top-corners"
[rope]
start = [0, 1, 0]
end = [1, 1, 0]
particles = 5
mass = 0.5
velocity = [1, 0, 0]
spin = [0, 0, 1]
[integrator]
dt = 0.01
duration = 1
)",
                                                      "moving.toml");
  const clothlab::Particles& p = scene.world.particles;
  // Cloth: 12 particles of 0.1 kg, 2 of them pinned at rest: p_z = 10 * 0.1 kg * 2 m/s.
  // Rope: 5 particles of 0.1 kg, centre at x = 0.5: v = (1, 0, 0) + z x (r - c), p = 0.5 kg v0.
  CHECK((scene.world.momentum() - Vec3(0.5, 0.0, 2.0)).norm() < 1e-12);
  CHECK(p.v.col(scene.cloth->at(0, 0)).norm() == 0.0);
  CHECK(p.v.col(scene.cloth->at(0, 3)).norm() == 0.0);
  CHECK((Vec3(p.v.col(scene.cloth->at(2, 3))) - Vec3(0, 0, 2)).norm() == 0.0);
  const Index last = scene.rope->first + 4;
  CHECK((Vec3(p.v.col(last)) - Vec3(1.0, 0.5, 0.0)).norm() < 1e-12);  // (1,0,0) + z x (0.5,0,0)
}

TEST_CASE("scene keys: a keyframed pin is on the straight lines between its keyframes") {
  clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 3
cols = 3
spacing = 0.1
mass = 0.9
pins = "top-corners"
[[cloth.pin_path]]
pins = [0]
times = [0.0, 0.5, 1.5]
offsets = [[0, 0, 0], [0.2, 0, 0], [0.2, 0.3, -0.1]]
[springs]
ks = 50
kd = 0.1
[gravity]
[integrator]
dt = 0.01
duration = 2
)",
                                                "wave.toml");
  clothlab::World& w = scene.world;
  const Vec3 x0 = w.particles.x.col(0);
  // The closed form: x0 + d(t), piecewise linear; v = d'(t); held after t = 1.5 s.
  const auto offset = [](double t) -> Vec3 {
    if (t < 0.5) return Vec3(0.2, 0, 0) * (t / 0.5);
    if (t < 1.5) return Vec3(0.2, 0, 0) + Vec3(0, 0.3, -0.1) * ((t - 0.5) / 1.0);
    return Vec3(0.2, 0.3, -0.1);
  };
  const auto velocity = [](double t) -> Vec3 {
    if (t < 0.5) return Vec3(0.4, 0, 0);
    if (t < 1.5) return Vec3(0, 0.3, -0.1);
    return Vec3::Zero();
  };
  CHECK((Vec3(w.particles.v.col(0)) - velocity(0.0)).norm() < 1e-15);
  int checked = 0;
  for (long s = 1; s <= scene.step_count(); ++s) {
    w.step(scene.dt);
    if (s % 25 != 0) continue;  // t = 0.25, 0.5, ..., 2.0 s
    CAPTURE(w.t);
    CHECK((Vec3(w.particles.x.col(0)) - (x0 + offset(w.t))).norm() < 1e-12);
    // At a keyframe's time the velocity jumps: which side a step lands on is rounding's choice.
    const bool at_keyframe = std::abs(w.t - 0.5) < 1e-9 || std::abs(w.t - 1.5) < 1e-9;
    if (!at_keyframe) CHECK((Vec3(w.particles.v.col(0)) - velocity(w.t)).norm() < 1e-12);
    ++checked;
  }
  CHECK(checked == 8);
  CHECK(w.particles.inv_m[0] == 0.0);
  // The other top corner stays where it was built.
  CHECK(w.particles.v.col(2).norm() == 0.0);
}

TEST_CASE("scene keys: a pin on a circle is at the closed-form point, for every method") {
  for (const std::string_view method : clothlab::method_names()) {
    CAPTURE(method);
    clothlab::Scene scene = clothlab::parse_scene(R"(
[rope]
start = [0.3, 2, 0]
end = [0.3, 1, 0]
particles = 6
mass = 0.3
[[rope.pin_path]]
pins = "first"
centre = [0, 2, 0]
axis = [0, 0, 1]
period = 2
[springs]
ks = 100
kd = 0.05
[integrator]
dt = 0.001
duration = 1
method = ")" + std::string(method) + "\"\n",
                                                  "swing.toml");
    clothlab::World& w = scene.world;
    // Turning about z through (0, 2, 0) at w = 2 pi / 2 s = pi rad/s from (0.3, 2, 0):
    // x = (0.3 cos(pi t), 2 + 0.3 sin(pi t), 0), v = 0.3 pi (-sin(pi t), cos(pi t), 0).
    for (long s = 1; s <= scene.step_count(); ++s) {
      w.step(scene.dt);
      if (s % 250 != 0) continue;
      CAPTURE(w.t);
      const double a = kPi * w.t;
      CHECK(
          (Vec3(w.particles.x.col(0)) - Vec3(0.3 * std::cos(a), 2 + 0.3 * std::sin(a), 0)).norm() <
          1e-12);
      CHECK((Vec3(w.particles.v.col(0)) - 0.3 * kPi * Vec3(-std::sin(a), std::cos(a), 0)).norm() <
            1e-12);
    }
    // No gravity, springs at rest: the rope moves only because its pin drags it. After 1 s
    // (half a turn) the pin is at (-0.3, 2, 0) and the free end has followed it a long way.
    const Index end = 5;
    CHECK((Vec3(w.particles.x.col(end)) - Vec3(0.3, 1, 0)).norm() > 0.1);
    CHECK(std::isfinite(w.particles.x.col(end).norm()));
  }
}

TEST_CASE("scene keys: wind at a time is the keyframes' plus the gust's sine") {
  // A 2 x 2 cloth (two triangles, 0.04 m^2 in all) facing z and held at its corners, in wind
  // along z; a still sheet facing the wind takes F = 1/2 rho cd A w^2 along it. The wind:
  // keyframes 0 -> 4 m/s over 1 s, then 4 -> 2 m/s over 2 s, plus 1 m/s sin(2 pi t / 0.5 s).
  // [drag] on each of the four particles: -1/2 rho |u|^2 cd a e with u = -wind, so along +z,
  // 1/2 rho cd a w^2 each, for the wind 3 + 0.5 sin(2 pi t / 0.25 s).
  clothlab::Scene scene = clothlab::parse_scene(R"(
[cloth]
rows = 2
cols = 2
spacing = 0.2
mass = 0.1
pins = "corners"
[aerodynamics]
rho = 1.2
cd = 1.1
wind_times = [0, 1, 3]
wind_values = [[0, 0, 0], [0, 0, 4], [0, 0, 2]]
gust = [0, 0, 1]
gust_period = 0.5
[drag]
rho = 1.2
cd = 0.5
area = 0.01
wind = [0, 0, 3]
gust = [0, 0, 0.5]
gust_period = 0.25
[integrator]
dt = 0.01
duration = 4
)",
                                                "gusts.toml");
  clothlab::World& w = scene.world;
  const auto wind_aero = [](double t) {
    const double steady = t < 1 ? 4 * t : t < 3 ? 4 - (t - 1) : 2;
    return steady + std::sin(2 * kPi * t / 0.5);
  };
  const auto wind_drag = [](double t) { return 3 + 0.5 * std::sin(2 * kPi * t / 0.25); };
  for (double t : {0.0, 0.1, 0.6, 1.0, 1.7, 2.9, 3.5}) {
    CAPTURE(t);
    for (const auto& effect : w.force_effects)
      effect->set_time(t);
    const double f_aero = 0.5 * 1.2 * 1.1 * 0.04 * wind_aero(t) * wind_aero(t);
    const double f_drag = 4 * 0.5 * 1.2 * 0.5 * 0.01 * wind_drag(t) * wind_drag(t);
    clothlab::Matrix3X f_readable(3, 4), f_fast(3, 4);
    w.compute_forces_readable(w.particles.x, w.particles.v, f_readable);
    w.compute_forces(w.particles.x, w.particles.v, f_fast);
    CHECK(f_readable.row(2).sum() == doctest::Approx(f_aero + f_drag).epsilon(1e-12));
    CHECK(f_readable.topRows(2).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((f_fast.array() == f_readable.array()).all());
  }
  // World::step gives each effect the time its step starts at.
  for (int s = 0; s < 137; ++s)
    w.step(scene.dt);
  const auto* aero = test::find_force_effect<clothlab::Aerodynamics>(w);
  const auto* drag = test::find_force_effect<clothlab::FluidDrag>(w);
  REQUIRE((aero && drag));
  const double t_last = w.t - scene.dt;  // the last step started here
  CHECK(aero->wind().z() == doctest::Approx(wind_aero(t_last)).epsilon(1e-12));
  CHECK(drag->fluid_velocity().z() == doctest::Approx(wind_drag(t_last)).epsilon(1e-12));
}

TEST_CASE("scene keys: masses by area give the rim half and the corners a sixth or a third") {
  const auto cloth = [](const std::string& mass_by) {
    return clothlab::parse_scene(R"(
[cloth]
rows = 4
cols = 5
spacing = 0.1
mass = 1.2
)" + mass_by + R"(
[integrator]
dt = 0.01
duration = 1
)",
                                 "masses.toml");
  };
  const clothlab::Scene equal = cloth("");
  CHECK(equal.world.particles.m.sum() == doctest::Approx(1.2));
  CHECK((equal.world.particles.m.array() == 1.2 / 20).all());
  const clothlab::Scene by_area = cloth("mass_by = \"area\"");
  const clothlab::VectorX& m = by_area.world.particles.m;
  const clothlab::ClothGrid& g = *by_area.cloth;
  // 3 x 4 cells of 0.1 kg. Inside, a particle touches six triangles of 0.05 kg, a third each: a
  // cell's mass. On the rim it touches three: half. The cells' diagonals run from (r, c + 1) to
  // (r + 1, c), so corners (0, 0) and (3, 4) touch one triangle (a sixth), (0, 4) and (3, 0) two.
  const double cell = 1.2 / 12;
  CHECK(m.sum() == doctest::Approx(1.2).epsilon(1e-14));
  CHECK(m[g.at(1, 1)] == doctest::Approx(cell));
  CHECK(m[g.at(2, 3)] == doctest::Approx(cell));
  CHECK(m[g.at(0, 2)] == doctest::Approx(cell / 2));
  CHECK(m[g.at(2, 0)] == doctest::Approx(cell / 2));
  CHECK(m[g.at(3, 1)] == doctest::Approx(cell / 2));
  CHECK(m[g.at(1, 4)] == doctest::Approx(cell / 2));
  CHECK(m[g.at(0, 0)] == doctest::Approx(cell / 6));
  CHECK(m[g.at(3, 4)] == doctest::Approx(cell / 6));
  CHECK(m[g.at(0, 4)] == doctest::Approx(cell / 3));
  CHECK(m[g.at(3, 0)] == doctest::Approx(cell / 3));
  CHECK((by_area.world.particles.inv_m.array() * m.array() - 1.0).abs().maxCoeff() < 1e-15);
}

TEST_CASE("scene: [engine] threads = 0 takes every core, as --threads 0 does") {
  const std::string scene =
      "[[particle]]\nposition = [0, 0, 0]\nmass = 1\n"
      "[integrator]\ndt = 0.01\nduration = 0.1\n[engine]\nthreads = ";
  CHECK(clothlab::parse_scene(scene + "0\n", "t.toml").world.threads ==
        clothlab::ThreadTeam::hardware_threads());
  CHECK(clothlab::parse_scene(scene + "3\n", "t.toml").world.threads == 3);
  CHECK_THROWS_WITH_AS((void)clothlab::parse_scene(scene + "-1\n", "t.toml"),
                       "t.toml:8:11: 'threads' in [engine] is -1; expected a whole number from 0 "
                       "to 1024",
                       clothlab::SceneError);
}

TEST_CASE("scene keys: a tiny axis, gravity or buoyancy still has its direction") {
  // |v|^2 of v = [0, 1e-170, 0] underflows to 0: normalised as it is, a pin path's axis stayed
  // [0, 1e-170, 0] (the circle a line through its centre), and buoyancy's up was NaN. Scaled
  // first, as [[plane]] normals are, each is the unit vector along v.
  const std::string body =
      "[[particle]]\nposition = [0, -1, 0]\nmass = 1\n"
      "[integrator]\ndt = 0.01\nduration = 0.1\n";
  clothlab::Scene circle = clothlab::parse_scene(
      "[rope]\nstart = [0.3, 2, 0]\nend = [0.3, 1, 0]\nparticles = 3\nmass = 0.3\n"
      "[[rope.pin_path]]\npins = \"first\"\ncentre = [0, 2, 0]\naxis = [0, 1e-170, 0]\n"
      "period = 2\n[integrator]\ndt = 0.01\nduration = 0.1\n",
      "axis.toml");
  const auto& pins =
      dynamic_cast<const clothlab::MovingPins&>(*circle.world.post_step_effects.back());
  CHECK(pins.paths()[0].axis == Vec3::UnitY());
  // [buoyancy] with a tiny g of its own, and against a tiny [gravity] that points up.
  const auto up = [](const clothlab::Scene& s) {
    return dynamic_cast<const clothlab::Buoyancy&>(*s.world.force_effects.back()).up();
  };
  CHECK(up(clothlab::parse_scene(body + "[buoyancy]\nvolume = 1\ng = 1e-170\n", "b.toml")) ==
        Vec3::UnitY());
  CHECK(up(clothlab::parse_scene(body + "[gravity]\ng = [0, 1e-170, 0]\n[buoyancy]\nvolume = 1\n",
                                 "g.toml")) == -Vec3::UnitY());
}
