#include "clothlab/world.hpp"

#include <cassert>
#include <chrono>

namespace clothlab {

namespace {

// Adds the wall time from its making to its end to *slot, and takes it from *less: a part of
// the step timed for --stats (World::timing). Without a slot it does nothing.
class Lap {
 public:
  explicit Lap(double* slot, double* less = nullptr) : slot_(slot), less_(less) {
    if (slot_) start_ = std::chrono::steady_clock::now();
  }
  ~Lap() {
    if (!slot_) return;
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    *slot_ += s;
    if (less_) *less_ -= s;
  }
  Lap(const Lap&) = delete;
  Lap& operator=(const Lap&) = delete;

 private:
  double* slot_;
  double* less_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

void World::step(double dt) {
  assert(integrator && "a world needs an integrator before it can step");
  if (steps == 0) guard.start(*this);
  if (timing) {
    timing->force_effects.resize(force_effects.size(), 0.0);
    timing->post_step_effects.resize(post_step_effects.size(), 0.0);
  }
  // The backend goes first; what it took of the step it did the lecture's way, bit for bit.
  BackendStep fast;
  if (backend) {
    Lap lap(timing ? &timing->backend_steps : nullptr);
    fast = backend->step(*this, dt);
  }
  if (!fast.taken) {
    {
      Lap lap(timing ? &timing->guard : nullptr);
      guard.check(*this, /*before_step=*/true);  // 5: the state the step starts from
    }
    Lap lap(timing ? &timing->integrator : nullptr);  // compute_forces takes its own time out
    integrator->advance(*this, dt);  // 1-3: forces, as often as it needs, then motion
  }
  for (size_t k = fast.post_step_done; k < post_step_effects.size(); ++k) {
    Lap lap(timing ? &timing->post_step_effects[k] : nullptr);
    post_step_effects[k]->apply(*this, dt);  // 4: collisions, plasticity, tearing
  }
  t += dt;
  ++steps;
  // 5: the state the step ends with, unless the backend checked every particle after its move
  // and nothing has changed it since.
  Lap lap(timing ? &timing->guard : nullptr);
  if (!fast.checked_after || fast.post_step_done < post_step_effects.size()) guard.check(*this);
  if (steps % guard.energy_check_every == 0) guard.check_energy(*this);
}

ThreadTeam* World::team() const {
  if (threads <= 1) return nullptr;
  if (!team_ || team_->size() != threads) team_ = std::make_unique<ThreadTeam>(threads);
  return team_.get();
}

void World::compute_forces(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const {
  if (backend) {
    Lap lap(timing ? &timing->backend_forces : nullptr, timing ? &timing->integrator : nullptr);
    if (backend->sum_forces(*this, x, v, f)) {
      ++force_evaluations;
      ++fast_evaluations;
      return;
    }
  }
  compute_forces_readable(x, v, f);
}

void World::for_particles(const std::function<void(Index begin, Index end)>& range) const {
  for_ranges(team(), particles.size(), range);
}

void World::compute_forces_readable(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const {
  f.setZero();
  ++force_evaluations;
  if (timing) timing->force_effects.resize(force_effects.size(), 0.0);
  for (size_t k = 0; k < force_effects.size(); ++k) {
    Lap lap(timing ? &timing->force_effects[k] : nullptr, timing ? &timing->integrator : nullptr);
    force_effects[k]->add_forces(particles, x, v, f);
  }
}

double World::kinetic_energy() const {
  // 1/2 m |v|^2 summed: colwise().squaredNorm() gives |v_i|^2 for every particle at once.
  return 0.5 * particles.m.dot(particles.v.colwise().squaredNorm().transpose());
}

double World::potential_energy() const {
  double energy = 0.0;
  for (const auto& effect : force_effects)
    energy += effect->potential_energy(particles, particles.x);
  return energy;
}

Vec3 World::momentum() const {
  return particles.v * particles.m;
}

std::string World::effects_in_play() const {
  std::string names;
  for (const auto& effect : force_effects) {
    if (!names.empty()) names += ", ";
    names += effect->name();
  }
  for (const auto& effect : post_step_effects) {
    if (!names.empty()) names += ", ";
    names += effect->name();
  }
  if (names.empty()) names = "no effects";
  if (integrator) {
    names += "; integrator ";
    names += integrator->name();
  }
  return names;
}

}  // namespace clothlab
