// damping.hpp: a damper from every particle to the still world around it.
//
// Lecture: a damper resists relative motion, F_d = -kd (v1 - v2). Tie one end to the world
// (v2 = 0) and it slows any motion at all, including motions no spring can damp: a cloth
// swinging about its pins as a whole stretches none of its springs. Here kd is made
// proportional to each particle's mass, f_i = -rate m_i v_i, so every particle loses speed at
// the same relative rate: left alone, a velocity decays as exp(-rate t). It stands for the
// small losses (air, internal friction) that make real cloth come to rest.
#pragma once

#include "clothlab/core/effect.hpp"

namespace clothlab {

class Damping final : public ForceEffect {
 public:
  explicit Damping(double rate) : rate_(rate) {}
  std::string_view name() const override { return "damping"; }
  void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                  Matrix3X& f) const override;
  // df_i/dv_i = -rate m_i I.
  bool add_jacobians(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                     ForceJacobians& jacobians) const override;
  double rate() const { return rate_; }  // [1/s]

 private:
  double rate_;  // damping rate [1/s]
};

}  // namespace clothlab
