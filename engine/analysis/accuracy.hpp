// accuracy.hpp: what accuracy costs in time, measured (lesson 07).
//
// A work-precision study runs one problem with every integrator over a ladder of time steps and
// records, for each run, the error at a fixed end time against a reference, the wall time and
// the force evaluations it took per simulated second, and whether it stayed stable. Plotted
// error against cost, log-log, each integrator is a line whose slope is its order: the
// cheapest method for an accuracy is the lowest line at that height.
//
// Two problems:
//   - the damped oscillator: one particle on a spring to a pinned anchor, moving along the
//     spring, with the analytic solution as reference;
//   - any scene: the reference is the same scene run with RK4 at a much smaller step.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "clothlab/core/world.hpp"

namespace clothlab {

class AccuracyProblem {
 public:
  virtual ~AccuracyProblem() = default;
  virtual std::string name() const = 0;
  virtual double end_time() const = 0;  // [s]
  // A fresh world at t = 0 that steps with `integrator`.
  virtual World make_world(const std::string& integrator) const = 0;
  // The error of `world` at end_time() against the reference, relative to the size of the
  // motion (1 = as large as the motion itself).
  virtual double error(const World& world) const = 0;
  // Whether a run that finished without the guard stopping it stayed stable.
  virtual bool stable(const World& world, double error) const = 0;
  // What the report should say about the problem (reference, caveats).
  virtual std::string description() const = 0;
};

// One particle of mass m on a spring (ks, kd, rest length 1 m) to a pinned anchor, released at
// rest from a stretch of 0.5 m: a damped harmonic oscillator with w = sqrt(ks/m) and
// zeta = kd / (2 sqrt(ks m)) (underdamped: zeta < 1). Stable means the integrator's step matrix
// on this oscillator has no eigenvalue beyond 1 in modulus (stability.hpp).
class DampedOscillatorProblem final : public AccuracyProblem {
 public:
  DampedOscillatorProblem(double mass, double ks, double zeta, double end_time);
  std::string name() const override { return "damped-oscillator"; }
  double end_time() const override { return end_time_; }
  World make_world(const std::string& integrator) const override;
  double error(const World& world) const override;
  bool stable(const World& world, double error) const override;
  std::string description() const override;

  // The exact displacement from rest [m] and velocity [m/s] at time t.
  double exact_x(double t) const;
  double exact_v(double t) const;
  double omega() const { return omega_; }

 private:
  double mass_, ks_, kd_, zeta_, omega_, end_time_;
  static constexpr double kStretch = 0.5;  // initial displacement [m]
};

// A scene file: the reference is RK4 at `reference_dt`; the error is the root-mean-square
// distance of the particles from the reference's at end_time, over the size of the scene (the
// diagonal of its particles' bounding box at the start). Stable means the error stayed below 1.
class SceneProblem final : public AccuracyProblem {
 public:
  SceneProblem(std::string path, double end_time, double reference_dt);
  std::string name() const override { return path_; }
  double end_time() const override { return end_time_; }
  World make_world(const std::string& integrator) const override;
  double error(const World& world) const override;
  bool stable(const World& world, double error) const override;
  std::string description() const override;
  double scene_dt() const { return scene_dt_; }

 private:
  std::string path_;
  double end_time_, reference_dt_, scene_dt_ = 0.0, size_ = 1.0;
  Matrix3X reference_x_;
  std::string post_step_names_;
};

// One run of the study.
struct AccuracyRun {
  std::string integrator;
  double dt = 0.0;             // [s]
  long steps = 0;              // steps to the end time
  double error = 0.0;          // relative; NaN when the guard stopped the run
  double wall_per_sim = 0.0;   // wall-clock seconds per simulated second (fastest repeat)
  double evals_per_sim = 0.0;  // force evaluations per simulated second
  bool stable = false;
  std::string stopped;  // the guard's message when it stopped the run
};

// Runs `problem` with each integrator at each dt (dt must divide the end time into whole
// steps, to rounding). Each run is repeated until min_seconds of wall time have passed (at most
// 1000 times) and the fastest repeat is kept. `progress` is told about each run as it ends.
std::vector<AccuracyRun> run_accuracy_study(
    const AccuracyProblem& problem, const std::vector<std::string>& integrators,
    const std::vector<double>& dts, double min_seconds,
    const std::function<void(const AccuracyRun&)>& progress = {});

// The observed order between two runs of one integrator: log(e1 / e2) / log(dt1 / dt2).
double observed_order(const AccuracyRun& coarse, const AccuracyRun& fine);

}  // namespace clothlab
