// forces.cpp: which effects the fast engine sums itself, and the simplest of them (gravity,
// damping, a fluid's drag): a loop over the range's particles, component by component.
#include "fast/forces.hpp"

#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/damping.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab::fast {

namespace {

// UniformGravity::add_forces: gravity_force(m, g) on each particle.
class FastGravity final : public FastForce {
 public:
  explicit FastGravity(const UniformGravity& gravity) : gravity_(gravity) {}
  bool prepare(const Particles& /*p*/) override { return true; }
  void add(const Particles& p, const SoA3& /*x*/, const SoA3& /*v*/, SoA3& f, Index begin,
           Index end) const override {
    double* __restrict fx = f.row(0).data();
    double* __restrict fy = f.row(1).data();
    double* __restrict fz = f.row(2).data();
    const double* __restrict m = p.m.data();
    const Vec3 g = gravity_.g();
    for (Index i = begin; i < end; ++i) {
      const Vec3 fg = gravity_force(m[i], g);
      fx[i] += fg.x();
      fy[i] += fg.y();
      fz[i] += fg.z();
    }
  }

 private:
  const UniformGravity& gravity_;
};

// Damping::add_forces: f -= rate (v m), the same products as its Eigen expression.
class FastDamping final : public FastForce {
 public:
  explicit FastDamping(const Damping& damping) : damping_(damping) {}
  bool prepare(const Particles& /*p*/) override { return true; }
  void add(const Particles& p, const SoA3& /*x*/, const SoA3& v, SoA3& f, Index begin,
           Index end) const override {
    const double* __restrict m = p.m.data();
    const double rate = damping_.rate();
    for (int c = 0; c < 3; ++c) {
      double* __restrict fc = f.row(c).data();
      const double* __restrict vc = v.row(c).data();
      for (Index i = begin; i < end; ++i)
        fc[i] -= rate * (vc[i] * m[i]);
    }
  }

 private:
  const Damping& damping_;
};

// FluidDrag::add_forces: fluid_drag_force on each particle's velocity.
class FastDrag final : public FastForce {
 public:
  explicit FastDrag(const FluidDrag& drag) : drag_(drag) {}
  bool prepare(const Particles& /*p*/) override { return true; }
  void add(const Particles& /*p*/, const SoA3& /*x*/, const SoA3& v, SoA3& f, Index begin,
           Index end) const override {
    const FluidDrag& d = drag_;
    for (Index i = begin; i < end; ++i)
      f.col(i) += fluid_drag_force(v.col(i), d.fluid_velocity(), d.rho(), d.cd(), d.area());
  }

 private:
  const FluidDrag& drag_;
};

}  // namespace

std::unique_ptr<FastForce> fast_force(const ForceEffect& effect) {
  if (const auto* springs = dynamic_cast<const SpringDampers*>(&effect))
    return fast_springs(*springs);
  if (const auto* gravity = dynamic_cast<const UniformGravity*>(&effect))
    return std::make_unique<FastGravity>(*gravity);
  if (const auto* damping = dynamic_cast<const Damping*>(&effect))
    return std::make_unique<FastDamping>(*damping);
  if (const auto* aero = dynamic_cast<const Aerodynamics*>(&effect))
    return fast_aerodynamics(*aero);
  if (const auto* drag = dynamic_cast<const FluidDrag*>(&effect))
    return std::make_unique<FastDrag>(*drag);
  return nullptr;
}

}  // namespace clothlab::fast
