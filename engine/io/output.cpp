#include "io/output.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

namespace clothlab {

std::ofstream open_for_writing(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
  return out;
}

FrameWriter::FrameWriter(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  files_ = {dir / "energy.csv", dir / "positions.csv"};
  energy_ = open_for_writing(files_[0]);
  positions_ = open_for_writing(files_[1]);
  energy_ << "frame,t,kinetic,potential,total,px,py,pz\n";
  positions_ << "frame,t,particle,x,y,z\n";
}

void FrameWriter::write(const World& world, long frame) {
  // {:.17g} prints a double so that it reads back bit for bit.
  const double kinetic = world.kinetic_energy();
  const double potential = world.potential_energy();
  const Vec3 p = world.momentum();
  energy_ << fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", frame,
                         world.t, kinetic, potential, kinetic + potential, p.x(), p.y(), p.z());
  const Matrix3X& x = world.particles.x;
  std::string rows;
  for (Index i = 0; i < x.cols(); ++i) {
    fmt::format_to(std::back_inserter(rows), "{},{:.17g},{},{:.17g},{:.17g},{:.17g}\n", frame,
                   world.t, i, x(0, i), x(1, i), x(2, i));
  }
  positions_ << rows;
  energy_.flush();
  positions_.flush();
  if (!energy_ || !positions_) throw std::runtime_error("writing the output files failed");
}

}  // namespace clothlab
