#include "scene/simulation.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "clothlab/bodies/normals.hpp"
#include "clothlab/forces/aerodynamics.hpp"

namespace clothlab {

// The forces the game holds on particles (apply_force): one more force effect, added to the
// world the first time a force is applied, so a game that applies none pays nothing for it.
class Simulation::ExternalForces final : public ForceEffect {
 public:
  explicit ExternalForces(Index n) : f_ext_(Matrix3X::Zero(3, n)) {}
  std::string_view name() const override { return "external"; }
  void add_forces(const Particles& /*p*/, const Matrix3X& /*x*/, const Matrix3X& /*v*/,
                  Matrix3X& f) const override {
    f += f_ext_;
  }
  // What the forces can do over the scene's size: sum of |f| size [J].
  double energy_scale(const Particles& /*p*/, const Matrix3X& /*x*/, double size) const override {
    return f_ext_.colwise().norm().sum() * size;
  }
  Matrix3X f_ext_;  // [N] one column per particle
};

Simulation::Simulation(Scene scene, long max_substeps)
    : scene_(std::move(scene)), max_substeps_(max_substeps) {
  if (!(scene_.dt > 0.0)) throw std::invalid_argument("Simulation: the scene's dt must be > 0");
  if (max_substeps_ == 0) max_substeps_ = std::max(1L, std::lround(0.25 / scene_.dt));
  set_max_substeps(max_substeps_);
  x_before_ = scene_.world.particles.x;
}

Simulation::Simulation(const std::filesystem::path& scene_file, long max_substeps)
    : Simulation(load_scene_file(scene_file), max_substeps) {}

void Simulation::set_max_substeps(long n) {
  if (n < 1) throw std::invalid_argument(fmt::format("Simulation: max_substeps {} < 1", n));
  max_substeps_ = n;
}

long Simulation::advance(double frame_time) {
  if (!std::isfinite(frame_time) || frame_time < 0.0)
    throw std::invalid_argument(fmt::format(
        "Simulation::advance: frame time {} s; expected a finite time >= 0", frame_time));
  const Substeps due = accumulate(leftover_, frame_time, scene_.dt, max_substeps_);
  leftover_ = due.leftover;
  dropped_ += due.dropped;

  World& world = scene_.world;
  Particles& p = world.particles;
  const double dt = scene_.dt;
  // Each pin moved for this frame goes from where it is now to its target in `count` equal
  // shares. (A move_pin made during these substeps, from on_substep, waits for the next frame.)
  std::vector<PinMove> moving;
  std::vector<Vec3> starts;
  if (due.count > 0) {
    moving.swap(moves_);
    for (const PinMove& m : moving)
      starts.push_back(p.x.col(m.i));
  }
  // When nothing happens between the substeps (no input to land on one, no wind ramping, no pin
  // on its way), all but the last are taken at once: the engine room may then keep the state in
  // its own layout between them (World::advance, the same bits as one at a time).
  long first = 1;
  if (due.count > 1 && !on_substep_ && ramp_.done >= ramp_.steps && moving.empty() &&
      !restart_guard_) {
    world.advance(dt, due.count - 1);
    first = due.count;
  }
  for (long k = first; k <= due.count; ++k) {
    if (on_substep_) on_substep_(*this);
    if (ramp_.done < ramp_.steps) {
      // Linear in the substeps: the wind moves by (to - from) / steps each substep.
      ++ramp_.done;
      const double s = static_cast<double>(ramp_.done) / static_cast<double>(ramp_.steps);
      const Vec3 wind =
          ramp_.done == ramp_.steps ? ramp_.to : Vec3(ramp_.from + s * (ramp_.to - ramp_.from));
      aerodynamics().set_wind(wind);
      if (ramp_.done == ramp_.steps) restart_guard_ = true;
    }
    const double share = static_cast<double>(k) / static_cast<double>(due.count);
    for (size_t m = 0; m < moving.size(); ++m) {
      // A pinned particle (inv_m = 0) keeps its velocity: r' = r + v dt lands on this substep's
      // point of the path, and springs and dampers see it move at the drag's speed.
      const Vec3 target = starts[m] + share * (moving[m].target - starts[m]);
      p.v.col(moving[m].i) = (target - p.x.col(moving[m].i)) / dt;
    }
    // The guard measures runaway energy against what the run had at its start; energy the game
    // put in (a drag, a force, a new wind) is not a runaway, so the guard starts again.
    if (restart_guard_ && world.steps > 0) world.guard.start(world);
    restart_guard_ = false;
    if (k == due.count) x_before_ = p.x;
    world.step(dt);
    for (size_t m = 0; m < moving.size(); ++m)  // exactly on the path, whatever the integrator
      p.x.col(moving[m].i) = starts[m] + share * (moving[m].target - starts[m]);
  }
  for (const PinMove& m : moving) {  // arrived: at rest on the target
    p.x.col(m.i) = m.target;
    p.v.col(m.i).setZero();
  }
  return due.count;
}

const Matrix3X& Simulation::interpolated_positions() {
  const double a = alpha();
  const Matrix3X& x = scene_.world.particles.x;
  if (x_before_.cols() != x.cols()) x_before_ = x;
  x_shown_.noalias() = (1.0 - a) * x_before_ + a * x;
  return x_shown_;
}

const Matrix3X& Simulation::normals() {
  if (normals_step_ != scene_.world.steps || normals_.cols() != scene_.world.particles.size()) {
    vertex_normals(scene_.world.particles.x, scene_.world.triangles, normals_);
    normals_step_ = scene_.world.steps;
  }
  return normals_;
}

void Simulation::check_particle(Index i, const char* what) const {
  if (i < 0 || i >= scene_.world.particles.size())
    throw std::out_of_range(fmt::format("Simulation::{}: particle {} does not exist ({} particles)",
                                        what, i, scene_.world.particles.size()));
}

void Simulation::apply_force(Index i, const Vec3& force) {
  check_particle(i, "apply_force");
  if (!external_) {
    auto effect = std::make_unique<ExternalForces>(scene_.world.particles.size());
    external_ = effect.get();
    scene_.world.force_effects.push_back(std::move(effect));
  }
  external_->f_ext_.col(i) += force;
  restart_guard_ = true;
}

void Simulation::clear_forces() {
  if (external_) external_->f_ext_.setZero();
}

void Simulation::pin(Index i) {
  check_particle(i, "pin");
  Particles& p = scene_.world.particles;
  p.inv_m[i] = 0.0;
  p.v.col(i).setZero();
}

void Simulation::unpin(Index i) {
  check_particle(i, "unpin");
  Particles& p = scene_.world.particles;
  p.inv_m[i] = 1.0 / p.m[i];
  std::erase_if(moves_, [i](const PinMove& m) { return m.i == i; });
}

void Simulation::move_pin(Index i, const Vec3& target) {
  check_particle(i, "move_pin");
  if (scene_.world.particles.inv_m[i] != 0.0)
    throw std::logic_error(
        fmt::format("Simulation::move_pin: particle {} is not pinned; pin(i) it first", i));
  if (!target.allFinite())
    throw std::invalid_argument("Simulation::move_pin: the target is not finite");
  for (PinMove& m : moves_) {
    if (m.i == i) {
      m.target = target;  // a newer target for this frame replaces the older one
      return;
    }
  }
  moves_.push_back({i, target});
  restart_guard_ = true;
}

Aerodynamics& Simulation::aerodynamics() const {
  for (const auto& effect : scene_.world.force_effects)
    if (auto* a = dynamic_cast<Aerodynamics*>(effect.get())) return *a;
  throw std::logic_error(fmt::format(
      "{}: the scene has no [aerodynamics] table, so there is no wind to change", scene_.source));
}

Vec3 Simulation::wind() const {
  return aerodynamics().wind();
}

void Simulation::set_wind(const Vec3& v_air, double ramp_time) {
  if (!v_air.allFinite() || !std::isfinite(ramp_time) || ramp_time < 0.0)
    throw std::invalid_argument(
        fmt::format("Simulation::set_wind: ramp time {} s; expected a finite wind and a finite "
                    "ramp time >= 0",
                    ramp_time));
  Aerodynamics& air = aerodynamics();
  // Whole substeps, at least one: ramp_time 0 changes the wind in one substep, the next.
  ramp_ = {air.wind(), v_air, std::max(1L, std::lround(ramp_time / scene_.dt)), 0};
  restart_guard_ = true;
}

}  // namespace clothlab
