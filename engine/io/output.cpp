#include "io/output.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

std::ofstream open_for_writing(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
  return out;
}

FrameWriter::FrameWriter(const std::filesystem::path& dir, bool velocities, bool springs) {
  std::filesystem::create_directories(dir);
  files_ = {dir / "energy.csv", dir / "positions.csv"};
  energy_ = open_for_writing(files_[0]);
  positions_ = open_for_writing(files_[1]);
  energy_ << "frame,t,kinetic,potential,total,px,py,pz\n";
  positions_ << "frame,t,particle,x,y,z\n";
  if (velocities) {
    files_.push_back(dir / "velocities.csv");
    velocities_ = open_for_writing(files_.back());
    velocities_ << "frame,t,particle,vx,vy,vz\n";
  }
  if (springs) {
    files_.push_back(dir / "springs.csv");
    springs_ = open_for_writing(files_.back());
    springs_ << "frame,t,effect,spring,i,j,strain,tension\n";
  }
}

namespace {

// One row per particle of the columns of m: "frame,t,particle,x,y,z".
std::string particle_rows(const Matrix3X& m, long frame, double t) {
  std::string rows;
  for (Index i = 0; i < m.cols(); ++i) {
    fmt::format_to(std::back_inserter(rows), "{},{:.17g},{},{:.17g},{:.17g},{:.17g}\n", frame, t, i,
                   m(0, i), m(1, i), m(2, i));
  }
  return rows;
}

// One row per spring of every spring effect: strain (l - l0) / l0 and tension f_sd, the
// spring-damper's force on end i along e = (x_j - x_i) / l (lesson 02): positive pulls the ends
// together.
std::string spring_rows(const World& world, long frame) {
  const Particles& p = world.particles;
  std::string rows;
  for (const auto& effect : world.force_effects) {
    const auto* family = dynamic_cast<const SpringDampers*>(effect.get());
    if (!family) continue;
    const SpringSet& s = family->springs();
    for (size_t k = 0; k < s.size(); ++k) {
      const Vec3 e_star = p.x.col(s.j(k)) - p.x.col(s.i(k));
      const double l = e_star.norm();
      const Vec3 f1 = spring_damper_force(p.x.col(s.i(k)), p.x.col(s.j(k)), p.v.col(s.i(k)),
                                          p.v.col(s.j(k)), s.ks(k), s.kd(k), s.l0(k));
      // + 0.0: a spring at rest, f_sd = -0, prints as 0.
      const double tension = (l > 0.0 ? f1.dot(e_star) / l : 0.0) + 0.0;
      const std::string strain =
          s.l0(k) > 0.0 ? fmt::format("{:.17g}", (l - s.l0(k)) / s.l0(k)) : std::string();
      fmt::format_to(std::back_inserter(rows), "{},{:.17g},{},{},{},{},{},{:.17g}\n", frame,
                     world.t, family->name(), k, s.i(k), s.j(k), strain, tension);
    }
  }
  return rows;
}

}  // namespace

void FrameWriter::write(const World& world, long frame) {
  // {:.17g} prints a double so that it reads back bit for bit.
  const double kinetic = world.kinetic_energy();
  const double potential = world.potential_energy();
  const Vec3 p = world.momentum();
  energy_ << fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", frame,
                         world.t, kinetic, potential, kinetic + potential, p.x(), p.y(), p.z());
  positions_ << particle_rows(world.particles.x, frame, world.t);
  energy_.flush();
  positions_.flush();
  if (velocities_.is_open()) {
    velocities_ << particle_rows(world.particles.v, frame, world.t);
    velocities_.flush();
  }
  if (springs_.is_open()) {
    springs_ << spring_rows(world, frame);
    springs_.flush();
  }
  if (!energy_ || !positions_ || (velocities_.is_open() && !velocities_) ||
      (springs_.is_open() && !springs_)) {
    throw std::runtime_error("writing the output files failed");
  }
}

}  // namespace clothlab
