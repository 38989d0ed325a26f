// forces.cpp: which effects the fast engine sums itself, and the simplest of them (gravity,
// damping, a fluid's drag): a loop over the range's particles, component by component. Gravity
// and damping are templates on the copies' scalar: the float room (float_room.hpp) takes them in
// float.
#include "fast/forces.hpp"

#include <type_traits>
#include <vector>

#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/damping.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "fast/scalar_kernels.hpp"

namespace clothlab::fast {

namespace {

// Lesson 01's f = m g: the exercise's gravity_force on doubles, the same product on floats.
Vec3 gravity_kernel(double m, const Vec3& g) {
  return gravity_force(m, g);
}
Vec3f gravity_kernel(float m, const Vec3f& g) {
  return m * g;
}

// UniformGravity::add_forces: gravity_force(m, g) on each particle. In float, from the masses
// rounded to float once a step (or a run of steps: prepare), not as each is read: a loop that
// reads doubles beside its floats takes as few floats an instruction as doubles. Rounded once
// or as read, a mass is the same float.
template <class S>
class FastGravity final : public FastForceOf<S> {
 public:
  explicit FastGravity(const UniformGravity& gravity) : gravity_(gravity) {}
  bool prepare(const Particles& p) override {
    if constexpr (!std::is_same_v<S, double>) masses_.assign(p.m.begin(), p.m.end());
    return true;
  }
  void add(const Particles& p, const SoA3Of<S>& /*x*/, const SoA3Of<S>& /*v*/, SoA3Of<S>& f,
           Index begin, Index end) const override {
    S* __restrict fx = f.row(0).data();
    S* __restrict fy = f.row(1).data();
    S* __restrict fz = f.row(2).data();
    const S* __restrict m;
    if constexpr (std::is_same_v<S, double>) {
      m = p.m.data();
    } else {
      m = masses_.data();
    }
    const Vec3Of<S> g = gravity_.g().cast<S>();
    for (Index i = begin; i < end; ++i) {
      const Vec3Of<S> fg = gravity_kernel(m[i], g);
      fx[i] += fg.x();
      fy[i] += fg.y();
      fz[i] += fg.z();
    }
  }

 private:
  const UniformGravity& gravity_;
  std::vector<S> masses_;  // the float room's masses (empty on doubles)
};

// Damping::add_forces: f -= rate (v m), the same products as its Eigen expression.
template <class S>
class FastDamping final : public FastForceOf<S> {
 public:
  explicit FastDamping(const Damping& damping) : damping_(damping) {}
  bool prepare(const Particles& /*p*/) override { return true; }
  void add(const Particles& p, const SoA3Of<S>& /*x*/, const SoA3Of<S>& v, SoA3Of<S>& f,
           Index begin, Index end) const override {
    const double* __restrict m = p.m.data();
    const S rate = static_cast<S>(damping_.rate());
    for (int c = 0; c < 3; ++c) {
      S* __restrict fc = f.row(c).data();
      const S* __restrict vc = v.row(c).data();
      for (Index i = begin; i < end; ++i)
        fc[i] -= rate * (vc[i] * static_cast<S>(m[i]));
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

// The forms written on either scalar: spring-dampers, gravity, damping, aerodynamics.
template <class S>
std::unique_ptr<FastForceOf<S>> fast_force_of(const ForceEffect& effect) {
  if (const auto* springs = dynamic_cast<const SpringDampers*>(&effect))
    return fast_springs<S>(*springs);
  if (const auto* gravity = dynamic_cast<const UniformGravity*>(&effect))
    return std::make_unique<FastGravity<S>>(*gravity);
  if (const auto* damping = dynamic_cast<const Damping*>(&effect))
    return std::make_unique<FastDamping<S>>(*damping);
  if (const auto* aero = dynamic_cast<const Aerodynamics*>(&effect))
    return fast_aerodynamics<S>(*aero);
  return nullptr;
}

}  // namespace

std::unique_ptr<FastForce> fast_force(const ForceEffect& effect) {
  if (std::unique_ptr<FastForce> fast = fast_force_of<double>(effect)) return fast;
  if (const auto* drag = dynamic_cast<const FluidDrag*>(&effect))
    return std::make_unique<FastDrag>(*drag);
  return nullptr;
}

std::unique_ptr<FastForceOf<float>> fast_force_float(const ForceEffect& effect) {
  return fast_force_of<float>(effect);
}

}  // namespace clothlab::fast
