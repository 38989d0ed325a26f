#include "clothlab/core/world.hpp"

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
  void discard() { slot_ = nullptr; }  // the part did not happen after all: count nothing
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
  for (const auto& effect : force_effects)
    effect->set_time(t);  // what changes in time takes its value at the step's start
  for (const auto& effect : post_step_effects)
    effect->before_step(*this);  // what needs the state the step starts from records it
  // The backend may take the step, or part of it, its own way with the same bits (backend.hpp),
  // checking the state as it goes; it says what it took, and the world does the rest.
  const BackendStep fast = backend ? backend_step(dt) : BackendStep{};
  if (!fast.taken) {
    check(/*before_step=*/true);  // the guard: the state the step starts from
    advance(dt);                  // 1-3: the integrator sums forces (compute_forces) and moves
  }
  for (size_t k = fast.post_step_done; k < post_step_effects.size(); ++k)
    apply(k, dt);  // 4: collisions, plasticity, tearing, ...
  t += dt;
  ++steps;
  const bool checked = fast.checked_after && fast.post_step_done == post_step_effects.size();
  if (!checked) check(/*before_step=*/false);  // 5: the guard: the state the step ends with
  if (steps % guard.energy_check_every == 0) guard.check_energy(*this);
}

// The parts of the step, each timed for --stats when World::timing is set.

BackendStep World::backend_step(double dt) {
  Lap lap(timing ? &timing->backend_steps : nullptr);
  const BackendStep taken = backend->step(*this, dt);
  if (!taken.taken) lap.discard();
  return taken;
}

void World::check(bool before_step) const {
  Lap lap(timing ? &timing->guard : nullptr);
  guard.check(*this, before_step);
}

void World::advance(double dt) {
  Lap lap(timing ? &timing->integrator : nullptr);  // compute_forces takes its own time out
  integrator->advance(*this, dt);
}

void World::apply(size_t k, double dt) {
  if (timing) timing->post_step_effects.resize(post_step_effects.size(), 0.0);
  Lap lap(timing ? &timing->post_step_effects[k] : nullptr);
  post_step_effects[k]->apply(*this, dt);
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
    lap.discard();
  }
  compute_forces_readable(x, v, f);
}

void World::for_particles(const std::function<void(Index begin, Index end)>& range) const {
  for_ranges(team(), particles.size(), range);
}

void World::for_items(Index n, const std::function<void(Index begin, Index end)>& range) const {
  for_ranges(team(), n, range);
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
